// Internal pieces of denoise() shared by the CPU path (denoise.cpp, still_inputs.cpp), the CUDA
// path (src/cuda/cuda_denoise.cu) and the white-box tests.
#pragma once
#include <string>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/image.h"
#include "atrous/learned.h"
#include "filters/still_state.h"

namespace atrous::filters {

// What checkInputs found and derived, for the path that runs.
struct CheckedInputs {
    // Constant σ² per channel when no variance buffer was given, the colour is on the host and the
    // filter runs on the GPU (for a GPU colour denoiseCuda fills it there from DenoiseReport::noiseSigma;
    // the CPU path makes its own from the estimate).
    Image estimatedVariance;
    LearnedWeights learned;  // the learned cascade's weights (empty for the other methods)
    // Without a variance buffer: whether DenoiseReport::noiseSigma holds the global estimate yet
    // (denoise() leaves it to denoiseCpu, which times it as the stage "noise sigma").
    bool sigmaEstimated = false;
    // The report's figures of a host colour and emission, from the one scan.
    double meanLuminanceIn = 0, meanLuminanceEmission = 0;
};

// Optional extra outputs for tests and the viewer.
struct StillDebug {
    Image sureS;  // host image with `levels` channels: receives s_i(p)
};

// Validates sizes, channels, the colour's and variance's ranges and the parameters (InputError),
// counts non-finite colour pixels, estimates the noise when there is no variance buffer and writes
// the report's buffersUsed. For inputs on the GPU the non-finite count and the variance check are
// left to denoiseCuda (no download). deferNoiseSigma: leave the global noise estimate of a host
// colour to denoiseCpu. varianceDropped given: a host variance that holds no information (every
// value 0 or non-finite: a 1-spp render's) is found by the same scan, treated as absent and
// *varianceDropped set (denoise()'s rule, docs/algorithms.md).
CheckedInputs checkInputs(const Frame& in, const DenoiseOptions& o, DenoiseReport& rep, bool deferNoiseSigma = false,
                          bool* varianceDropped = nullptr);
// The report's line of buffers for a call of o.method (resolved): each given buffer, and why it is
// unused where it is (unusedReason: the rows' reads, the options' switches).
std::string buffersUsed(const Frame& in, const DenoiseOptions& o, bool noiseEstimated);
// True when a host variance holds no information (every value 0 or non-finite).
bool varianceIsEmpty(const Image& v);
// Every filter's colour rule (docs/reliability.md): a finite value beyond ±1e15 is not a
// measurement. Throws InputError "color buffer has a value of magnitude ... at pixel (x, y)" for
// a host image; a CUDA image is not scanned here.
void requireColorInRange(const Image& color);
// The InputError for a negative variance value at planar index `pixel` (of one plane).
InputError negativeVarianceError(float value, size_t pixel, int width);
// Without a variance buffer: the local noise estimate (noise_estimate.h), floored at
// kNoiseFloorFraction of the global estimate in `rep`. Nothing when cfg.varianceGiven. The radius
// and the floor: docs/decisions.md.
constexpr int kNoiseRadius = 5;
constexpr float kNoiseFloorFraction = 1.0f;
void setNoiseEstimate(StillConfig& cfg, const DenoiseReport& rep);
// Per-channel noise standard deviation by Donoho's MAD of the finest B3 detail of the colour
// divided by the modulation albedo (albedo null: of the colour itself).
void estimateNoiseSigma(const Image& color, const Image* albedo, float eps, float floor, float sigma[3],
                        Image* scratch = nullptr);
// The same estimate of a colour on the GPU, computed there (src/cuda/cuda_denoise.cu): the same
// MadDetail functor, so the same medians. A host albedo is uploaded for it.
void estimateNoiseSigmaCuda(const Image& color, const Image* albedo, float eps, float floor, float sigma[3]);
// The still path's inputs and configuration for a checked call (the host views of the buffers;
// without a variance, checked.estimatedVariance's).
StillInputs stillInputs(const Frame& in, const CheckedInputs& checked);
StillConfig stillConfig(const Frame& in, const DenoiseOptions& o, const CheckedInputs& checked, const DenoiseReport& rep);
// handedOver (optional): the caller's colour, variance and emission images, which the filter
// works in and returns its result in one of (denoise() on DenoiseBuffers, StillInputs' stores).
Image denoiseCpu(const Frame& in, const DenoiseOptions& o, const CheckedInputs& checked, DenoiseReport& rep,
                 StillDebug* debug, const DenoiseBuffers* handedOver = nullptr);
// timed: per-stage GPU times into rep.stages (events on the stream; denoiseWithReport).
Image denoiseCuda(const Frame& in, const DenoiseOptions& o, const CheckedInputs& checked, DenoiseReport& rep, bool timed);

}  // namespace atrous::filters

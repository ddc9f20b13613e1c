// Spatiotemporal variance-guided filtering (Schied et al. 2017, "SVGF"): a temporal accumulation
// of 1-spp frames followed by an edge-avoiding à-trous wavelet filter whose luminance edge stop is
// scaled by the estimated per-pixel standard deviation. See docs/svgf.md.
#pragma once
#include <memory>

#include "atrous/buffers.h"
#include "atrous/device.h"
#include "atrous/image.h"
#include "atrous/learned.h"
#include "atrous/stage_time.h"

namespace atrous {

// Every knob of the filter. Its table, svgfParams() in atrous/params.h (one row per field: name,
// range, doc), feeds validation, the CLI flags, the Python keywords and the viewer; each field
// changes the output (tests/svgf_test.cpp checks that).
struct SvgfParams {
    // À-trous edge stops (paper's σ_l, σ_n, σ_z).
    // luminance: exp(-|l_p - l_q| / (σ_l sqrt(g3x3(var_p)) + ε)). 2, with historyClip 0.5
    // (docs/decisions.md, "Sequences").
    float sigmaL = 2.0f;
    float sigmaN = 128.0f;  // normal: max(0, n_p·n_q)^σ_n
    float sigmaZ = 1.0f;    // depth: exp(-|z_p - z_q| / (σ_z |∇z_p·(p - q)| + ε))
    // Temporal accumulation: blend factor α = max(alpha, 1/historyLength) for colour and
    // momentsAlpha likewise for the luminance moments. In (0, 1].
    float alpha = 0.2f;
    float momentsAlpha = 0.2f;
    int historyCap = 32;   // history length saturates here (>= 1)
    // History clipping: the reprojected illumination is scaled into m ± historyClip·s of the
    // current frame's 3x3 luminance samples before the blend, so a moving highlight leaves no
    // trail (other renderers' glossy metals). >= 0; 0 = off. Chosen with σ_l (docs/decisions.md).
    float historyClip = 0.5f;
    int levels = 5;        // à-trous levels, step 2^i (0..10; 0 = temporal accumulation only)
    // Which à-trous level's output becomes next frame's colour history: 0 = after the first level
    // (the paper), -1 = the unfiltered temporal accumulation. In [-1, levels - 1]; with levels 0
    // the default 0 is accepted and means the accumulation, as -1.
    int feedbackTap = 0;
    // Below this history length (frames) the variance comes from a 7x7 spatial bilateral estimate
    // instead of the temporal moments (the paper: 4). >= 1.
    int spatialVarianceFrames = 4;
    // Reprojection consistency: a previous-frame tap is kept when its depth differs by at most
    // depthTolerance * (|dz/dx| + |dz/dy| + 0.01 z) (relative to the local depth gradient), its
    // normal's cosine to the current one is at least normalCos, and the mesh ids agree (the same
    // test and names as TemporalParams', atrous/temporal.h).
    float depthTolerance = 2.0f;
    float normalCos = 0.9f;
    // Optional temporal anti-aliasing on the remodulated output: reprojected previous output,
    // clamped to the current 3x3 neighbourhood's colour box, blended with weight taaAlpha.
    bool taa = false;
    float taaAlpha = 0.1f;
    // Temporal accumulation of the emission buffer before it is added back (svgf_emission.h):
    // the reprojected emission history (Catmull-Rom), clamped into the current 3x3 emission's
    // min/max box, is blended with weight max(emissionAlpha, 1/historyLength,
    // emissionMotionAlpha·|motion across the edge in pixels|). It smooths the 1-spp coverage
    // flicker on a visible light's edge; the motion term bounds the lag of a moving edge.
    // emissionAlpha in (0, 1] (1 = the raw emission, no accumulation); emissionMotionAlpha >= 0
    // (0 = off). The defaults: docs/decisions.md, "Sequences".
    float emissionAlpha = 0.1f;
    float emissionMotionAlpha = 4.0f;
    // The spatial filter: false = SVGF's à-trous (the edge stops above), true = the learned
    // à-trous cascade (docs/learned.md; the built-in weights or SvgfDenoiser's learnedWeights) on
    // the accumulated illumination, SVGF's variance (scaled to the accumulation's, svgf_learned.h)
    // and the frame's albedo, normal and depth. The temporal half is the same: with feedbackTap
    // >= 0 SVGF's à-trous levels 0..feedbackTap still run for the colour history only, so the
    // history is SVGF's own.
    bool learnedSpatial = false;
    // Per-frame safety net (svgf_safety.h, docs/svgf.md): the still default (auto) also denoises
    // each frame alone, and SVGF's output gives way to it where their luminances disagree by more
    // than this, as the 3x3 mean of the signed relative difference (fully from twice this on), so
    // a ghost, a smeared light or a lagging highlight comes out as the per-frame filter's. Costs
    // a still denoise per frame. >= 0; 0 = off (SVGF alone).
    float safetyNet = 0.05f;
};

// The row of SVGF in the registry of sequence methods (atrous/sequence_methods.h).
constexpr const char* kSvgfMethod = "svgf";

// Throws ParamError (atrous/error.h: an InputError naming the field, `sigma_l`) when a
// parameter is out of range.
void validateSvgfParams(const SvgfParams& p);

// A frame's buffers are a Frame (atrous/buffers.h: channels and conventions). SVGF reads color (1 spp),
// albedo, normal, depth, ids (channel 0), motion and emission; it estimates its own variance and
// has no use for positions. Only `color` is required; a missing buffer takes a neutral default
// (albedo 1, normal +z, depth 1, id 0, motion 0, emission 0). Non-finite values anywhere are
// treated as missing for that pixel (a non-finite colour is no sample; non-finite motion means
// "no history"). Demodulation divides by max(albedo, 1e-3), fading to 1 below 0.1.

// What the last timed frame did: per-stage times (SvgfDenoiser::lastReport).
struct SvgfReport {
    std::vector<StageTime> stages;  // demodulate, reproject, accumulate, variance, level i, learned, remodulate, taa
    double milliseconds = 0;        // sum of the stages (the frame's filter time, uploads excluded)
};

namespace detail {
class SvgfBackend;
}

// Keeps the history across frames. Feed frames in order; reset() (or a change of image size)
// starts a new history. Not thread-safe: one denoiser per stream of frames.
class SvgfDenoiser {
public:
    // Throws InputError for bad params or an unusable device. learnedWeights: the learned spatial
    // filter's (params.learnedSpatial; LearnedWeights::load for a weight file); empty (the
    // default, no impl) = the built-in weights; unused without learnedSpatial.
    explicit SvgfDenoiser(const SvgfParams& params = {}, Device device = Device::Cpu,
                          const LearnedWeights& learnedWeights = {});
    ~SvgfDenoiser();
    SvgfDenoiser(SvgfDenoiser&&) noexcept;
    SvgfDenoiser& operator=(SvgfDenoiser&&) noexcept;

    // Denoises one frame and returns the 3-channel linear HDR result on the host. Throws InputError
    // when `color` is missing or a buffer's size or channel count does not match the colour's.
    Image denoiseFrame(const Frame& frame);
    // The same, but the result stays on the denoiser's device, owned by the denoiser and valid
    // until the next call (no copy back to the host: for GPU pipelines and benchmarks). The
    // device's work is finished when it returns.
    const Image& denoiseFrameOnDevice(const Frame& frame);
    // Forgets all history (next frame is treated as the first).
    void reset();
    // Times the stages of each later denoiseFrame* call (off: no timing, the default). On CUDA the
    // stages are timed with events on the stream, read after the frame's final synchronisation
    // (no extra synchronisation).
    void setTiming(bool on);
    // The last timed frame's stage times (empty when timing is off or no frame ran yet).
    SvgfReport lastReport() const;

    const SvgfParams& params() const { return mParams; }
    Device device() const { return mDevice; }

private:
    SvgfParams mParams;
    Device mDevice = Device::Cpu;
    std::unique_ptr<detail::SvgfBackend> mImpl;
};

}  // namespace atrous

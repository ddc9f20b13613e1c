// The offline sequence denoiser (docs/temporal.md): frame t of an animation is denoised with the
// frames t-K .. t+K around it. Each neighbour is reprojected onto frame t through the motion
// vectors (chained frame by frame; the frames after t through the inverse of their own backward
// motion, so one motion convention serves both sides), its taps kept only where depth, normal
// and id agree with the frame it was reached from (SVGF's test, hop by hop) and, optionally,
// where its local colour agrees with frame t's; the kept colour, albedo, normal and emission are
// averaged, and the average is filtered by a still method (the default: auto). A film is
// denoised after rendering, so by default frame t uses its future too; TemporalParams::causal
// keeps to the frames before it (a viewer, a stream).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/image.h"
#include "atrous/svgf.h"

namespace atrous {

// Every knob; its table is temporalParams() in atrous/params.h (CLI --temporal-<name>, Python).
struct TemporalParams {
    // Frames on each side of t (0 = frame t alone: the still method per frame). The default:
    // docs/decisions.md, "Sequences".
    int radius = 3;
    // The hop test (svgf_reproject.h's): |z_q - z_p| <= τ_z (|dz/dx| + |dz/dy| + 0.01 z), n_p·n_q >=
    // normalCos, equal ids.
    float depthTolerance = 2.0f;
    float normalCos = 0.9f;
    // A neighbour's tap is left out where its 3x3 mean luminance (of the demodulated colour) differs
    // from frame t's by more than this many standard errors of the two means (a moving shadow or
    // highlight, a light switched on). 0 = off.
    float colorSigmas = 3.0f;
    // Frame t ± k weighs exp(-k² / (2 falloff²)) in the average (frame t: 1). 0 = all equal. A
    // glossy highlight slides over its surface as the camera moves, and the colour test above,
    // on 3x3 means of 1-spp frames, misses part of that: the far frames smear it.
    float falloff = 1.5f;
    // Every frame of the window goes through the still filters' firefly pass (prepass.h, bound k
    // local standard deviations, without a variance) before it is averaged: the bilinear taps
    // would spread a neighbour's firefly into a 2x2 blob that the still method's own pass keeps.
    // 0 = off (with radius 0 nothing is done: the still method has its own pass). 16, above the
    // still filters' 4, keeps the 1-spp frames' caustics and highlights (docs/decisions.md,
    // "Sequences").
    float fireflyK = 16.0f;
    // Causal: frame t from t - radius .. t only (the frames after it are not used even when the
    // window has them), so a frame can be denoised as soon as it is rendered (a viewer, a stream).
    // The offline default uses both sides.
    bool causal = false;
    // The falloff in causal mode (in place of `falloff`): one-sided averaging lags a moving
    // highlight in one direction only, and the far frames must weigh less (docs/decisions.md;
    // docs/temporal.md, "A causal mode"). 0 = all frames equal.
    float causalFalloff = 1.0f;
    // Frames on each side for the pixels that have not moved under a camera that stands still (a
    // turntable, a product shot): a track whose every hop so far moved less than
    // kTemporalStaticMotion pixels, through frames in which at least half the pixels did not move
    // either, goes on to t ± staticRadius with equal weights; the others keep `radius` and
    // `falloff`. The colour, depth, normal and id tests still apply (a moving shadow
    // on a static floor is left out as before); such a track's test also accepts the static
    // surfaces next to it (a 1-spp pixel on an edge). Offline mode only (causal ignores it); with
    // radius 0 the frame is denoised alone. It needs the renderer's motion vectors in every frame:
    // without them (taken as still), and in `denoise --sequence` and the Python module where the
    // motion is fitted to positions or estimated from colours, a moving object looks still, and
    // it is off. 0 = off. The default: docs/decisions.md, "Sequences".
    int staticRadius = 6;
};

// A track counts as static while each hop moves it less than this (pixels): renderers write exact
// zeros where neither the camera nor the object moves.
constexpr float kTemporalStaticMotion = 0.05f;

// How far from frame t the method reads: radius, or staticRadius when larger (offline mode), 0
// for radius 0. Windows given to gatherTemporal / denoiseTemporal need t ± this many frames.
int temporalWindowRadius(const TemporalParams& p);

void validateTemporalParams(const TemporalParams& p);

// The checks every frame of a window gets (sizes and channels against its colour, the colour's
// range): InputError naming the buffer. A caller that reads frames one at a time can run it on
// each as it arrives, so that the message can name that frame's file.
void checkTemporalFrame(const Frame& frame);

// The window averaged onto its centre frame: what the still method then filters.
struct TemporalGather {
    Image color, albedo, normal, emission, variance;  // like the centre frame's (albedo ... empty when it has none)
    // Channel 0: the effective number of frames each pixel averages, (Σw)² / Σw² (the centre's
    // included; the number of frames when the weights are equal); channel 1: Σw².
    Image frames;
};

// What a sliding window over a sequence prepares once per frame (its sanitised G-buffer, colour
// statistics and firefly clamp), kept between calls: with a cache, gatherTemporal and
// denoiseTemporal take one id per frame of the window (the frame number, say) and prepare only the
// frames whose id they have not seen; frames whose id leaves the window are dropped. An id must
// name the same, unchanged buffers as long as it is in the windows given; a change of size or of
// the parameters that shape the preparation starts over. Not thread-safe.
class TemporalCache {
public:
    TemporalCache();
    ~TemporalCache();
    TemporalCache(TemporalCache&&) noexcept;
    TemporalCache& operator=(TemporalCache&&) noexcept;
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

// Reprojects and averages window[center - r .. center + r] (r = temporalWindowRadius(params),
// clipped to the window; center - radius .. center with params.causal) onto window[center]. Every frame must have the centre's buffers and size (Frame's
// conventions: depth and ids in channel 0, motion previous - current in pixels). Frames without
// motion are taken as still; what moved is then rejected by the depth, normal and id test.
// Non-finite values of a neighbour are left out; the centre's own pass through. Host images.
TemporalGather gatherTemporal(const std::vector<Frame>& window, size_t center, const TemporalParams& params,
                              TemporalCache* cache = nullptr, const std::vector<long long>* ids = nullptr);

// What denoiseTemporal did.
struct TemporalReport {
    double meanFrames = 0;     // effective frames averaged per pixel (TemporalGather::frames), over the image
    double gatherMs = 0;       // reprojecting and averaging the window
    DenoiseReport spatial;     // the still method's report (methodUsed: what auto chose)
};

// gatherTemporal, then `spatial` (a still method's options: auto, eaw, ...) on the average, with
// the centre frame's depth, ids and position. Returns the denoised frame on the host.
Image denoiseTemporal(const std::vector<Frame>& window, size_t center, const TemporalParams& params,
                      const DenoiseOptions& spatial, TemporalCache* cache = nullptr,
                      const std::vector<long long>* ids = nullptr);
// The same, with what it did (the image is bit for bit denoiseTemporal's).
struct TemporalResult {
    Image image;
    TemporalReport report;
};
TemporalResult denoiseTemporalWithReport(const std::vector<Frame>& window, size_t center,
                                         const TemporalParams& params, const DenoiseOptions& spatial,
                                         TemporalCache* cache = nullptr, const std::vector<long long>* ids = nullptr);

// Motion vectors for frames that have a Position pass but no vectors (LuxCore's POSITION): each
// frame's pinhole camera fitted to its own pixels and world positions (src/filters/camera_fit.cpp),
// and a pixel's motion = its position projected by the previous frame's camera − by its own.
// Right for a static scene seen by a moving camera; on what moves it is wrong, and the sequence
// methods' tests leave that out. A fit whose median reprojection error exceeds
// kCameraFitMaxErrorPx (a fisheye, a mostly moving scene, too few hit pixels) is not `ok`. A
// 1-spp position is one sample's, anywhere in the pixel filter's footprint: the median error of a
// right fit is then about 0.4 px (a box filter: Mitsuba, atrous) to 0.6 px (LuxCore's
// Blackman-Harris), hence 1.5.
constexpr double kCameraFitMaxErrorPx = 1.5;
struct CameraFit {
    double m[12] = {};           // the 3x4 projection: (u, v) = (m0..3 · P1, m4..7 · P1) / (m8..11 · P1), P1 = (P, 1)
    double medianErrorPx = 1e30;  // over the fitted pixels (pixel centres at integer coordinates)
    bool ok = false;
    bool project(const double P[3], double& u, double& v) const;  // false behind the camera
};
CameraFit fitCamera(const Image& position);  // host image, 3 channels; 0 or non-finite = nothing hit
// 2 channels, previous − current in pixels (Frame's motion). Where nothing is hit (the sky),
// the direction through the pixel, mapped by the two cameras. NaN where either camera is not `ok`
// or the point is behind one.
Image motionFromPositions(const Image& position, const CameraFit& current, const CameraFit& previous);

// Motion for frames that have neither motion vectors nor a Position pass: from the colours
// themselves (src/filters/motion_estimate.cpp). Coarse-to-fine block matching on log(1 + the
// 3x3-averaged luminance), `levels` halvings, blocks of `block` pixels searched ±radius pixels at
// the coarsest level (±radius · 2^(levels-1) at full size) and ±1 around the coarser level's
// vectors (of the block and its four neighbours) below; a block whose costs tie within 2% keeps
// the vector nearest its prediction (flat regions). The vectors are bilinear between block
// centres: right for a camera's smooth field, a blur of it at the edges of what moves, which the
// temporal method's depth, normal and colour tests then reject. 2 channels, previous − current
// in pixels (Frame's motion); host images of one size (3 channels, or 1). Without a previous
// frame (null: the first of a sequence) NaN everywhere: no history.
struct MotionEstimateParams {
    int levels = 4;
    int block = 8;
    int radius = 4;
};
Image estimateMotion(const Image& current, const Image* previous, const MotionEstimateParams& params = {});

// Motion for a stream of frames that have no motion vectors, frame by frame in order (the
// sequence session, Python's denoise_temporal): from the frame's Position pass, through each
// frame's fitted camera (motionFromPositions against the previous frame's), or without one from its
// colour (estimateMotion against the previous frame's). A first frame, and one whose previous
// frame has another size, has no history: NaN. Host images.
class StreamMotion {
public:
    enum class From { Positions, Colours };
    // `frame`'s motion; `previous`: the frame before it in the stream, null for the first.
    Image next(const Frame& frame, const Frame* previous);
    From from() const { return mFrom; }  // what the last next() used
    // Positions: the camera fitted to the frame before the last one (null before two frames), which
    // its motion was measured against.
    const CameraFit* previousCamera() const { return mFrames > 1 ? &mPrevious : nullptr; }

private:
    From mFrom = From::Positions;
    CameraFit mCamera, mPrevious;
    size_t mFrames = 0;
};

// The row of this method in the registry of sequence methods (atrous/sequence_methods.h).
constexpr const char* kTemporalMethod = "temporal";

}  // namespace atrous

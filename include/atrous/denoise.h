// Denoising API: EAW (Dammertz et al. 2010), SURE-based À-Trous (Kim, Moon, Yoon 2016) and the
// learned à-trous filter (docs/learned.md).
// The names below are used by the render command (`atrous render --denoise eaw,sure`), the CLI
// (`atrous denoise`) and the benchmarks. The math is docs/denoising.md; the
// parameters and how their defaults are derived are documented in docs/denoising.md.
#pragma once
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "atrous/buffers.h"
#include "atrous/device.h"
#include "atrous/image.h"
#include "atrous/learned.h"
#include "atrous/refine.h"
#include "atrous/stage_time.h"

namespace atrous {

// Learned: the learned à-trous cascade (docs/learned.md) on the same prepared planes (sanitise,
// emission, fireflies, noise estimate, demodulation) as EAW and SURE, then the same safety net and
// remodulation. Of the parameters, the firefly pass, the emission filter (emissionLevels/Scale),
// the albedo rule (demodulate, albedoEpsilon, albedoFloor) and the safety net apply; levels, the
// σ's and scales of the EAW stops and SureParams do not. Blend: the mean of the learned and the
// SURE outputs, both from the same prepared planes (one preparation, the two cascades): their
// errors are partly independent (docs/decisions.md; docs/quality.md, "The default method"). Auto (the default): resolved by denoise() to Blend when
// an albedo and a normal buffer are given, else Sure (DenoiseReport::methodUsed says which).
// Refine: SURE, then the refine stage (src/filters/refine.h, docs/refine.md): a small U-Net on the
// finished image, the noisy colour, the albedo and the normal predicts a correction, a residual
// in log space, and a smooth gain keeps SURE's light per 64-pixel block; it needs an albedo and a
// normal. Registered methods (registerDenoiseMethod, below) take the values after Refine.
enum class DenoiseMethod : int { Eaw, Sure, Learned, Auto, Blend, Refine };

// The buffers of a denoise() call are one Frame (atrous/buffers.h, where each buffer's channels
// and conventions are stated). Only `color` is required; a missing feature simply removes its edge
// stop. Motion is not read. With an emission buffer the filters work on color - emission and add
// it back through an edge-avoiding filter of its own (EawParams::emissionLevels), which averages
// a visible light's partly covered edge pixels with each other and with nothing else.

// Edge-avoiding à-trous cascade (docs/denoising.md). Also the cascade that SURE runs on.
// Edge-stopping weight of a tap: w = exp(-(Δc²/σ_c,i² + Δn²/σ_n,i² + Δx²/σ_x² + (Δz/(σ_z z))² + ids)).
struct EawParams {
    int levels = 5;  // 1..10; five levels reach ±62 pixels
    // σ_c. 0 = automatic: σ_c² at a tap pair is colorScale² · (V(p) + V(q)), V = 3×3-prefiltered
    // sum over channels of the variance buffer (or of the estimated noise). > 0 = the paper's raw
    // constant σ_c (GLSL c_phi = σ_c²).
    float sigmaColor = 0.0f;
    float colorScale = 6.0f;        // k_c of the automatic σ_c (> 0)
    float colorLevelFactor = 0.5f;  // σ_c,i = σ_c · factor^i (paper: halved per level), (0, 1]
    // σ_n on |n(p) - n(q)| (unit normals). 0 disables the normal stop. GLSL n_phi = σ_n².
    float sigmaNormal = 0.5f;
    // Divide the normal distance by the squared step width 2^(2i), as the paper's GLSL does.
    bool normalStepScale = false;
    // σ_x. 0 = automatic: σ_x at a tap is positionScale · (pixel offset of the tap) · (world-space
    // size of a pixel at p, from the position buffer), so flat surfaces pass at any depth and any
    // level. > 0 = the paper's raw constant σ_x (GLSL p_phi = σ_x²), the same at every level.
    float sigmaPosition = 0.0f;
    float positionScale = 1.0f;  // k_x of the automatic σ_x (> 0)
    // σ_z on the relative depth difference (z_p - z_q) / z_p; 0 disables the depth stop (default:
    // position already covers it).
    float sigmaDepth = 0.0f;
    bool useIds = true;  // weight 0 across mesh or material id changes when an ids buffer is given
    // Emission buffer (both methods): the emission added back after filtering goes through an
    // edge-avoiding cascade of this many levels (0 = added back as is), with σ² at a tap pair
    // emissionScale · 2·min(V_p, V_q) · 4^-i (V = the pixel's summed variance), so pixels partly
    // covered by an emitter average with each other and nothing crosses a full/empty emitter edge.
    int emissionLevels = 4;     // 0..10
    float emissionScale = 1.0f;  // > 0
};

enum class SureMode { Discrete, JamesStein };

// SURE-based choice of the fraction s_i(p) of each detail d_i kept (docs/denoising.md, "SURE details").
struct SureParams {
    SureMode mode = SureMode::Discrete;
    std::vector<float> candidates = {0.0f, 0.2f, 0.4f, 0.6f, 0.8f, 1.0f};  // 1..8 values in [0,1]
    int windowRadius = 3;  // the SURE window is (2r+1)², 1..10
    // Correct the propagated variance v_i for the correlation the independence assumption ignores
    // (per-level factors computed exactly for the unweighted B3 cascade on white noise).
    bool correlatedVariance = true;
    // Levels i < firstLevel keep none of their detail (s_i = 0); 0 is the paper's form. The default
    // 2: fine levels' detail noise is strongly correlated across levels, which the per-level risk
    // ignores (docs/decisions.md).
    int firstLevel = 2;
};

// Firefly suppression before either filter (docs/denoising.md, "Fireflies"): a pixel whose luminance exceeds
// m + k·sqrt(s² + v) (m, s² the mean and variance of its 3×3 neighbours' luminance without the
// brightest one, v their mean luminance variance) is scaled down to that bound.
struct FireflyParams {
    bool enabled = true;
    float k = 4.0f;  // > 0
    // Put what the pass removed back, spread over the smallest window around each clamped pixel
    // that holds 32 clamped pixels (radius <= 32; a lone firefly's excess is dropped):
    // src/filters/firefly_restore.h.
    bool restore = true;
};

// The safety net after either filter (docs/algorithms.md, "The safety net"), off by default: per
// pixel, SURE on the residual between the input and the filter's output chooses how much of the
// residual to give back, where that residual's energy is above `trigger` times the input's
// variance (the filter is then estimated worse than its input). With an estimated variance (other
// renderers' output) the local variance is too uncertain for it, so it is a choice for inputs
// whose variance is trusted (docs/decisions.md).
struct SafetyNetParams {
    bool enabled = false;
    int windowRadius = 3;  // the window is (2r+1)², 1..10
    float trigger = 2.0f;  // τ >= 0: act where ΣD > τ ΣV (2: the SURE risk of the output is above the input's)
};

// The parameters' user-facing names (Python keywords, CLI flags), ranges and doc lines are one
// table, denoiseParams() in atrous/params.h: a new field needs a row there (tests/params_test.cpp).
struct DenoiseOptions {
    DenoiseMethod method = DenoiseMethod::Auto;
    Device device = Device::Cpu;
    EawParams eaw;
    SureParams sure;
    FireflyParams firefly;
    SafetyNetParams safety;
    // Albedo demodulation (when an albedo buffer is given): filter color / max(albedo, ε) with
    // variance / max(albedo, ε)², then multiply the result by max(albedo, ε).
    bool demodulate = true;
    float albedoEpsilon = 1e-3f;  // > 0
    // Where a pixel's largest albedo channel m is below this, demodulation fades out: the divisor
    // is 1 + t (max(a, ε) - 1) with t = min(m / albedoFloor, 1)² (0 = off: max(a, ε) everywhere).
    // Other renderers' albedo is 0 on glass, mirrors, emitters and the sky (docs/algorithms.md).
    // 0.05: 0.1 half-demodulated dark texture (docs/decisions.md).
    float albedoFloor = 0.05f;  // [0, 1]
    // The learned methods' network (learned, blend, auto): a resource loaded once by the caller
    // (LearnedWeights::load for a weight file, version 4 or 3; docs/learned.md) and shared between
    // calls, so a sequence or a batch reads its file once. Empty = the built-in weights.
    LearnedWeights weights;
    // The refine method's network (RefineWeights::load for a weight file); empty = the built-in weights.
    RefineWeights refineWeights;
};

// What a denoise() call did, for the CLI and for measurements.
struct DenoiseReport {
    // The method that ran: options.method, or what Auto resolved to (Blend or Sure).
    DenoiseMethod methodUsed = DenoiseMethod::Sure;
    // No variance buffer: the noise was estimated from the image, per pixel, floored at Donoho's
    // MAD of the (demodulated, with an albedo) colour (docs/algorithms.md).
    bool noiseEstimated = false;
    // A variance buffer was given but was zero everywhere (a 1-spp render has no variance
    // estimate): it was ignored and the noise estimated as without one.
    bool varianceIgnored = false;
    float noiseSigma[3] = {0, 0, 0};  // the global MAD estimate, per channel (the per-pixel floor)
    int nonFinitePixels = 0;          // colour samples that were NaN/Inf (treated as missing)
    int firefliesClamped = 0;
    double meanLuminanceIn = 0;        // mean luminance of the (finite) input colour
    double meanLuminanceAfterFirefly = 0;  // ... after firefly suppression
    std::string buffersUsed;           // e.g. "color,variance,normal,position"
    double milliseconds = 0;           // filter time (excluding validation)
    // Per-stage times of the filter, in order: (without a variance buffer) noise sigma (the global
    // MAD estimate), sanitize (NaN/Inf repair, the emission split and, with an emission buffer, the
    // emission filter), fireflies, demodulate, (without a variance buffer) noise estimate (the
    // per-pixel estimate, docs/algorithms.md), sigma scales, then
    // "level i" (and for SURE "sure i": the window sums and the choice of s_i) per level (the
    // learned method: one stage "learned" instead of sigma scales and the levels), then
    // "give-back" (EAW and SURE with an albedo: the albedo give-back, docs/algorithms.md), "safety
    // net" (when on) and remodulate. CPU: wall clock; CUDA: cudaEvents on the stream (GPU time, no extra syncs).
    std::vector<StageTime> stages;
    // The buffers given as strided memory (StridedImage) that were copied into planar float32
    // storage of their own before filtering, e.g. "albedo (float16, 3 channels)". The colour, the
    // variance and the emission never are: they are converted into the planes the filter works in
    // (its first pass reads them where they are).
    std::vector<std::string> copies;
};

// Denoises inputs.color and returns a 3-channel image of the same size: on the host, except with
// options.device == Cuda and a colour already on the GPU, when the result stays there. Throws
// InputError for mismatched sizes, missing colour, negative variance or parameters out of range.
// A buffer may be given as strided memory in the caller's layout (BufferRef: float32 or float16,
// interleaved or planar; DenoiseReport::copies says what was copied).
Image denoise(const Frame& inputs, const DenoiseOptions& options);

// The same, with what the run did (the CLI's line, the benchmarks' stage times). The image is bit
// for bit denoise()'s; on CUDA the stages are timed with events on the stream, which the plain call
// does not record.
struct DenoiseResult {
    Image image;
    DenoiseReport report;
};
DenoiseResult denoiseWithReport(const Frame& inputs, const DenoiseOptions& options);

// The inputs of a denoise() call whose caller hands its colour, variance and emission images over
// to the filter, as a one-shot caller does that read them from files only to denoise them (the
// CLI). On the CPU the filter then works in their storage instead of copying them (c_0 and its
// variance are sanitised in place, the variance's storage becomes a cascade buffer, the emission's
// the emission filter's) and returns its result in one of them: a call costs about 24 bytes per
// pixel beyond its inputs for EAW (docs/architecture.md, "Memory"). After the call each of the
// three is empty or holds intermediate values: the caller must not read them. Images the filter
// cannot use (on the GPU, not 3 channels) are copied as by the const overload, whose results
// this one's equal bit for bit. The other buffers are read only, as in Frame.
struct DenoiseBuffers {
    Image* color = nullptr;           // required
    Image* variance = nullptr;
    Image* emission = nullptr;
    const Image* albedo = nullptr;
    const Image* normal = nullptr;
    const Image* position = nullptr;
    const Image* depth = nullptr;
    const Image* ids = nullptr;
};
Image denoise(DenoiseBuffers& buffers, const DenoiseOptions& options);
DenoiseResult denoiseWithReport(DenoiseBuffers& buffers, const DenoiseOptions& options);
// A frame's buffers for the overloads above: `color`, `variance` and `emission` the caller's own
// images, handed over (the CLI's decoded files, those the frame points at); the features the
// frame's, read only. An empty (or null) variance or emission is absent.
DenoiseBuffers handOver(const Frame& frame, Image& color, Image* variance, Image* emission);

// denoiseWithReport() with method Sure on the CPU, and SURE's kept fraction s_i(p) of each level's
// detail (one channel per level; levels below sure.firstLevel are 0): the viewer's debug view.
// InputError for another method or device.
struct SureFractionsResult {
    Image image;
    Image fractions;
    DenoiseReport report;
};
SureFractionsResult denoiseWithSureFractions(const Frame& inputs, const DenoiseOptions& options);

// Throws ParamError (atrous/params.h: an InputError naming the field, `sigma_normal`) when a
// parameter is out of range; the ranges are the rows of denoiseParams().
void validateDenoiseOptions(const DenoiseOptions& options);

// The planes every still method is prepared with (docs/architecture.md, "The still path"): the
// preparation (sanitise, emission, fireflies, noise estimate, demodulation) writes them, a
// method's cascade reads them, the finishing (safety net, remodulation) takes the cascade's output
// back to radiance: out = filtered * modulation + emission. Views on the device the call runs on.
struct PreparedView {
    Device device = Device::Cpu;
    ImageView color;     // c: sanitised, emission taken out, fireflies clamped, demodulated (3)
    ImageView variance;  // its per-channel variance, given or estimated (3)
    // The features the method reads, sanitised; invalid when not given or not read (albedo also
    // when demodulation is off).
    ImageView albedo, normal, position;  // 3 channels each
    ImageView depth;                     // 1
    ImageView ids;                       // 2: object, material
    // What the finishing applies: the remodulation's multiplier (1 where no albedo) and the
    // filtered emission added back (0 without one), 3 channels each. Invalid in what a cascade is
    // given; set in PreparedPlanes (the training's targets need them).
    ImageView modulation, emission;
};

// The same planes as host images, owned: what preparePlanes() returns.
struct PreparedPlanes {
    Image color, variance, albedo, normal, position, depth, ids, modulation, emission;
    PreparedView view() const;
};
// The preparation of a denoise() call with these options, on the CPU, with the features that
// options.method reads (auto resolved as denoise() resolves it): for training
// (atrous.prepared_planes) and for checking a registered method against its cascade: with the
// safety net off, denoise()'s output is cascade(planes) * modulation + emission. A feature not
// given or not read is an empty image.
PreparedPlanes preparePlanes(const Frame& frame, const DenoiseOptions& options);

// A registered method's own cascade (registerDenoiseMethod): given the prepared planes of what it
// reads, it writes the filtered colour, in the same demodulated units, to `out` (3 planes of the
// colour's size on the planes' device); denoise() then applies the safety net (when on),
// remodulates and adds the filtered emission back, as for the built-in methods.
using StillCascade = std::function<void(const PreparedView& planes, const DenoiseOptions& options, const ImageView& out)>;

// What a still method reads, said once in its registry row: the one rule of what a call decodes,
// prepares and reports (denoiseReads, DenoiseReport::buffersUsed) and of which parameters and
// flags apply to it (the CLI's notes). Every method's preparation and finishing read the colour,
// the variance, the emission, the albedo (demodulation) and, when the noise is estimated, the
// normal and depth, with the parameter groups of stillStageGroups(); `reads` adds what the
// method's cascade reads.
struct MethodReads {
    BufferMask buffers;               // the feature buffers its cascade reads (colour always)
    std::vector<std::string> params;  // the groups of denoiseParams() its cascade reads ("eaw", "sure")
    bool weights = false;             // the learned filter's weights (DenoiseOptions::weights)
    // Rows whose reads this one's adds, each with its own switches (blend: learned and sure; auto:
    // blend and sure). Registered methods: none.
    std::vector<DenoiseMethod> combines;
};

// How a row's cascade runs: one of the still path's own (they share its temporaries), or the
// row's registered function; auto has none (denoise() resolves it first).
enum class CascadeKind { Registered, Eaw, Sure, Learned, Blend, Auto };

// The still methods, one row each: the one list the CLI (--method, its help and messages, the
// sequence check), `atrous bench`, the viewer and Python (atrous.methods(), the farm, the
// evaluation) read. A registered method is a row with a cascade per device
// (registerDenoiseMethod), and nothing else needs an edit (docs/architecture.md, "Where a new piece
// goes"; tests/toy_method.cpp is one).
struct DenoiseMethodInfo {
    DenoiseMethod method = DenoiseMethod::Eaw;  // its value (registerDenoiseMethod assigns it)
    const char* name = "";     // "eaw", ...: the CLI's --method, Python's method=, the report's column
    const char* summary = "";  // one line for --help
    MethodReads reads;
    // A registered method's cascade on the CPU and on CUDA (empty: not on that device).
    StillCascade cpu = {}, cuda = {};
    CascadeKind kind = CascadeKind::Registered;
    bool registered() const { return kind == CascadeKind::Registered; }
};
// The rows in order: eaw, sure, learned, blend, auto, then the registered methods. The references
// stay valid while the program runs.
const std::deque<DenoiseMethodInfo>& denoiseMethods();
// Adds a still method: `info.name` (a new name of letters, digits, '_' or '-'), its summary, what
// it reads and at least one cascade; `info.method` and `info.kind` are ignored and the method's new
// value returned (pass it as DenoiseOptions::method, or the name to the CLI and Python). Call it
// before any denoise() of the program runs (it is not synchronised with them). InputError for a
// taken or malformed name, no cascade, the learned weights, or a parameter group denoiseParams()
// does not have.
DenoiseMethod registerDenoiseMethod(DenoiseMethodInfo info);
const DenoiseMethodInfo* findDenoiseMethod(const std::string& name);  // null when unknown
const DenoiseMethodInfo& denoiseMethodInfo(DenoiseMethod m);          // the method's row
// The names in order, "eaw, sure, learned, blend or auto".
std::string denoiseMethodNames();

// The parameter groups of denoiseParams() that every still method's preparation and finishing
// read: "" (demodulate, albedo_*), "firefly", "emission", "safety".
const std::vector<std::string>& stillStageGroups();
// Whether a call of `method` reads the parameters of `group`, and the learned weights (with the
// rows it combines: auto, what either of its resolutions reads).
bool readsParamGroup(const DenoiseMethodInfo& method, const std::string& group);
bool readsWeights(const DenoiseMethodInfo& method);

// The buffers a call reads, from the rows' `reads` and the options' switches (docs/denoising.md,
// "What a method reads"):
// - methodReads: the features the method's cascade reads: its row's buffers less those a
//   parameter of a group it reads switches off (sigma_depth 0: depth; no use_ids: the ids;
//   no demodulate: the albedo). Auto: what either of its resolutions reads.
// - denoiseReads: what a reader decodes for a call: colour, variance and emission, the albedo
//   when demodulating, the normal and depth (the noise estimate's edges, needed when the variance
//   turns out absent or empty), and methodReads. Never motion.
BufferMask methodReads(const DenoiseMethodInfo& method, const DenoiseOptions& options);
BufferMask denoiseReads(const DenoiseOptions& options, DenoiseMethod resolved);
// Why a given buffer is not read by a call of a resolved method ("by learned", "--sigma-depth 0"),
// "" when it is read. noiseEstimated: the call estimated its noise (the normal and depth steer it).
std::string unusedReason(Buffer b, const DenoiseOptions& options, DenoiseMethod resolved, bool noiseEstimated);

// A name of denoiseMethods(); InputError otherwise.
DenoiseMethod parseDenoiseMethod(const std::string& name);
const char* denoiseMethodName(DenoiseMethod m);
// What Auto becomes for these inputs: Blend with an albedo and a normal buffer, else Sure; any
// other method is returned as it is.
DenoiseMethod resolveDenoiseMethod(DenoiseMethod m, const Frame& inputs);
// The same rule from whether an albedo and a normal are given (a reader deciding what to decode).
DenoiseMethod resolveDenoiseMethod(DenoiseMethod m, bool albedo, bool normal);

}  // namespace atrous

// The denoise() entry point: validates the inputs and parameters, estimates the noise when no
// variance buffer is given, and runs the driver (denoise_driver.h) on the CPU or, through
// src/cuda/cuda_denoise.cu, on the GPU.
#include "atrous/denoise.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/learned.h"
#include "atrous/params.h"
#include "core/parallel.h"
#include "core/timer.h"
#include "filters/denoise_driver.h"
#include "filters/denoise_internal.h"
#include "filters/noise_estimate.h"
#include "filters/stage_clock.h"

namespace atrous {

DenoiseMethod parseDenoiseMethod(const std::string& name) {
    if (name == "eaw") return DenoiseMethod::Eaw;
    if (name == "sure") return DenoiseMethod::Sure;
    if (name == "learned") return DenoiseMethod::Learned;
    if (name == "auto") return DenoiseMethod::Auto;
    throw InputError("unknown denoise method '" + name + "' (expected eaw, sure, learned or auto)");
}

const char* denoiseMethodName(DenoiseMethod m) {
    switch (m) {
        case DenoiseMethod::Eaw: return "eaw";
        case DenoiseMethod::Sure: return "sure";
        case DenoiseMethod::Learned: return "learned";
        case DenoiseMethod::Auto: return "auto";
    }
    return "?";
}

// The network was trained with an albedo and a normal (docs/learned.md); without them SURE.
DenoiseMethod resolveDenoiseMethod(DenoiseMethod m, const DenoiseInputs& in) {
    if (m != DenoiseMethod::Auto) return m;
    return in.albedo && !in.albedo->empty() && in.normal && !in.normal->empty() ? DenoiseMethod::Learned
                                                                               : DenoiseMethod::Sure;
}

// The ranges are params.h's table (one row per field); the library's own limits must agree.
static_assert(filters::kMaxLevels == 10 && filters::kMaxSureCandidates == 8, "update params.h's ranges");

void validateDenoiseOptions(const DenoiseOptions& o) { validateParams(o, denoiseParams()); }

namespace filters {

// Donoho's estimator on the finest detail of the unweighted B3 à-trous (MadDetail, noise_estimate.h):
// σ_d = median|d_0| / 0.6745; for white noise var(d_0) = σ² (1 + Σh² - 2 h(0)), so
// σ = σ_d / sqrt(0.7900...). Per channel, over finite pixels; of the demodulated colour when an
// albedo is given.
void estimateNoiseSigma(const Image& color, const Image* albedo, float eps, float floor, float sigma[3]) {
    globalNoiseSigma(CpuExec{}, color.view(), albedo ? albedo->view() : ImageView{}, eps, floor, sigma);
}

float medianFinite(const CpuExec&, const ImageView& v, float none) {
    float* d = v.data;
    const size_t n = size_t(v.width) * size_t(v.height);
    float* end = std::partition(d, d + n, [](float a) { return a < INFINITY && a == a; });
    const size_t m = size_t(end - d);
    if (!m) return none;
    std::nth_element(d, d + m / 2, end);
    return d[m / 2];
}

static void checkBuffer(const Image* img, const Image& color, const char* name) {
    if (!img) return;
    if (img->empty()) throw InputError(std::string(name) + " buffer is empty");
    if (img->width() != color.width() || img->height() != color.height())
        throw InputError(std::string(name) + " buffer is " + std::to_string(img->width()) + "x" +
                         std::to_string(img->height()) + " but the color is " + std::to_string(color.width()) + "x" +
                         std::to_string(color.height()));
    if (img->channels() < 3) throw InputError(std::string(name) + " buffer needs 3 channels");
}

// The largest finite colour magnitude and variance the filters take (docs/reliability.md): squares
// and sums of colours, and variances times the weights, stay finite in float. Beyond them a value
// is not a measurement (3e38 made the whole output NaN): an error, as a negative variance is.
constexpr float kMaxInputColor = 1e15f;
constexpr float kMaxInputVariance = 1e30f;

InputError outOfRangeError(const char* buffer, float value, float limit, size_t pixel, int width) {
    char v[32], l[32];
    std::snprintf(v, sizeof v, "%g", double(value));
    std::snprintf(l, sizeof l, "%g", double(limit));
    return InputError(std::string(buffer) + " buffer has a value of magnitude " + v + " (above " + l + ") at pixel (" +
                      std::to_string(pixel % size_t(width)) + ", " + std::to_string(pixel / size_t(width)) + ")");
}

InputError negativeVarianceError(float value, size_t pixel, int width) {
    return InputError("variance buffer has a negative value (" + std::to_string(value) + ") at pixel (" +
                      std::to_string(pixel % size_t(width)) + ", " + std::to_string(pixel / size_t(width)) + ")");
}

void requireColorInRange(const Image& color) {
    if (color.device() != Device::Cpu) return;
    for (size_t i = 0; i < 3 * color.plane(); ++i) {
        const float v = color.data()[i];
        if (std::isfinite(v) && std::fabs(v) > kMaxInputColor)
            throw outOfRangeError("color", v, kMaxInputColor, i % color.plane(), color.width());
    }
}

PreparedInputs prepareInputs(const DenoiseInputs& in, const DenoiseOptions& o, DenoiseReport& rep) {
    if (!in.color || in.color->empty()) throw InputError("no color buffer given");
    const Image& color = *in.color;
    if (color.channels() < 3) throw InputError("color buffer needs 3 channels");
    checkBuffer(in.variance, color, "variance");
    checkBuffer(in.albedo, color, "albedo");
    checkBuffer(in.normal, color, "normal");
    checkBuffer(in.position, color, "position");
    checkBuffer(in.depth, color, "depth");
    checkBuffer(in.ids, color, "ids");
    checkBuffer(in.emission, color, "emission");
    validateDenoiseOptions(o);
    PreparedInputs p;
    // GPU inputs (the viewer's running means, DLPack arrays) are not downloaded for these scans:
    // denoiseCuda counts the non-finite pixels and checks the variance on the GPU
    // (checkDeviceVariance). Only the noise estimate below needs the colour on the host.
    const bool colorOnHost = color.device() == Device::Cpu;
    rep.nonFinitePixels = 0;
    if (colorOnHost) {
        requireColorInRange(color);
        for (size_t i = 0; i < color.plane(); ++i) {
            if (!std::isfinite(color.data()[i]) || !std::isfinite(color.data()[i + color.plane()]) ||
                !std::isfinite(color.data()[i + 2 * color.plane()]))
                ++rep.nonFinitePixels;
        }
    }
    std::string used = "color";
    if (in.variance) {
        if (in.variance->device() == Device::Cpu) {
            const Image& vh = *in.variance;
            for (size_t i = 0; i < 3 * vh.plane(); ++i) {
                if (vh.data()[i] < 0) throw negativeVarianceError(vh.data()[i], i % vh.plane(), vh.width());
                if (std::isfinite(vh.data()[i]) && vh.data()[i] > kMaxInputVariance)
                    throw outOfRangeError("variance", vh.data()[i], kMaxInputVariance, i % vh.plane(), vh.width());
            }
        }
        used += ",variance";
        rep.noiseEstimated = false;
    } else {
        // No variance: Donoho's MAD estimate, constant over the image. A GPU colour is estimated
        // on the GPU, and denoiseCuda fills the constant variance there (estimatedVariance empty).
        rep.noiseEstimated = true;
        if (colorOnHost) {
            const Image* albedo = o.demodulate && in.albedo && in.albedo->device() == Device::Cpu ? in.albedo : nullptr;
            estimateNoiseSigma(color, albedo, o.albedoEpsilon, o.albedoFloor, rep.noiseSigma);
            p.estimatedVariance = Image(color.width(), color.height(), 3, Device::Cpu);
            for (int c = 0; c < 3; ++c) {
                const float v = rep.noiseSigma[c] * rep.noiseSigma[c];
                std::fill(p.estimatedVariance.data() + c * p.estimatedVariance.plane(),
                          p.estimatedVariance.data() + (c + 1) * p.estimatedVariance.plane(), v);
            }
        } else {
            estimateNoiseSigmaCuda(color, o.demodulate ? in.albedo : nullptr, o.albedoEpsilon, o.albedoFloor, rep.noiseSigma);
        }
    }
    const DenoiseBufferUse use = denoiseBufferUse(o, o.method);
    const bool learned = o.method == DenoiseMethod::Learned;
    if (in.albedo) used += use.albedo ? ",albedo" : ",albedo(unused: demodulation off)";
    if (in.normal) used += ",normal";
    if (in.position) used += use.position ? ",position" : ",position(unused by learned)";
    // Depth steers the depth stop (sigma-depth > 0), the learned network, and, without a usable
    // variance, the noise estimate's geometric edges.
    if (in.depth) used += learned || o.eaw.sigmaDepth > 0 || rep.noiseEstimated ? ",depth" : ",depth(unused: sigma-depth 0)";
    if (in.ids) used += use.ids ? ",ids" : learned ? ",ids(unused by learned)" : ",ids(unused)";
    if (in.emission) used += ",emission";
    rep.buffersUsed = used;
    return p;
}

}  // namespace filters

// The learned filter's network reads depth (and no position or ids); EAW/SURE the reverse by default.
DenoiseBufferUse denoiseBufferUse(const DenoiseOptions& o, DenoiseMethod resolved) {
    const bool learned = resolved == DenoiseMethod::Learned;
    DenoiseBufferUse u;
    u.albedo = o.demodulate;
    u.position = !learned;
    // Depth is read by EAW/SURE too when the variance turns out unusable (the noise estimate's
    // edges), which only reading the variance tells: always.
    u.depth = true;
    u.ids = !learned && o.eaw.useIds;
    return u;
}

namespace filters {

void setNoiseEstimate(DriverConfig& cfg, const DenoiseReport& rep) {
    if (cfg.varianceGiven) return;
    cfg.noiseRadius = kNoiseRadius;
    for (int c = 0; c < 3; ++c) cfg.noiseFloorVar[c] = kNoiseFloorFraction * rep.noiseSigma[c] * rep.noiseSigma[c];
}

static ImageView viewOf(const Image* img) { return img ? img->view() : ImageView{}; }

static double meanLuminance(const Image& img) {
    double s = 0;
    size_t n = 0;
    for (size_t i = 0; i < img.plane(); ++i) {
        const float l = lum(img.data()[i], img.data()[i + img.plane()], img.data()[i + 2 * img.plane()]);
        if (std::isfinite(l)) {
            s += l;
            ++n;
        }
    }
    return n ? s / double(n) : 0.0;
}

static DriverInputs driverInputsOf(const DenoiseInputs& in, const PreparedInputs& prep) {
    DriverInputs di;
    di.color = in.color->view();
    di.variance = in.variance ? in.variance->view() : prep.estimatedVariance.view();
    di.albedo = viewOf(in.albedo);
    di.normal = viewOf(in.normal);
    di.position = viewOf(in.position);
    di.depth = viewOf(in.depth);
    di.ids = viewOf(in.ids);
    di.emission = viewOf(in.emission);
    return di;
}

Image denoiseCpu(const DenoiseInputs& in, const DenoiseOptions& o, const PreparedInputs& prep, DenoiseReport& rep,
                 DriverDebug* debug) {
    const int w = in.color->width(), h = in.color->height();
    const DriverInputs di = driverInputsOf(in, prep);
    Image out(w, h, 3, Device::Cpu), after(w, h, 3, Device::Cpu), flag(w, h, 1, Device::Cpu);
    DriverOutputs dout;
    dout.out = out.view();
    dout.afterFirefly = after.view();
    dout.fireflyFlag = flag.view();
    if (debug && !debug->sureS.empty()) dout.sureS = debug->sureS.view();
    // A steady-clock read per stage (stages take >= 0.1 ms): always on, it costs nothing measurable.
    std::unique_ptr<StageClock> clock = makeStageClock(Device::Cpu);
    dout.clock = clock.get();
    Timer t;
    DriverConfig cfg{o};
    cfg.learned = prep.learned;
    cfg.varianceGiven = in.variance != nullptr;
    setNoiseEstimate(cfg, rep);
    clock->start();
    runDenoise(CpuExec{}, di, cfg, dout);
    rep.milliseconds = t.ms();
    clock->collect(rep.stages);
    rep.meanLuminanceIn = meanLuminance(*in.color);
    // `after` is c_0 = colour − emission after the pass: add the emission back so that both
    // figures are of the whole image (with the sky as emission, they differed by the sky).
    rep.meanLuminanceAfterFirefly = meanLuminance(after) + (in.emission ? meanLuminance(*in.emission) : 0.0);
    int clamped = 0;
    for (size_t i = 0; i < flag.plane(); ++i) clamped += flag.data()[i] > 0.5f;
    rep.firefliesClamped = clamped;
    return out;
}

}  // namespace filters

namespace {

// True when a host variance buffer holds no information: every value is 0 (or non-finite, which the
// filters treat as missing). A renderer at 1 sample per pixel writes exactly that (a one-sample
// mean has no variance estimate), and taken at face value it tells the filters the image is
// noise-free, so they would return it unchanged. A converged image still has tiny nonzero values.
bool varianceIsEmpty(const Image& v) {
    if (v.device() != Device::Cpu) return false;  // GPU buffers are taken as given
    const float* d = v.data();
    for (size_t i = 0, n = v.plane() * size_t(std::min(v.channels(), 3)); i < n; ++i)
        if (d[i] != 0.0f && std::isfinite(d[i])) return false;
    return true;
}

// What denoise() and learnedPlanes() do before the driver: an all-zero variance dropped, the
// inputs validated and the noise estimated (prepareInputs).
filters::PreparedInputs prepareCall(DenoiseInputs& inputs, const DenoiseOptions& options, DenoiseReport& rep) {
    rep = DenoiseReport{};
    const bool varianceIgnored = inputs.variance && inputs.color && !inputs.color->empty() &&
                                 inputs.variance->view().sameSize(inputs.color->view()) &&
                                 varianceIsEmpty(*inputs.variance);
    if (varianceIgnored) inputs.variance = nullptr;  // estimate the noise from the image instead
    filters::PreparedInputs prep = filters::prepareInputs(inputs, options, rep);
    if (varianceIgnored) {
        rep.varianceIgnored = true;
        rep.buffersUsed += ",variance(ignored: all zero, e.g. a 1-spp render; noise estimated)";
    }
    return prep;
}

void requireHostInputs(const DenoiseInputs& inputs) {
    for (const Image* img : {inputs.color, inputs.variance, inputs.albedo, inputs.normal, inputs.position,
                             inputs.depth, inputs.ids, inputs.emission})
        if (img && img->device() != Device::Cpu) {
            // Host path with device inputs: bring them over (rare; the CLI always passes host images).
            throw InputError("denoise on the CPU needs host images (got a CUDA image)");
        }
}

}  // namespace

Image denoise(const DenoiseInputs& given, const DenoiseOptions& options) {
    DenoiseReport local;
    DenoiseReport& rep = options.report ? *options.report : local;
    DenoiseInputs inputs = given;
    DenoiseOptions o = options;
    o.method = resolveDenoiseMethod(options.method, inputs);
    // The weights before any work: a bad file is an InputError naming it, nothing computed.
    LearnedWeights weights;
    if (o.method == DenoiseMethod::Learned)
        weights = o.learnedWeights.empty() ? LearnedWeights::builtin() : LearnedWeights::load(o.learnedWeights);
    filters::PreparedInputs prep = prepareCall(inputs, o, rep);
    prep.learned = weights;
    rep.methodUsed = o.method;
    if (o.device == Device::Cuda) {
        requireCuda();
        return filters::denoiseCuda(inputs, o, prep, rep);
    }
    requireHostInputs(inputs);
    return filters::denoiseCpu(inputs, o, prep, rep, nullptr);
}

namespace filters {

PreparedPlanes learnedPlanes(const DenoiseInputs& given, const DenoiseOptions& options) {
    DenoiseReport local;
    DenoiseReport& rep = options.report ? *options.report : local;
    DenoiseInputs in = given;
    const PreparedInputs prep = prepareCall(in, options, rep);
    requireHostInputs(in);
    const int w = in.color->width(), h = in.color->height();
    PreparedPlanes p;
    p.d = Image(w, h, 3), p.var = Image(w, h, 3), p.mod = Image(w, h, 3), p.emission = Image(w, h, 3);
    if (in.albedo && options.demodulate) p.albedo = Image(w, h, 3);
    if (in.normal) p.normal = Image(w, h, 3);
    if (in.depth) p.depth = Image(w, h, 1);
    DriverPlanes views;
    views.d = p.d.view(), views.var = p.var.view(), views.mod = p.mod.view(), views.emission = p.emission.view();
    views.albedo = viewOf(p.albedo.empty() ? nullptr : &p.albedo);
    views.normal = viewOf(p.normal.empty() ? nullptr : &p.normal);
    views.depth = viewOf(p.depth.empty() ? nullptr : &p.depth);
    DriverOutputs dout;
    dout.planes = &views;
    DriverConfig cfg{options};
    cfg.varianceGiven = in.variance != nullptr;
    setNoiseEstimate(cfg, rep);
    runDenoise(CpuExec{}, driverInputsOf(in, prep), cfg, dout);
    return p;
}

}  // namespace filters

}  // namespace atrous

#if !defined(ATROUS_HAVE_CUDA)
namespace atrous::filters {
Image denoiseCuda(const DenoiseInputs&, const DenoiseOptions&, const PreparedInputs&, DenoiseReport&) {
    noCudaBackend();
}
void estimateNoiseSigmaCuda(const Image&, const Image*, float, float, float[3]) {
    noCudaBackend();
}
}  // namespace atrous::filters
#endif

// The denoise() entry point: validates the inputs and parameters, estimates the noise when no
// variance buffer is given, and runs the driver (denoise_driver.h) on the CPU or, through
// src/cuda/cuda_denoise.cu, on the GPU.
#include "atrous/denoise.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/learned.h"
#include "atrous/params.h"
#include "core/parallel.h"
#include "atrous/timer.h"
#include "core/isa_dispatch.h"
#include "cpu/row_sums.h"
#include "filters/denoise_driver.h"
#include "filters/denoise_internal.h"
#include "filters/noise_estimate.h"
#include "filters/stage_clock.h"

namespace atrous {

// The ranges are params.h's table (one row per field); the library's own limits must agree.
static_assert(filters::kMaxLevels == 10 && filters::kMaxSureCandidates == 8, "update params.h's ranges");

void validateDenoiseOptions(const DenoiseOptions& o) { validateParams(o, denoiseParams()); }

namespace filters {

// Donoho's estimator on the finest detail of the unweighted B3 à-trous (MadDetail, noise_estimate.h):
// σ_d = median|d_0| / 0.6745; for white noise var(d_0) = σ² (1 + Σh² - 2 h(0)), so
// σ = σ_d / sqrt(0.7900...). Per channel, over finite pixels; of the demodulated colour when an
// albedo is given.
void estimateNoiseSigma(const Image& color, const Image* albedo, float eps, float floor, float sigma[3], Image* scratch) {
    globalNoiseSigma(CpuExec{}, color.view(), albedo ? albedo->view() : ImageView{}, eps, floor, sigma,
                     scratch ? scratch->view() : ImageView{});
}

static void checkBuffer(const Image* img, const Image& color, const char* name, int minChannels = 3) {
    if (!img) return;
    if (img->empty()) throw InputError(std::string(name) + " buffer is empty");
    if (img->width() != color.width() || img->height() != color.height())
        throw InputError(std::string(name) + " buffer is " + std::to_string(img->width()) + "x" +
                         std::to_string(img->height()) + " but the color is " + std::to_string(color.width()) + "x" +
                         std::to_string(color.height()));
    if (img->channels() < minChannels)
        throw InputError(std::string(name) + " buffer needs " + std::to_string(minChannels) +
                         (minChannels == 1 ? " channel" : " channels"));
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

namespace {

// One parallel pass over the host colour, variance and emission for what prepareInputs checks and
// the report counts: per band of rows, then the bands in order (the luminance sums are per row,
// rows added in order: deterministic, not the old sequential sum's last bits).
struct InputScan {
    size_t colorBad = SIZE_MAX;     // first planar index of a finite colour value beyond kMaxInputColor
    int nonFinite = 0;              // pixels with a non-finite colour channel
    double lumSum = 0, lumCount = 0;  // finite luminances of the colour
    bool varianceInformative = false;  // a finite nonzero variance value (varianceIsEmpty's test)
    size_t varianceBad = SIZE_MAX;  // first planar index of a negative or out-of-range variance
    double emissionLumSum = 0, emissionLumCount = 0;
};

InputScan scanInputs(const Image& color, const Image* variance, const Image* emission) {
    const int w = color.width(), h = color.height();
    const size_t plane = color.plane();
    constexpr int kBand = 16;
    const int bands = (h + kBand - 1) / kBand;
    std::vector<InputScan> part(static_cast<size_t>(bands));
    const ImageView c = color.view();
    const ImageView v = variance ? variance->view() : ImageView{};
    const ImageView e = emission ? emission->view() : ImageView{};
    cpu::parallelForIsa(cpu::activeIsa(), 0, bands, 1, [&](int b0, int b1) {
        for (int b = b0; b < b1; ++b) {
            InputScan& r = part[size_t(b)];
            const int y0 = b * kBand, y1 = std::min(h, y0 + kBand);
            for (int y = y0; y < y1; ++y) {
                const size_t o = size_t(y) * w;
                const float* ATROUS_RESTRICT cr = c.channel(0) + o;
                const float* ATROUS_RESTRICT cg = c.channel(1) + o;
                const float* ATROUS_RESTRICT cb = c.channel(2) + o;
                for (int ch = 0; ch < 3; ++ch) {
                    const float* ATROUS_RESTRICT a = c.channel(ch) + o;
                    int bad = 0;
#pragma omp simd reduction(| : bad)
                    for (int x = 0; x < w; ++x) bad |= (finite(a[x]) & (fabsf(a[x]) > kMaxInputColor)) ? 1 : 0;
                    if (bad)
                        for (int x = 0; x < w; ++x)
                            if (finite(a[x]) && fabsf(a[x]) > kMaxInputColor) {
                                r.colorBad = std::min(r.colorBad, size_t(ch) * plane + o + size_t(x));
                                break;
                            }
                }
                int nf = 0;
                double ls = 0, ln = 0;
                // (Vector lanes of partial sums: the report's means, deterministic for an ISA.)
#pragma omp simd reduction(+ : nf, ls, ln)
                for (int x = 0; x < w; ++x) {
                    nf += (finite(cr[x]) & finite(cg[x]) & finite(cb[x])) ? 0 : 1;
                    const float l = lum(cr[x], cg[x], cb[x]);
                    const bool ok = finite(l);
                    ls += ok ? double(l) : 0.0;
                    ln += ok ? 1.0 : 0.0;
                }
                r.nonFinite += nf;
                r.lumSum += ls, r.lumCount += ln;
                if (v.valid())
                    for (int ch = 0; ch < 3; ++ch) {
                        const float* ATROUS_RESTRICT a = v.channel(ch) + o;
                        int info = 0, bad = 0;
#pragma omp simd reduction(| : info, bad)
                        for (int x = 0; x < w; ++x) {
                            info |= (a[x] != 0.0f) & finite(a[x]) ? 1 : 0;
                            bad |= (a[x] < 0.0f) | (finite(a[x]) & (a[x] > kMaxInputVariance)) ? 1 : 0;
                        }
                        r.varianceInformative = r.varianceInformative || info;
                        if (bad)
                            for (int x = 0; x < w; ++x)
                                if (a[x] < 0.0f || (finite(a[x]) && a[x] > kMaxInputVariance)) {
                                    r.varianceBad = std::min(r.varianceBad, size_t(ch) * plane + o + size_t(x));
                                    break;
                                }
                    }
                if (e.valid()) {
                    double es = 0, en = 0;
                    cpu::finiteLuminanceRow(e.channel(0) + o, e.channel(1) + o, e.channel(2) + o, w, es, en);
                    r.emissionLumSum += es, r.emissionLumCount += en;
                }
            }
        }
    });
    InputScan all;
    for (const InputScan& r : part) {
        all.colorBad = std::min(all.colorBad, r.colorBad);
        all.nonFinite += r.nonFinite;
        all.lumSum += r.lumSum, all.lumCount += r.lumCount;
        all.varianceInformative = all.varianceInformative || r.varianceInformative;
        all.varianceBad = std::min(all.varianceBad, r.varianceBad);
        all.emissionLumSum += r.emissionLumSum, all.emissionLumCount += r.emissionLumCount;
    }
    return all;
}

}  // namespace

// True when a host variance buffer holds no information: every value is 0 (or non-finite, which the
// filters treat as missing). A renderer at 1 sample per pixel writes exactly that (a one-sample
// mean has no variance estimate), and taken at face value it tells the filters the image is
// noise-free, so they would return it unchanged. A converged image still has tiny nonzero values.
bool varianceIsEmpty(const Image& v) {
    if (v.device() != Device::Cpu) return false;  // GPU buffers are taken as given
    std::atomic<bool> informative{false};
    const size_t n = v.plane() * size_t(std::min(v.channels(), 3));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
        if (informative.load(std::memory_order_relaxed)) return;
        const float* d = v.data();
        for (size_t i = r.begin(); i < r.end(); ++i)
            if (d[i] != 0.0f && std::isfinite(d[i])) {
                informative.store(true, std::memory_order_relaxed);
                return;
            }
    });
    return !informative.load();
}

PreparedInputs prepareInputs(const DenoiseInputs& in, const DenoiseOptions& o, DenoiseReport& rep, bool deferNoiseSigma) {
    return prepareInputsDropping(in, o, rep, deferNoiseSigma, nullptr);
}

PreparedInputs prepareInputsDropping(const DenoiseInputs& given, const DenoiseOptions& o, DenoiseReport& rep,
                                     bool deferNoiseSigma, bool* varianceDropped) {
    DenoiseInputs in = given;
    if (!in.color || in.color->empty()) throw InputError("no color buffer given");
    const Image& color = *in.color;
    if (color.channels() < 3) throw InputError("color buffer needs 3 channels");
    checkBuffer(in.variance, color, "variance");
    checkBuffer(in.albedo, color, "albedo");
    checkBuffer(in.normal, color, "normal");
    checkBuffer(in.position, color, "position");
    checkBuffer(in.depth, color, "depth", 1);  // channel 0 is read
    checkBuffer(in.ids, color, "ids", 1);      // object id, and the material id in channel 1 when given
    checkBuffer(in.emission, color, "emission");
    validateDenoiseOptions(o);
    PreparedInputs p;
    // GPU inputs (the viewer's running means, DLPack arrays) are not downloaded for these scans:
    // denoiseCuda counts the non-finite pixels and checks the variance on the GPU
    // (checkDeviceVariance). Only the noise estimate below needs the colour on the host.
    const bool colorOnHost = color.device() == Device::Cpu;
    rep.nonFinitePixels = 0;
    if (colorOnHost) {
        const Image* hostVariance = in.variance && in.variance->device() == Device::Cpu ? in.variance : nullptr;
        const Image* hostEmission = in.emission && in.emission->device() == Device::Cpu ? in.emission : nullptr;
        const InputScan scan = scanInputs(color, hostVariance, hostEmission);
        if (scan.colorBad != SIZE_MAX) {
            const float v = color.data()[scan.colorBad];
            throw outOfRangeError("color", v, kMaxInputColor, scan.colorBad % color.plane(), color.width());
        }
        rep.nonFinitePixels = scan.nonFinite;
        p.meanLuminanceIn = scan.lumCount > 0 ? scan.lumSum / scan.lumCount : 0.0;
        if (varianceDropped && hostVariance && !scan.varianceInformative) {
            // All zero (or non-finite): no information, dropped before its values are checked.
            in.variance = nullptr, hostVariance = nullptr;
            *varianceDropped = true;
        }
        p.meanLuminanceEmission = scan.emissionLumCount > 0 ? scan.emissionLumSum / scan.emissionLumCount : 0.0;
        if (hostVariance && scan.varianceBad != SIZE_MAX) {
            const Image& vh = *hostVariance;
            const float v = vh.data()[scan.varianceBad];
            if (v < 0) throw negativeVarianceError(v, scan.varianceBad % vh.plane(), vh.width());
            throw outOfRangeError("variance", v, kMaxInputVariance, scan.varianceBad % vh.plane(), vh.width());
        }
    } else if (in.variance && in.variance->device() == Device::Cpu) {
        const Image& vh = *in.variance;
        for (size_t i = 0; i < 3 * vh.plane(); ++i) {
            if (vh.data()[i] < 0) throw negativeVarianceError(vh.data()[i], i % vh.plane(), vh.width());
            if (std::isfinite(vh.data()[i]) && vh.data()[i] > kMaxInputVariance)
                throw outOfRangeError("variance", vh.data()[i], kMaxInputVariance, i % vh.plane(), vh.width());
        }
    }
    std::string used = "color";
    if (in.variance) {
        used += ",variance";
        rep.noiseEstimated = false;
    } else {
        // No variance: Donoho's MAD estimate, the per-pixel estimate's floor. A GPU colour is
        // estimated on the GPU, and denoiseCuda fills the constant variance there (estimatedVariance
        // empty); a host colour on the host (by denoiseCpu when deferred), and the GPU path uploads
        // the constant it is given.
        rep.noiseEstimated = true;
        if (colorOnHost) {
            if (!deferNoiseSigma || o.device == Device::Cuda) {
                const Image* albedo = o.demodulate && in.albedo && in.albedo->device() == Device::Cpu ? in.albedo : nullptr;
                estimateNoiseSigma(color, albedo, o.albedoEpsilon, o.albedoFloor, rep.noiseSigma);
                p.sigmaEstimated = true;
            }
            if (o.device == Device::Cuda) {
                p.estimatedVariance = Image::uninitialized(color.width(), color.height(), 3, Device::Cpu);
                for (int c = 0; c < 3; ++c) {
                    const float v = rep.noiseSigma[c] * rep.noiseSigma[c];
                    std::fill(p.estimatedVariance.data() + c * p.estimatedVariance.plane(),
                              p.estimatedVariance.data() + (c + 1) * p.estimatedVariance.plane(), v);
                }
            }
        } else {
            estimateNoiseSigmaCuda(color, o.demodulate ? in.albedo : nullptr, o.albedoEpsilon, o.albedoFloor, rep.noiseSigma);
            p.sigmaEstimated = true;
        }
    }
    const DenoiseBufferUse use = denoiseBufferUse(o, o.method);
    const bool learned = o.method == DenoiseMethod::Learned;
    const DenoiseMethodInfo& info = denoiseMethodInfo(o.method);
    const bool network = info.usesWeights;  // the learned cascade runs
    const std::string by = std::string(" by ") + info.name + ")";
    if (in.albedo) used += use.albedo ? ",albedo" : ",albedo(unused: demodulation off)";
    if (in.normal) used += use.normal ? ",normal" : ",normal(unused" + by;
    if (in.position) used += use.position ? ",position" : ",position(unused" + by;
    // Depth steers the depth stop (sigma-depth > 0), the learned network, and, without a usable
    // variance, the noise estimate's geometric edges.
    if (in.depth) used += network || info.registered() || o.eaw.sigmaDepth > 0 || rep.noiseEstimated ? ",depth" : ",depth(unused: sigma-depth 0)";
    if (in.ids) used += use.ids ? ",ids" : learned || info.registered() ? ",ids(unused" + by : ",ids(unused)";
    if (in.emission) used += ",emission";
    rep.buffersUsed = used;
    return p;
}

}  // namespace filters

// The learned filter's network reads depth (and no position or ids); EAW/SURE the reverse by
// default; Blend what both read.
DenoiseBufferUse denoiseBufferUse(const DenoiseOptions& o, DenoiseMethod resolved) {
    const DenoiseMethodInfo& info = denoiseMethodInfo(resolved);
    if (info.registered()) {
        DenoiseBufferUse u = info.reads;
        u.albedo = o.demodulate;  // the preparation demodulates by it, whether the cascade reads it or not
        u.depth = true;           // the noise estimate's edges (below)
        u.variance = u.emission = true;  // the preparation's (the planes' variance, the emission split)
        return u;
    }
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

static DriverInputs driverInputsOf(const DenoiseInputs& in, const PreparedInputs& prep) {
    DriverInputs di;
    di.color = in.color->view();
    // Without a variance buffer the CPU driver makes its own from the estimate (GlobalVariance);
    // the GPU path is given the constant estimate.
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
                 DriverDebug* debug, const HandedOver* stores) {
    DriverInputs di = driverInputsOf(in, prep);
    if (stores) di.colorStore = stores->color, di.varianceStore = stores->variance, di.emissionStore = stores->emission;
    Image out;
    DriverReport dr;
    DriverOutputs dout;
    dout.result = &out;  // remodulated in the driver's own planes
    dout.report = &dr;
    if (debug && !debug->sureS.empty()) dout.sureS = debug->sureS.view();
    // A steady-clock read per stage (stages take >= 0.1 ms): always on, it costs nothing measurable.
    std::unique_ptr<StageClock> clock = makeStageClock(Device::Cpu);
    dout.clock = clock.get();
    Timer t;
    DriverConfig cfg{o};
    cfg.learned = prep.learned;
    cfg.varianceGiven = in.variance != nullptr;
    clock->start();
    // Without a variance, the planes the driver fills with the estimate (var(c_0)): a handed-over
    // variance that was dropped (all zero) serves, or one made here, which the global estimate
    // first uses for its detail planes (one 3-plane image, first touched once).
    Image estimate;
    if (!in.variance && !(stores && stores->variance && !stores->variance->empty())) {
        estimate = Image::uninitialized(in.color->width(), in.color->height(), 3);
        di.varianceStore = &estimate;
    }
    if (!in.variance && !prep.sigmaEstimated) {
        // The global estimate (Donoho's MAD), timed as a stage of its own.
        const Image* albedo = o.demodulate && in.albedo ? in.albedo : nullptr;
        estimateNoiseSigma(*in.color, albedo, o.albedoEpsilon, o.albedoFloor, rep.noiseSigma,
                           estimate.empty() ? di.varianceStore : &estimate);
        markStage(dout.clock, "noise sigma");
    }
    setNoiseEstimate(cfg, rep);
    runDenoise(CpuExec{}, di, cfg, dout);
    rep.milliseconds = t.ms();
    clock->collect(rep.stages);
    rep.meanLuminanceIn = prep.meanLuminanceIn;
    // c_0 after the pass is colour − emission: the emission's mean is added back so that both
    // figures are of the whole image (with the sky as emission, they differed by the sky).
    rep.meanLuminanceAfterFirefly =
        (dr.lumAfterCount > 0 ? dr.lumAfterSum / dr.lumAfterCount : 0.0) + (in.emission ? prep.meanLuminanceEmission : 0.0);
    rep.firefliesClamped = dr.firefliesClamped;
    return out;
}

}  // namespace filters

namespace {

// What denoise() and learnedPlanes() do before the driver: an all-zero variance dropped, the
// inputs validated and the noise estimated (prepareInputs; on the CPU denoise() leaves the global
// estimate to denoiseCpu, which times it).
filters::PreparedInputs prepareCall(DenoiseInputs& inputs, const DenoiseOptions& options, DenoiseReport& rep,
                                    bool deferNoiseSigma = false) {
    rep = DenoiseReport{};
    // A host variance of 3 channels or more is tested in prepareInputs' one scan of the inputs
    // (then dropped before its values are checked); any other as before, on its own.
    const bool fused = inputs.variance && inputs.color && !inputs.color->empty() &&
                       inputs.color->device() == Device::Cpu && inputs.variance->device() == Device::Cpu &&
                       inputs.variance->channels() >= 3;
    bool varianceIgnored = !fused && inputs.variance && inputs.color && !inputs.color->empty() &&
                           inputs.variance->view().sameSize(inputs.color->view()) &&
                           filters::varianceIsEmpty(*inputs.variance);
    if (varianceIgnored) inputs.variance = nullptr;  // estimate the noise from the image instead
    filters::PreparedInputs prep = filters::prepareInputsDropping(inputs, options, rep, deferNoiseSigma,
                                                                  fused ? &varianceIgnored : nullptr);
    if (varianceIgnored) {
        inputs.variance = nullptr;
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

// denoise() with, optionally, the caller's images handed over (used on the CPU only).
// timed: the CUDA path records its stages (denoiseWithReport; the CPU's clock costs nothing).
Image denoiseWith(const DenoiseInputs& given, const DenoiseOptions& options, const filters::HandedOver* stores,
                  DenoiseReport& rep, bool timed, filters::DriverDebug* debug = nullptr) {
    DenoiseInputs inputs = given;
    DenoiseOptions o = options;
    o.method = resolveDenoiseMethod(options.method, inputs);
    const DenoiseMethodInfo& info = denoiseMethodInfo(o.method);
    if (info.registered() && !(o.device == Device::Cuda ? info.cuda : info.cpu))
        throw InputError(std::string("method '") + info.name + "' has no cascade for " +
                         (o.device == Device::Cuda ? "CUDA" : "the CPU"));
    LearnedWeights weights;
    if (info.usesWeights) weights = o.weights.impl ? o.weights : LearnedWeights::builtin();
    filters::PreparedInputs prep = prepareCall(inputs, o, rep, true);
    prep.learned = weights;
    // ids of one channel (the object id alone): the material id is then the same everywhere.
    Image ids2;
    if (inputs.ids && inputs.ids->channels() == 1) {
        const Image host = inputs.ids->to(Device::Cpu);
        ids2 = Image(host.width(), host.height(), 2);
        std::copy(host.data(), host.data() + host.plane(), ids2.data());
        if (inputs.ids->device() != Device::Cpu) ids2 = ids2.to(inputs.ids->device());
        inputs.ids = &ids2;
    }
    rep.methodUsed = o.method;
    if (o.device == Device::Cuda) {
        requireCuda();
        return filters::denoiseCuda(inputs, o, prep, rep, timed);
    }
    requireHostInputs(inputs);
    return filters::denoiseCpu(inputs, o, prep, rep, debug, stores);
}

}  // namespace

Image denoise(const DenoiseInputs& given, const DenoiseOptions& options) {
    DenoiseReport rep;
    return denoiseWith(given, options, nullptr, rep, false);
}

DenoiseResult denoiseWithReport(const DenoiseInputs& given, const DenoiseOptions& options) {
    DenoiseResult r;
    r.image = denoiseWith(given, options, nullptr, r.report, true);
    return r;
}

namespace {

DenoiseInputs inputsOf(const DenoiseBuffers& buffers, filters::HandedOver& stores) {
    stores.color = buffers.color, stores.variance = buffers.variance, stores.emission = buffers.emission;
    DenoiseInputs in;
    in.color = buffers.color, in.variance = buffers.variance, in.albedo = buffers.albedo, in.normal = buffers.normal;
    in.position = buffers.position, in.depth = buffers.depth, in.ids = buffers.ids, in.emission = buffers.emission;
    return in;
}

}  // namespace

Image denoise(DenoiseBuffers& buffers, const DenoiseOptions& options) {
    filters::HandedOver stores;
    const DenoiseInputs in = inputsOf(buffers, stores);
    DenoiseReport rep;
    return denoiseWith(in, options, &stores, rep, false);
}

DenoiseResult denoiseWithReport(DenoiseBuffers& buffers, const DenoiseOptions& options) {
    filters::HandedOver stores;
    const DenoiseInputs in = inputsOf(buffers, stores);
    DenoiseResult r;
    r.image = denoiseWith(in, options, &stores, r.report, true);
    return r;
}

SureFractionsResult denoiseWithSureFractions(const DenoiseInputs& inputs, const DenoiseOptions& options) {
    if (options.method != DenoiseMethod::Sure || options.device != Device::Cpu)
        throw InputError("SURE's fractions: the method must be sure and the device the CPU");
    if (!inputs.color || inputs.color->empty()) throw InputError("missing color buffer");
    filters::DriverDebug dbg;
    dbg.sureS = Image(inputs.color->width(), inputs.color->height(), options.eaw.levels);
    SureFractionsResult r;
    r.image = denoiseWith(inputs, options, nullptr, r.report, true, &dbg);
    r.fractions = std::move(dbg.sureS);
    return r;
}

PreparedPlanes learnedPlanes(const DenoiseInputs& given, const DenoiseOptions& options) {
    DenoiseReport rep;
    DenoiseInputs in = given;
    const filters::PreparedInputs prep = prepareCall(in, options, rep);
    requireHostInputs(in);
    const int w = in.color->width(), h = in.color->height();
    PreparedPlanes p;
    p.d = Image(w, h, 3), p.var = Image(w, h, 3), p.mod = Image(w, h, 3), p.emission = Image(w, h, 3);
    if (in.albedo && options.demodulate) p.albedo = Image(w, h, 3);
    if (in.normal) p.normal = Image(w, h, 3);
    if (in.depth) p.depth = Image(w, h, 1);
    filters::DriverPlanes views;
    views.d = p.d.view(), views.var = p.var.view(), views.mod = p.mod.view(), views.emission = p.emission.view();
    views.albedo = filters::viewOf(p.albedo.empty() ? nullptr : &p.albedo);
    views.normal = filters::viewOf(p.normal.empty() ? nullptr : &p.normal);
    views.depth = filters::viewOf(p.depth.empty() ? nullptr : &p.depth);
    filters::DriverOutputs dout;
    dout.planes = &views;
    filters::DriverConfig cfg{options};
    cfg.opts.method = DenoiseMethod::Learned;  // the planes of the learned method, whatever options.method says
    cfg.varianceGiven = in.variance != nullptr;
    filters::setNoiseEstimate(cfg, rep);
    filters::runDenoise(CpuExec{}, filters::driverInputsOf(in, prep), cfg, dout);
    return p;
}

}  // namespace atrous

#if !defined(ATROUS_HAVE_CUDA)
namespace atrous::filters {
Image denoiseCuda(const DenoiseInputs&, const DenoiseOptions&, const PreparedInputs&, DenoiseReport&, bool) {
    noCudaBackend();
}
void estimateNoiseSigmaCuda(const Image&, const Image*, float, float, float[3]) {
    noCudaBackend();
}
}  // namespace atrous::filters
#endif

// The still path's input checks (denoise(), docs/reliability.md): sizes and channels, the colour's
// and the variance's ranges, the non-finite count and the report's means in one scan of the host
// inputs, an all-zero variance dropped, and the global noise estimate when no variance is given.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/params.h"
#include "core/parallel.h"
#include "core/isa_dispatch.h"
#include "cpu/row_sums.h"
#include "filters/denoise_internal.h"
#include "filters/noise_estimate.h"

namespace atrous {

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

namespace {

void checkBuffer(const Image* img, const Image& color, const char* name, int minChannels = 3) {
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

}  // namespace

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

// One parallel pass over the host colour, variance and emission for what checkInputs checks and
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

namespace {

void checkSizes(const Frame& in) {
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
}

InputError varianceError(const Image& v, size_t index) {
    const float x = v.data()[index];
    if (x < 0) return negativeVarianceError(x, index % v.plane(), v.width());
    return outOfRangeError("variance", x, kMaxInputVariance, index % v.plane(), v.width());
}

// The one scan of a host colour (with a host variance and emission): the colour's range, the
// non-finite count, the means, and an all-zero variance dropped (varianceDropped given) before its
// values are checked. A GPU colour is not downloaded for it: denoiseCuda counts the non-finite
// pixels and checks the variance on the GPU (checkDeviceVariance); a host variance beside it is
// checked here.
void scanHost(Frame& in, CheckedInputs& p, DenoiseReport& rep, bool* varianceDropped) {
    const Image& color = *in.color;
    rep.nonFinitePixels = 0;
    const Image* hostVariance = in.variance && in.variance->device() == Device::Cpu ? in.variance : nullptr;
    if (color.device() != Device::Cpu) {
        if (!hostVariance) return;
        const Image& vh = *hostVariance;
        for (size_t i = 0; i < 3 * vh.plane(); ++i)
            if (vh.data()[i] < 0 || (std::isfinite(vh.data()[i]) && vh.data()[i] > kMaxInputVariance)) throw varianceError(vh, i);
        return;
    }
    const Image* hostEmission = in.emission && in.emission->device() == Device::Cpu ? in.emission : nullptr;
    const InputScan scan = scanInputs(color, hostVariance, hostEmission);
    if (scan.colorBad != SIZE_MAX)
        throw outOfRangeError("color", color.data()[scan.colorBad], kMaxInputColor, scan.colorBad % color.plane(), color.width());
    rep.nonFinitePixels = scan.nonFinite;
    // An all-NaN render would come out black (every pixel repaired from nothing): refused, with the
    // message the readers give (io::requireFinitePixel), for every caller alike.
    if (color.plane() > 0 && size_t(scan.nonFinite) == color.plane())
        throw InputError("color buffer has no finite pixel (every pixel has a NaN or an infinite value): nothing to denoise");
    p.meanLuminanceIn = scan.lumCount > 0 ? scan.lumSum / scan.lumCount : 0.0;
    if (varianceDropped && hostVariance && !scan.varianceInformative) {
        // All zero (or non-finite): no information, dropped before its values are checked.
        in.variance = nullptr, hostVariance = nullptr;
        *varianceDropped = true;
    }
    p.meanLuminanceEmission = scan.emissionLumCount > 0 ? scan.emissionLumSum / scan.emissionLumCount : 0.0;
    if (hostVariance && scan.varianceBad != SIZE_MAX) throw varianceError(*hostVariance, scan.varianceBad);
}

// No variance: Donoho's MAD estimate, the per-pixel estimate's floor. A GPU colour is estimated on
// the GPU, and denoiseCuda fills the constant variance there (estimatedVariance empty); a host
// colour on the host (by denoiseCpu when deferred), and the GPU path uploads the constant it is
// given.
void estimateGlobalNoise(const Frame& in, const DenoiseOptions& o, CheckedInputs& p, DenoiseReport& rep, bool deferNoiseSigma) {
    const Image& color = *in.color;
    if (color.device() != Device::Cpu) {
        estimateNoiseSigmaCuda(color, o.demodulate ? in.albedo : nullptr, o.albedoEpsilon, o.albedoFloor, rep.noiseSigma);
        p.sigmaEstimated = true;
        return;
    }
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
}

}  // namespace

std::string buffersUsed(const Frame& in, const DenoiseOptions& o, bool noiseEstimated) {
    std::string used = "color";
    for (Buffer b : {Buffer::Variance, Buffer::Albedo, Buffer::Normal, Buffer::Position, Buffer::Depth, Buffer::ObjectId,
                     Buffer::Emission}) {
        if (!in.get(b)) continue;
        const std::string why = unusedReason(b, o, o.method, noiseEstimated);
        used += std::string(",") + (b == Buffer::ObjectId ? "ids" : bufferName(b));
        if (!why.empty()) used += why.rfind("by ", 0) == 0 ? "(unused " + why + ")" : "(unused: " + why + ")";
    }
    return used;
}

CheckedInputs checkInputs(const Frame& given, const DenoiseOptions& o, DenoiseReport& rep, bool deferNoiseSigma,
                          bool* varianceDropped) {
    Frame in = given;
    checkSizes(in);
    validateDenoiseOptions(o);
    if (o.method == DenoiseMethod::Refine && (!in.albedo || in.albedo->empty() || !in.normal || in.normal->empty()))
        throw InputError("method 'refine' needs an albedo and a normal buffer (its network reads them); without "
                         "them, sure is the same filter without the network");
    CheckedInputs p;
    scanHost(in, p, rep, varianceDropped);
    rep.noiseEstimated = !in.variance;
    if (rep.noiseEstimated) estimateGlobalNoise(in, o, p, rep, deferNoiseSigma);
    rep.buffersUsed = buffersUsed(in, o, rep.noiseEstimated);
    return p;
}

void setNoiseEstimate(StillConfig& cfg, const DenoiseReport& rep) {
    if (cfg.varianceGiven) return;
    cfg.noiseRadius = kNoiseRadius;
    for (int c = 0; c < 3; ++c) cfg.noiseFloorVar[c] = kNoiseFloorFraction * rep.noiseSigma[c] * rep.noiseSigma[c];
}

}  // namespace filters
}  // namespace atrous

// SVGF: parameter checks, frame checks, the public SvgfDenoiser and the CPU instantiation of the
// shared driver (the CUDA one is in src/cuda/cuda_svgf.cu).
#include "atrous/svgf.h"

#include <cmath>
#include <string>

#include "atrous/error.h"
#include "core/parallel.h"
#include "filters/svgf_pipeline.h"

namespace atrous {

namespace {

void requireRange(bool ok, const char* field, const std::string& rule) {
    if (!ok) throw InputError(std::string("SVGF parameter ") + field + " " + rule);
}

// At least 1e-6: σ's inverse squares stay finite (at 1e-20 the whole output was NaN).
bool finitePositive(float v) { return std::isfinite(v) && v >= 1e-6f; }

}  // namespace

void validateSvgfParams(const SvgfParams& p) {
    requireRange(finitePositive(p.sigmaL), "sigmaL", "must be a finite number >= 1e-6");
    requireRange(std::isfinite(p.sigmaN) && p.sigmaN >= 0.0f, "sigmaN", "must be a finite number >= 0");
    requireRange(finitePositive(p.sigmaZ), "sigmaZ", "must be a finite number >= 1e-6");
    requireRange(p.alpha > 0.0f && p.alpha <= 1.0f, "alpha", "must be in (0, 1]");
    requireRange(p.momentsAlpha > 0.0f && p.momentsAlpha <= 1.0f, "momentsAlpha", "must be in (0, 1]");
    requireRange(p.historyCap >= 1 && p.historyCap <= 1 << 20, "historyCap", "must be in [1, 1048576]");
    requireRange(p.levels >= 0 && p.levels <= 10, "levels", "must be in [0, 10]");
    // levels 0 (temporal accumulation only) works with the default tap 0: there is no filtered
    // level to feed back, so the history is the accumulation (as with -1).
    requireRange(p.feedbackTap >= -1 && (p.feedbackTap < p.levels || (p.levels == 0 && p.feedbackTap == 0)),
                 "feedbackTap",
                 "must be in [-1, levels - 1] (-1 = unfiltered accumulation; got " + std::to_string(p.feedbackTap) +
                     " with levels " + std::to_string(p.levels) + ")");
    requireRange(p.spatialVarianceFrames >= 1 && p.spatialVarianceFrames <= 1 << 20, "spatialVarianceFrames",
                 "must be in [1, 1048576]");
    requireRange(std::isfinite(p.reprojectDepthTolerance) && p.reprojectDepthTolerance >= 0.0f,
                 "reprojectDepthTolerance", "must be a finite number >= 0");
    requireRange(p.reprojectNormalCos >= -1.0f && p.reprojectNormalCos <= 1.0f, "reprojectNormalCos", "must be in [-1, 1]");
    requireRange(p.taaAlpha > 0.0f && p.taaAlpha <= 1.0f, "taaAlpha", "must be in (0, 1]");
    requireRange(std::isfinite(p.historyClip) && p.historyClip >= 0.0f, "historyClip", "must be a finite number >= 0 (0 = off)");
    requireRange(p.emissionAlpha > 0.0f && p.emissionAlpha <= 1.0f, "emissionAlpha", "must be in (0, 1]");
    requireRange(std::isfinite(p.emissionMotionAlpha) && p.emissionMotionAlpha >= 0.0f, "emissionMotionAlpha",
                 "must be a finite number >= 0");
}

namespace svgf {

void checkFrame(const SvgfFrame& f) {
    if (!f.color || f.color->empty()) throw InputError("SVGF frame: the color buffer is missing");
    const int w = f.color->width(), h = f.color->height();
    auto check = [&](const Image* img, const char* name, int channels) {
        if (!img) return;
        if (img->empty()) throw InputError(std::string("SVGF frame: the ") + name + " buffer is empty");
        if (img->width() != w || img->height() != h)
            throw InputError(std::string("SVGF frame: the ") + name + " buffer is " + std::to_string(img->width()) + "x" +
                             std::to_string(img->height()) + " but color is " + std::to_string(w) + "x" + std::to_string(h));
        if (img->channels() < channels)
            throw InputError(std::string("SVGF frame: the ") + name + " buffer has " + std::to_string(img->channels()) +
                             " channel(s), needs " + std::to_string(channels));
    };
    check(f.color, "color", 3);
    check(f.albedo, "albedo", 3);
    check(f.normal, "normal", 3);
    check(f.depth, "depth", 1);
    check(f.ids, "ids", 1);
    check(f.motion, "motion", 2);
    check(f.emission, "emission", 3);
}

}  // namespace svgf

namespace detail {

std::unique_ptr<SvgfBackend> makeSvgfCpuBackend(const SvgfParams& params) {
    return std::make_unique<svgf::SvgfBackendImpl<CpuExec>>(params);
}

#if !defined(ATROUS_HAVE_CUDA)
std::unique_ptr<SvgfBackend> makeSvgfCudaBackend(const SvgfParams&) {
    throw InputError("SVGF on cuda: this build of atrous has no CUDA backend (nvcc was not found at build time)");
}
#endif

}  // namespace detail

SvgfDenoiser::SvgfDenoiser(const SvgfParams& params, Device device) : mParams(params), mDevice(device) {
    validateSvgfParams(params);
    if (device == Device::Cuda) {
        if (!cudaAvailable()) throw InputError("SVGF on cuda: no CUDA backend or no CUDA-capable GPU is available");
        mImpl = detail::makeSvgfCudaBackend(params);
    } else {
        mImpl = detail::makeSvgfCpuBackend(params);
    }
}

SvgfDenoiser::~SvgfDenoiser() = default;
SvgfDenoiser::SvgfDenoiser(SvgfDenoiser&&) noexcept = default;
SvgfDenoiser& SvgfDenoiser::operator=(SvgfDenoiser&&) noexcept = default;

Image SvgfDenoiser::denoiseFrame(const SvgfFrame& frame) { return mImpl->denoiseFrame(frame); }

const Image& SvgfDenoiser::denoiseFrameOnDevice(const SvgfFrame& frame) { return mImpl->denoiseFrameOnDevice(frame); }

void SvgfDenoiser::reset() { mImpl->reset(); }

void SvgfDenoiser::setReport(SvgfReport* report) { mImpl->setReport(report); }

}  // namespace atrous

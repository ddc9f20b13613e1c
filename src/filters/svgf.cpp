// SVGF: parameter checks, frame checks, the public SvgfDenoiser and the CPU instantiation of the
// shared driver (the CUDA one is in src/cuda/cuda_svgf.cu).
#include "atrous/svgf.h"

#include <string>

#include "atrous/error.h"
#include "atrous/params.h"
#include "core/parallel.h"
#include "filters/denoise_internal.h"
#include "filters/svgf_pipeline.h"

namespace atrous {

// The ranges are params.h's table (one row per field).
void validateSvgfParams(const SvgfParams& p) { validateParams(p, svgfParams()); }

namespace svgf {

void checkFrame(const Frame& f) {
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
    // The still filters' colour rule: beyond ±1e15 the history's squares overflow.
    filters::requireColorInRange(*f.color);
}

}  // namespace svgf

namespace detail {

std::unique_ptr<SvgfBackend> makeSvgfCpuBackend(const SvgfParams& params) {
    return std::make_unique<svgf::SvgfBackendImpl<CpuExec>>(params);
}

#if !defined(ATROUS_HAVE_CUDA)
std::unique_ptr<SvgfBackend> makeSvgfCudaBackend(const SvgfParams&) {
    noCudaBackend();
}
#endif

}  // namespace detail

SvgfDenoiser::SvgfDenoiser(const SvgfParams& params, Device device, const LearnedWeights& learnedWeights)
    : mParams(params), mDevice(device) {
    validateSvgfParams(params);
    if (device == Device::Cuda) {
        requireCuda();
        mImpl = detail::makeSvgfCudaBackend(params);
    } else {
        mImpl = detail::makeSvgfCpuBackend(params);
    }
    if (params.learnedSpatial && learnedWeights.impl) mImpl->setLearnedWeights(learnedWeights);
}

SvgfDenoiser::~SvgfDenoiser() = default;
SvgfDenoiser::SvgfDenoiser(SvgfDenoiser&&) noexcept = default;
SvgfDenoiser& SvgfDenoiser::operator=(SvgfDenoiser&&) noexcept = default;

Image SvgfDenoiser::denoiseFrame(const Frame& frame) { return mImpl->denoiseFrame(frame); }

const Image& SvgfDenoiser::denoiseFrameOnDevice(const Frame& frame) { return mImpl->denoiseFrameOnDevice(frame); }

void SvgfDenoiser::reset() { mImpl->reset(); }

void SvgfDenoiser::setTiming(bool on) { mImpl->setTiming(on); }

SvgfReport SvgfDenoiser::lastReport() const { return mImpl->lastReport(); }

}  // namespace atrous

// CUDA instantiation of the still path (src/filters/still_pipeline.h) with CudaExec: the same
// functors as the CPU path, launched as kernels. Inputs already on the GPU (the viewer's running
// means, Python's DLPack arrays) are read in place and the result stays on the GPU; host inputs
// are uploaded and the result is downloaded. The report's statistics are reduced on the GPU, so a
// device-resident call moves nothing but the few bytes of the reduction back to the host.
#include <cuda_runtime.h>
#include <thrust/execution_policy.h>
#include <thrust/count.h>
#include <thrust/find.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/sort.h>
#include <thrust/transform_reduce.h>

#include <cmath>
#include <exception>
#include <string>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/math.h"
#include "atrous/timer.h"
#include "atrous/cuda_check.cuh"
#include "cuda/cuda_exec.cuh"
#include "filters/denoise_internal.h"
#include "filters/still_pipeline.h"
#include "filters/stage_clock.h"

namespace atrous::filters {
namespace {

// Partial sums of the report (denoise.cpp's meanLuminance and the firefly count): luminance sums
// in double over the finite luminances only, with their counts, as the CPU does.
struct ReportSums {
    double in = 0, after = 0, emission = 0;
    unsigned long long nIn = 0, nAfter = 0, nEmission = 0, clamped = 0;
    unsigned long long nonFinite = 0;  // colour pixels with a NaN/Inf channel (checkInputs' count)
};

struct AddReportSums {
    ATROUS_HOST_DEVICE ReportSums operator()(const ReportSums& a, const ReportSums& b) const {
        ReportSums r;
        r.in = a.in + b.in;
        r.after = a.after + b.after;
        r.emission = a.emission + b.emission;
        r.nIn = a.nIn + b.nIn;
        r.nAfter = a.nAfter + b.nAfter;
        r.nEmission = a.nEmission + b.nEmission;
        r.clamped = a.clamped + b.clamped;
        r.nonFinite = a.nonFinite + b.nonFinite;
        return r;
    }
};

// One pixel's contribution. All views are device images (color and emission: the caller's inputs
// as given, after: c_0 after the firefly pass, flag: 1 where a firefly was clamped).
struct PixelReportSums {
    ImageView color, after, flag, emission;  // emission invalid when absent

    ATROUS_HOST_DEVICE ReportSums operator()(size_t i) const {
        ReportSums r;
        const size_t pl = color.plane();
        const float c0 = color.data[i], c1 = color.data[pl + i], c2 = color.data[2 * pl + i];
        r.nonFinite = isFiniteF(c0) && isFiniteF(c1) && isFiniteF(c2) ? 0 : 1;
        const float lc = lum(c0, c1, c2);
        if (isFiniteF(lc)) r.in = lc, r.nIn = 1;  // non-finite input luminance skipped (denoise.cpp)
        const float la = lum(after.data[i], after.data[pl + i], after.data[2 * pl + i]);
        if (isFiniteF(la)) r.after = la, r.nAfter = 1;
        if (emission.data) {
            const float le = lum(emission.data[i], emission.data[pl + i], emission.data[2 * pl + i]);
            if (isFiniteF(le)) r.emission = le, r.nEmission = 1;
        }
        r.clamped = flag.data[i] > 0.5f ? 1 : 0;
        return r;
    }
};

struct IsNegative {
    const float* data;
    ATROUS_HOST_DEVICE bool operator()(size_t i) const { return data[i] < 0.0f; }
};

// checkInputs' negative-variance check for a variance on the GPU: the first negative value in
// planar order (as the host scan finds it), read back alone for the message.
void checkDeviceVariance(const Image& variance) {
    const size_t n = 3 * variance.plane();
    size_t first = n;
    try {
        first = *thrust::find_if(thrust::cuda::par, thrust::counting_iterator<size_t>(0),
                                 thrust::counting_iterator<size_t>(n), IsNegative{variance.data()});
    } catch (const std::exception& e) {
        throw RuntimeError(std::string("CUDA variance check failed: ") + e.what());
    }
    if (first >= n) return;
    float value = 0.0f;
    ATROUS_CUDA_CHECK(cudaMemcpy(&value, variance.data() + first, sizeof(float), cudaMemcpyDeviceToHost));
    throw negativeVarianceError(value, first % variance.plane(), variance.width());
}

struct IsFiniteDetail {
    ATROUS_HOST_DEVICE bool operator()(float d) const { return d < INFINITY; }
};

// Fills a 3-channel variance with the constant σ_c² (the estimate of a GPU colour).
struct FillVariance {
    float v[3];
    ImageView out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int c = 0; c < 3; ++c) out(x, y, c) = v[c];
    }
};

}  // namespace

float medianFinite(const CudaExec&, const ImageView& v, float none) {
    float* d = v.data;
    const size_t plane = v.plane();
    size_t n = 0;
    try {
        // The median the host takes with nth_element at n / 2: sort; +Inf and NaN (neither below
        // +Inf) go after every finite value.
        n = size_t(thrust::count_if(thrust::cuda::par, d, d + plane, IsFiniteDetail{}));
        if (n) thrust::sort(thrust::cuda::par, d, d + plane);
    } catch (const std::exception& e) {
        throw RuntimeError(std::string("CUDA median failed: ") + e.what());
    }
    if (!n) return none;
    float mid = 0.0f;
    ATROUS_CUDA_CHECK(cudaMemcpy(&mid, d + n / 2, sizeof(float), cudaMemcpyDeviceToHost));
    return mid;
}

void estimateNoiseSigmaCuda(const Image& color, const Image* albedo, float eps, float floor, float sigma[3]) {
    if (color.device() != Device::Cuda) throw RuntimeError("estimateNoiseSigmaCuda: the colour is not on the GPU");
    Image albedoHolder;
    if (albedo && albedo->device() != Device::Cuda) albedoHolder = albedo->to(Device::Cuda);
    const ImageView a = !albedo ? ImageView{} : (albedoHolder.empty() ? albedo->view() : albedoHolder.view());
    globalNoiseSigma(CudaExec{}, color.view(), a, eps, floor, sigma);
}

Image denoiseCuda(const Frame& in, const DenoiseOptions& o, const CheckedInputs& checked, DenoiseReport& rep, bool timed) {
    const int w = in.color->width(), h = in.color->height();
    if (in.variance && in.variance->device() == Device::Cuda) checkDeviceVariance(*in.variance);
    // A device input is used in place (no copy); a host input is uploaded into its holder, which
    // lives until the still path has finished (runStill synchronises before returning).
    Image holders[8];
    auto onDevice = [&holders](const Image* img, int slot) -> ImageView {
        if (!img) return ImageView{};
        if (img->device() == Device::Cuda) return img->view();
        holders[slot] = img->to(Device::Cuda);
        return holders[slot].view();
    };
    StillInputs di;
    di.color = onDevice(in.color, 0);
    if (in.variance) {
        di.variance = onDevice(in.variance, 1);
    } else if (!checked.estimatedVariance.empty()) {
        di.variance = onDevice(&checked.estimatedVariance, 1);  // estimated on the host: uploaded
    } else {
        // Estimated on the GPU (checkInputs with a GPU colour): the constant σ² filled there.
        holders[1] = Image(w, h, 3, Device::Cuda);
        FillVariance fill{{rep.noiseSigma[0] * rep.noiseSigma[0], rep.noiseSigma[1] * rep.noiseSigma[1],
                           rep.noiseSigma[2] * rep.noiseSigma[2]},
                          holders[1].view()};
        CudaExec{}.forEachPixel(w, h, fill);  // ordered before the driver on the default stream
        di.variance = holders[1].view();
    }
    di.albedo = onDevice(in.albedo, 2);
    di.normal = onDevice(in.normal, 3);
    di.position = onDevice(in.position, 4);
    di.depth = onDevice(in.depth, 5);
    di.ids = onDevice(in.ids, 6);
    di.emission = onDevice(in.emission, 7);
    Image out(w, h, 3, Device::Cuda), after(w, h, 3, Device::Cuda), flag(w, h, 1, Device::Cuda);
    StillOutputs dout;
    dout.out = out.view();
    dout.afterFirefly = after.view();
    dout.fireflyFlag = flag.view();
    // Per-stage GPU times only when the caller asked for a report (events, read after the sync).
    std::unique_ptr<StageClock> clock = timed ? makeStageClock(Device::Cuda) : nullptr;
    dout.clock = clock.get();
    Timer t;
    const StillConfig cfg = stillConfig(in, o, checked, rep);
    if (clock) clock->start();
    runStill(CudaExec{}, di, cfg, dout);  // ends with a stream synchronisation
    rep.milliseconds = t.ms();
    if (clock) clock->collect(rep.stages);

    // The report's statistics in one reduction over the pixels (the same definitions as
    // denoiseCpu; summation order differs, so the doubles may differ in their last digits).
    const size_t plane = size_t(w) * h;
    PixelReportSums px{di.color, after.view(), flag.view(), di.emission};
    ReportSums sums;
    try {
        sums = thrust::transform_reduce(thrust::cuda::par, thrust::counting_iterator<size_t>(0),
                                        thrust::counting_iterator<size_t>(plane), px, ReportSums{}, AddReportSums{});
    } catch (const std::exception& e) {  // thrust::system_error: turn it into the library's error
        throw RuntimeError(std::string("CUDA denoise report reduction failed: ") + e.what());
    }
    rep.meanLuminanceIn = sums.nIn ? sums.in / double(sums.nIn) : 0.0;
    // `after` is c_0 = colour − emission after the pass: the emission's mean is added back so that
    // both figures are of the whole image (see denoise.cpp).
    rep.meanLuminanceAfterFirefly = (sums.nAfter ? sums.after / double(sums.nAfter) : 0.0) +
                                    (in.emission && sums.nEmission ? sums.emission / double(sums.nEmission) : 0.0);
    rep.firefliesClamped = int(sums.clamped);
    if (in.color->device() == Device::Cuda) rep.nonFinitePixels = int(sums.nonFinite);  // host: checkInputs
    if (in.color->device() == Device::Cuda) return out;
    return out.to(Device::Cpu);
}

}  // namespace atrous::filters

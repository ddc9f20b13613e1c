// CUDA instantiation of the EAW/SURE driver (src/filters/denoise_driver.h) with CudaExec: the same
// functors as the CPU path, launched as kernels. Host inputs are uploaded and the result is
// downloaded; inputs already on the GPU (Python's DLPack arrays) are used there and the result
// stays on the GPU.
#include <cmath>

#include "atrous/denoise.h"
#include "core/timer.h"
#include "cuda/cuda_exec.cuh"
#include "filters/denoise_internal.h"
#include "filters/stage_clock.h"

namespace atrous::filters {

Image denoiseCuda(const DenoiseInputs& in, const DenoiseOptions& o, const PreparedInputs& prep, DenoiseReport& rep) {
    const int w = in.color->width(), h = in.color->height();
    auto upload = [](const Image* img) { return img ? img->to(Device::Cuda) : Image(); };
    Image color = upload(in.color);
    Image variance = in.variance ? upload(in.variance) : prep.estimatedVariance.to(Device::Cuda);
    Image albedo = upload(in.albedo), normal = upload(in.normal), position = upload(in.position),
          depth = upload(in.depth), ids = upload(in.ids), emission = upload(in.emission);
    DriverInputs di;
    di.color = color.view();
    di.variance = variance.view();
    di.albedo = albedo.view();
    di.normal = normal.view();
    di.position = position.view();
    di.depth = depth.view();
    di.ids = ids.view();
    di.emission = emission.view();
    Image out(w, h, 3, Device::Cuda), after(w, h, 3, Device::Cuda), flag(w, h, 1, Device::Cuda);
    DriverOutputs dout;
    dout.out = out.view();
    dout.afterFirefly = after.view();
    dout.fireflyFlag = flag.view();
    // Per-stage GPU times only when the caller asked for a report (events, read after the sync).
    std::unique_ptr<StageClock> clock = o.report ? makeStageClock(Device::Cuda) : nullptr;
    dout.clock = clock.get();
    Timer t;
    DriverConfig cfg = makeConfig(o);
    cfg.varianceGiven = in.variance != nullptr;
    if (clock) clock->start();
    runDenoise(CudaExec{}, di, cfg, dout);
    rep.milliseconds = t.ms();
    if (clock) clock->collect(rep.stages);
    Image hostAfter = after.to(Device::Cpu), hostFlag = flag.to(Device::Cpu);
    const bool colorOnDevice = in.color->device() == Device::Cuda;
    const Image hostColorCopy = colorOnDevice ? in.color->to(Device::Cpu) : Image();
    const Image& hostColor = colorOnDevice ? hostColorCopy : *in.color;
    double s0 = 0, s1 = 0;
    size_t n0 = 0;
    int clamped = 0;
    const size_t plane = size_t(w) * h;
    for (size_t i = 0; i < plane; ++i) {
        const float* c = hostColor.data();
        const float l = lum(c[i], c[i + plane], c[i + 2 * plane]);
        if (std::isfinite(l)) {
            s0 += l;
            ++n0;
        }
        s1 += lum(hostAfter.data()[i], hostAfter.data()[i + plane], hostAfter.data()[i + 2 * plane]);
        clamped += hostFlag.data()[i] > 0.5f;
    }
    rep.meanLuminanceIn = n0 ? s0 / double(n0) : 0.0;
    // `after` is c_0 = colour − emission after the pass: add the emission's mean back so that both
    // figures are of the whole image (see denoise.cpp).
    if (in.emission) {
        const Image hostEm = in.emission->to(Device::Cpu);
        for (size_t i = 0; i < plane; ++i) {
            const float l = lum(hostEm.data()[i], hostEm.data()[i + plane], hostEm.data()[i + 2 * plane]);
            if (std::isfinite(l)) s1 += l;
        }
    }
    rep.meanLuminanceAfterFirefly = s1 / double(plane);
    rep.firefliesClamped = clamped;
    if (colorOnDevice) return out;
    return out.to(Device::Cpu);
}

}  // namespace atrous::filters

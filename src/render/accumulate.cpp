// CPU runners of the accumulation and motion functors (render/accumulate.h); the CUDA ones are in
// src/cuda/cuda_accumulate.cu (stubs below when the build has no CUDA backend).
#include "render/accumulate.h"

#include "atrous/error.h"
#include "core/parallel.h"

namespace atrous {

void runAccumulateFrame(Device device, const AccumulateFrame& f) {
    if (device == Device::Cuda) return runAccumulateFrameCuda(f);
    CpuExec{}.forEachPixel(f.outColor.width, f.outColor.height, f);
}

void runMotionFromDepth(Device device, const MotionFromDepth& f) {
    if (device == Device::Cuda) return runMotionFromDepthCuda(f);
    CpuExec{}.forEachPixel(f.motion.width, f.motion.height, f);
}

#if !defined(ATROUS_HAVE_CUDA)
void runAccumulateFrameCuda(const AccumulateFrame&) {
    throw RuntimeError("accumulation on CUDA: this build of atrous has no CUDA backend");
}
void runMotionFromDepthCuda(const MotionFromDepth&) {
    throw RuntimeError("motion on CUDA: this build of atrous has no CUDA backend");
}
#endif

}  // namespace atrous

// CUDA runners of the viewer's accumulation and motion functors (render/accumulate.h): the same
// per-pixel code as the CPU, one thread per pixel on the default stream. The caller checks that
// every view is a device image (ViewPipeline::checkOnDevice) before building the functor.
#include "cuda/cuda_exec.cuh"
#include "render/accumulate.h"

namespace atrous {

void runAccumulateFrameCuda(const AccumulateFrame& f) {
    const CudaExec exec;
    exec.forEachPixel(f.outColor.width, f.outColor.height, f);  // launch error checked there
    exec.synchronize();  // kernel faults surface here, and stage times stay honest
}

void runMotionFromDepthCuda(const MotionFromDepth& f) {
    const CudaExec exec;
    exec.forEachPixel(f.motion.width, f.motion.height, f);
    exec.synchronize();
}

}  // namespace atrous

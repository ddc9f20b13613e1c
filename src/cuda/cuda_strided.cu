#include "core/strided.h"
#include "cuda/cuda_exec.cuh"

namespace atrous::detail {

void cudaGatherStrided(const GatherStrided& f, int width, int height) {
    CudaExec exec;
    exec.forEachPixel(width, height, f);
    exec.synchronize();
}

void cudaScatterInterleaved(const ScatterInterleaved& f, int width, int height) {
    CudaExec exec;
    exec.forEachPixel(width, height, f);
    exec.synchronize();
}

}  // namespace atrous::detail

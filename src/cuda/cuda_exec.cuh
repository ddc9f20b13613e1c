// The CUDA half of the one dispatcher: runs the same per-pixel functors as CpuExec
// (src/core/parallel.h) as a 2D kernel, one thread per pixel.
#pragma once
#include <cuda_runtime.h>

#include "atrous/device.h"
#include "atrous/cuda_check.cuh"

namespace atrous::cuda {

template <class F>
__global__ void forEachPixelKernel(F f, int width, int height) {
    int x = blockIdx.x * blockDim.x + threadIdx.x;
    int y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x < width && y < height) f(x, y);
}

}  // namespace atrous::cuda

namespace atrous {

struct CudaExec {
    cudaStream_t stream = nullptr;
    Device device() const { return Device::Cuda; }
    template <class F>
    void forEachPixel(int width, int height, const F& f) const {
        if (width <= 0 || height <= 0) return;
        dim3 block(32, 8);
        dim3 grid((width + block.x - 1) / block.x, (height + block.y - 1) / block.y);
        cuda::forEachPixelKernel<<<grid, block, 0, stream>>>(f, width, height);
        ATROUS_CUDA_CHECK(cudaGetLastError());
    }
    void synchronize() const { ATROUS_CUDA_CHECK(cudaStreamSynchronize(stream)); }
};

}  // namespace atrous

#include <cuda_runtime.h>

#include <string>

#include "atrous/device.h"
#include "core/memory.h"
#include "cuda/cuda_check.cuh"

namespace atrous {

bool cudaCompiled() { return true; }

namespace detail {

void* cudaAllocate(size_t bytes) {
    void* p = nullptr;
    cudaError_t err = cudaMalloc(&p, bytes == 0 ? 1 : bytes);
    if (err == cudaErrorMemoryAllocation) {
        cudaGetLastError();  // clear the sticky-free error so later calls work
        throw RuntimeError("out of GPU memory allocating " + std::to_string(bytes) + " bytes");
    }
    ATROUS_CUDA_CHECK(err);
    return p;
}

void cudaRelease(void* p) {
    if (p) cudaFree(p);  // no throw from destructors; a failure here is reported by the next call
}

void cudaCopy(void* dst, Device dstDevice, const void* src, Device srcDevice, size_t bytes) {
    cudaMemcpyKind kind = cudaMemcpyDefault;
    (void)dstDevice;
    (void)srcDevice;
    ATROUS_CUDA_CHECK(cudaMemcpy(dst, src, bytes, kind));
}

__global__ void fillKernel(float* dst, float value, size_t count) {
    size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < count) dst[i] = value;
}

void cudaFillFloats(float* dst, float value, size_t count) {
    if (count == 0) return;
    unsigned blocks = unsigned((count + 255) / 256);
    fillKernel<<<blocks, 256>>>(dst, value, count);
    ATROUS_CUDA_CHECK(cudaGetLastError());
    ATROUS_CUDA_CHECK(cudaDeviceSynchronize());
}

bool cudaDevicePresent() {
    static const bool present = [] {
        int n = 0;
        cudaError_t err = cudaGetDeviceCount(&n);
        if (err != cudaSuccess) {
            cudaGetLastError();
            return false;
        }
        return n > 0;
    }();
    return present;
}

std::string cudaDeviceName() {
    if (!cudaDevicePresent()) return "none (no CUDA device)";
    int dev = 0;
    ATROUS_CUDA_CHECK(cudaGetDevice(&dev));
    cudaDeviceProp prop{};
    ATROUS_CUDA_CHECK(cudaGetDeviceProperties(&prop, dev));
    return prop.name;
}

}  // namespace detail
}  // namespace atrous

#include <cuda_runtime.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "atrous/device.h"
#include "core/memory.h"
#include "atrous/cuda_check.cuh"

namespace atrous {

bool cudaCompiled() { return true; }

namespace detail {

namespace {

// Device memory comes from the device's stream-ordered pool (cudaMallocAsync) with the release
// threshold raised to "never", so the memory of freed images stays in the pool and the next
// allocation of a denoise or SVGF call is a cheap sub-allocation. Plain cudaMalloc/cudaFree per call
// would cost far more than the 0.5 ms filter itself, and cudaFree synchronises the whole device.
// Everything in atrous runs on the legacy default stream (CudaExec::stream, cudaMemcpy), so
// allocating and freeing on stream 0 keeps every use of a pointer ordered between the two. Devices
// without memory pools fall back to cudaMalloc/cudaFree.
bool useMemoryPool() {
    static const bool pooled = [] {
        int dev = 0, supported = 0;
        cudaMemPool_t pool = nullptr;
        if (cudaGetDevice(&dev) != cudaSuccess ||
            cudaDeviceGetAttribute(&supported, cudaDevAttrMemoryPoolsSupported, dev) != cudaSuccess || !supported ||
            cudaDeviceGetDefaultMemPool(&pool, dev) != cudaSuccess) {
            cudaGetLastError();  // not sticky; leave no error behind for the next checked call
            return false;
        }
        uint64_t keep = UINT64_MAX;
        if (cudaMemPoolSetAttribute(pool, cudaMemPoolAttrReleaseThreshold, &keep) != cudaSuccess) {
            cudaGetLastError();
            return false;
        }
        return true;
    }();
    return pooled;
}

}  // namespace

void* cudaAllocate(size_t bytes) {
    void* p = nullptr;
    const size_t n = bytes == 0 ? 1 : bytes;
    cudaError_t err = useMemoryPool() ? cudaMallocAsync(&p, n, /*stream=*/0) : cudaMalloc(&p, n);
    if (err == cudaErrorMemoryAllocation) {
        cudaGetLastError();  // clear the error so later calls work
        throw RuntimeError("out of GPU memory allocating " + std::to_string(bytes) + " bytes");
    }
    ATROUS_CUDA_CHECK(err);
    return p;
}

void cudaRelease(void* p) {
    // No throw from destructors; a failure here is reported by the next checked call.
    if (!p) return;
    if (useMemoryPool())
        cudaFreeAsync(p, /*stream=*/0);
    else
        cudaFree(p);
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
    if (value == 0.0f && !std::signbit(value)) {
        // +0.0f is all zero bytes: the copy engine's memset (every new device image is zeroed;
        // the kernel below wrote at about a quarter of the H200's bandwidth).
        ATROUS_CUDA_CHECK(cudaMemsetAsync(dst, 0, count * sizeof(float)));
    } else {
        unsigned blocks = unsigned((count + 255) / 256);
        fillKernel<<<blocks, 256>>>(dst, value, count);
        ATROUS_CUDA_CHECK(cudaGetLastError());
    }
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

double cudaPeakBandwidthGBs() {
    if (!cudaDevicePresent()) return 0.0;
    int dev = 0, clockKHz = 0, busBits = 0;
    ATROUS_CUDA_CHECK(cudaGetDevice(&dev));
    // Attributes, not cudaDeviceProp fields: CUDA 13 removed cudaDeviceProp::memoryClockRate.
    ATROUS_CUDA_CHECK(cudaDeviceGetAttribute(&clockKHz, cudaDevAttrMemoryClockRate, dev));
    ATROUS_CUDA_CHECK(cudaDeviceGetAttribute(&busBits, cudaDevAttrGlobalMemoryBusWidth, dev));
    // Double data rate: two transfers per clock.
    return 2.0 * double(clockKHz) * 1e3 * double(busBits) / 8.0 / 1e9;
}

}  // namespace detail
}  // namespace atrous

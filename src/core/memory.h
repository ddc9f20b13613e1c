// Raw allocation behind Image. Host memory is 64-byte aligned; device memory comes from the CUDA
// backend (src/cuda/cuda_memory.cu) or, in a build without CUDA, from stubs that throw
// (src/core/no_cuda.cpp). Nothing else in the project calls cudaMalloc.
#pragma once
#include <cstddef>
#include <string>

#include "atrous/device.h"

namespace atrous::detail {

void* allocateBytes(size_t bytes, Device device);
void freeBytes(void* p, Device device);
void copyBytes(void* dst, Device dstDevice, const void* src, Device srcDevice, size_t bytes);
void fillFloats(float* dst, Device device, float value, size_t count);

// Implemented by the CUDA backend (or the no-CUDA stubs).
void* cudaAllocate(size_t bytes);
void cudaRelease(void* p);
void cudaCopy(void* dst, Device dstDevice, const void* src, Device srcDevice, size_t bytes);
void cudaFillFloats(float* dst, float value, size_t count);
bool cudaDevicePresent();
std::string cudaDeviceName();
// Theoretical peak DRAM bandwidth of the current GPU in GB/s (memory clock x bus width x 2, from
// the device attributes); 0 without a GPU.
double cudaPeakBandwidthGBs();

}  // namespace atrous::detail

// Every CUDA call is checked (docs/architecture.md, principle 3): ATROUS_CUDA_CHECK(call) throws the
// library's RuntimeError naming the call (out of memory said as such). For CUDA code of the library and
// its front-ends (the viewer's OpenGL interop); it includes cuda_runtime.h.
#pragma once
#include <cuda_runtime.h>

#include <string>

#include "atrous/error.h"

namespace atrous::cuda {

[[noreturn]] inline void fail(cudaError_t err, const char* what, const char* file, int line) {
    std::string msg = std::string("CUDA error in ") + what + ": " + cudaGetErrorString(err) + " (" + file + ":" +
                      std::to_string(line) + ")";
    if (err == cudaErrorMemoryAllocation) throw RuntimeError("out of GPU memory: " + msg);
    throw RuntimeError(msg);
}

}  // namespace atrous::cuda

#define ATROUS_CUDA_CHECK(call)                                                  \
    do {                                                                         \
        cudaError_t atrous_err_ = (call);                                        \
        if (atrous_err_ != cudaSuccess) ::atrous::cuda::fail(atrous_err_, #call, __FILE__, __LINE__); \
    } while (0)

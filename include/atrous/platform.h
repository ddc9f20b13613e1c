// The one place that asks which compiler is looking (docs/architecture.md, principle 1): every per-pixel function
// is marked ATROUS_HOST_DEVICE so the same body compiles for TBB threads and CUDA kernels.
#pragma once

#if defined(__CUDACC__)
#define ATROUS_HOST_DEVICE __host__ __device__
#define ATROUS_DEVICE_COMPILER 1
#else
#define ATROUS_HOST_DEVICE
#define ATROUS_DEVICE_COMPILER 0
#endif

#if defined(__CUDA_ARCH__)
#define ATROUS_ON_DEVICE 1  // compiling the device side of a .cu file
#else
#define ATROUS_ON_DEVICE 0
#endif

#define ATROUS_INLINE ATROUS_HOST_DEVICE inline

// Restrict-qualified pointers let the host compiler vectorise the per-row loops.
#if defined(__CUDACC__) || defined(__GNUC__) || defined(__clang__)
#define ATROUS_RESTRICT __restrict__
#else
#define ATROUS_RESTRICT
#endif

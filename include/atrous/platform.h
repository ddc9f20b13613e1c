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

// Host-only forced inlining for the shared per-pixel math called from the CPU row loops: a call
// left in the x loop stops it vectorising.
#if defined(__GNUC__) && !defined(__CUDACC__)
#define ATROUS_FORCE_INLINE __attribute__((always_inline))
#else
#define ATROUS_FORCE_INLINE
#endif

// The learned filter's lane loops (the pixel index, innermost): `omp simd` on the host compiler,
// so that GCC vectorises them rather than unrolling them into scalar code; nothing for nvcc (one
// lane there).
#if defined(__GNUC__) && !defined(__CUDACC__)
#define ATROUS_LANES _Pragma("omp simd")
#else
#define ATROUS_LANES
#endif

// A layer's unit loop fully unrolled on the device, so that the layer's outputs (and the MLP's 34
// raw outputs) stay in registers: without it nvcc kept v3's 34 outputs in a 136-byte local array
// (ptxas -v, sm_90). Nothing on the host (GCC vectorises the lane loops instead).
#if defined(__CUDACC__)
#define ATROUS_DEVICE_UNROLL _Pragma("unroll")
#else
#define ATROUS_DEVICE_UNROLL
#endif

// At the top of a CPU loop file, before its includes: GCC may if-convert selects (FP exceptions are
// never unmasked or tested here); no reassociation or contraction comes with it.
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
#define ATROUS_NO_TRAPPING_MATH _Pragma("GCC optimize(\"no-trapping-math\")")
#else
#define ATROUS_NO_TRAPPING_MATH
#endif

// Restrict-qualified pointers let the host compiler vectorise the per-row loops.
#if defined(__CUDACC__) || defined(__GNUC__) || defined(__clang__)
#define ATROUS_RESTRICT __restrict__
#else
#define ATROUS_RESTRICT
#endif

// The CPU loops compiled for several instruction sets (src/core/isa_dispatch.h, parallelForIsa): with
// GCC on x86-64 (also the host side of a .cu file: nvcc passes the attributes to GCC).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define ATROUS_CPU_MULTI_ISA 1
#define ATROUS_CPU_AVX512 1
// `flatten` inlines everything the wrapper calls (the functor and what it calls in turn), so the
// whole body is compiled for the wrapper's target, not only the force-inlined parts.
#define ATROUS_TARGET_BASELINE __attribute__((flatten))
#define ATROUS_TARGET_AVX2 __attribute__((flatten, target("arch=x86-64-v3")))
// AVX-512 F/VL/BW/DQ (the subset every AVX-512 core has) on top of x86-64-v3, with 512-bit
// vectors: EAW's tap loop needs ~30 live vectors (src/cpu/atrous_rows.h).
#define ATROUS_TARGET_AVX512 \
    __attribute__((flatten, target("arch=x86-64-v3,avx512f,avx512vl,avx512bw,avx512dq,prefer-vector-width=512")))
#else
#define ATROUS_CPU_MULTI_ISA 0
#define ATROUS_CPU_AVX512 0
#define ATROUS_TARGET_BASELINE
#endif

// Run-time choice of the CPU loops' instruction set. The library is compiled for baseline x86-64
// (SSE2: every x86-64 CPU); the loops that pay for wider vectors are compiled three times from one
// body, through the wrappers of parallelForIsa (src/cpu/atrous_rows.h): as compiled (baseline),
// for AVX2+FMA (x86-64-v3) and for AVX-512, and one of them runs, chosen once from CPUID or
// ATROUS_CPU_ISA (src/cpu/cpu_isa.h).
#pragma once

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

#include "cpu/cpu_isa.h"

namespace atrous {

// Whether this CPU runs the AVX-512 loops (false where they are not compiled).
inline bool cpuHasAvx512() { return cpu::isaSupported(cpu::Isa::Avx512); }

}  // namespace atrous

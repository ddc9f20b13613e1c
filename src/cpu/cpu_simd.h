// Run-time choice of the CPU row loops' instruction set, shared by the fast paths that compile
// the same loop body twice: for AVX2 (the build's baseline, x86-64-v3) and for AVX-512, picked
// at run time (src/cpu/eaw_cpu.cpp's header comment says why AVX-512 pays there).
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && (defined(__x86_64__) || defined(__i386__))
#define ATROUS_CPU_AVX512 1
// Row loops compiled for AVX-512 (F/VL/BW/DQ: the subset every AVX-512 core has) with 512-bit
// vectors; the inlined shared functors take the caller's target, so the math is the same code.
#define ATROUS_TARGET_AVX512 \
    __attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,prefer-vector-width=512")))
#else
#define ATROUS_CPU_AVX512 0
#endif

namespace atrous {

// Whether this CPU runs the AVX-512 loops (false where they are not compiled).
inline bool cpuHasAvx512() {
#if ATROUS_CPU_AVX512
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
#else
    return false;
#endif
}

}  // namespace atrous

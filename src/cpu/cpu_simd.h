// Run-time choice of the CPU loops' instruction set. The library is compiled for baseline x86-64
// (SSE2: every x86-64 CPU); the loops that pay for wider vectors are compiled three times from one
// body, through the wrappers of parallelForIsa (src/cpu/atrous_rows.h): as compiled (baseline),
// for AVX2+FMA (x86-64-v3) and for AVX-512, and one of them runs, chosen once from CPUID or
// ATROUS_CPU_ISA (src/cpu/cpu_isa.h).
#pragma once

// ATROUS_CPU_MULTI_ISA, ATROUS_CPU_AVX512 and the ATROUS_TARGET_* attributes: atrous/platform.h.
#include "atrous/platform.h"

#include "cpu/cpu_isa.h"

namespace atrous {

// Whether this CPU runs the AVX-512 loops (false where they are not compiled).
inline bool cpuHasAvx512() { return cpu::isaSupported(cpu::Isa::Avx512); }

}  // namespace atrous

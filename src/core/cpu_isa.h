// The CPU instruction set the hot loops run with, chosen once per process: platform code, beside
// the executors it steers. The library is compiled for baseline x86-64 (SSE2), so it runs on every
// x86-64 CPU; the loops that pay for it are compiled three times (the ATROUS_TARGET_* wrappers of
// atrous/platform.h: baseline, AVX2+FMA = x86-64-v3, AVX-512) and the dispatch (parallelForIsa,
// src/core/isa_dispatch.h) picks one of them from activeIsa(). activeIsa() is the best this CPU
// has (CPUID), or what the environment variable ATROUS_CPU_ISA=baseline|avx2|avx512 asks for;
// asking for an unknown name or an ISA the CPU lacks is an InputError (one line) at the first CPU
// loop, never an illegal instruction.
#pragma once
#include <string>

// ATROUS_CPU_MULTI_ISA, ATROUS_CPU_AVX512 and the ATROUS_TARGET_* attributes.
#include "atrous/platform.h"

namespace atrous::cpu {

enum class Isa : int { Baseline = 0, Avx2 = 1, Avx512 = 2 };

// "baseline", "avx2", "avx512".
const char* isaName(Isa isa);
// Whether this CPU (and this build) can run the loops compiled for `isa`. Avx2: AVX2, FMA, BMI1/2,
// F16C, LZCNT, MOVBE (x86-64-v3, what GCC may emit for that target); Avx512: that plus
// AVX-512 F/VL/BW/DQ (the subset every AVX-512 core has).
bool isaSupported(Isa isa);
// The best ISA this CPU runs.
Isa bestIsa();
// Parses a name of isaName(); throws InputError naming `what` (e.g. "ATROUS_CPU_ISA") otherwise.
Isa parseIsa(const std::string& name, const char* what);
// The ISA in use: ATROUS_CPU_ISA if set (checked once), else bestIsa(). Throws InputError if the
// variable names an unknown ISA or one this CPU lacks (on every call, so every entry point says it).
Isa activeIsa();
// activeIsa() without the error: baseline when ATROUS_CPU_ISA is invalid (the first loop throws).
Isa activeIsaOrBaseline();
// Sets the ISA in use (tests, benchmarks); throws InputError if the CPU lacks it. Also sets the
// AVX-512 switch (avx512Switch()) to isa == Avx512.
void setActiveIsa(Isa isa);
// The switch of the loops that take it (parallelForIsa(bool, ...): the à-trous row engine, the
// learned filter's rows; filters::atrousCpuAvx512() is this switch): their AVX-512 versions, or the
// ISA in use capped at AVX2. Starts as activeIsaOrBaseline() == Avx512; tests turn it off to run the
// AVX2 loops on an AVX-512 CPU. Setting it on a CPU without AVX-512 is not allowed.
bool& avx512Switch();
// "avx2 (x86-64-v3)", "baseline (x86-64, SSE2)", "avx512 (AVX-512 F/VL/BW/DQ)"; for the device
// description; never throws (an invalid ATROUS_CPU_ISA reads "invalid ATROUS_CPU_ISA").
std::string isaDescription();

}  // namespace atrous::cpu

namespace atrous {

// Whether this CPU runs the AVX-512 loops (false where they are not compiled).
inline bool cpuHasAvx512() { return cpu::isaSupported(cpu::Isa::Avx512); }

}  // namespace atrous

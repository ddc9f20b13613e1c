// Run-time choice of the CPU loops' instruction set (src/core/cpu_isa.h).
#include "core/cpu_isa.h"

#include <cstdlib>

#include "atrous/error.h"

namespace atrous::cpu {

namespace {

struct IsaState {
    Isa isa = Isa::Baseline;
    std::string error;  // non-empty: ATROUS_CPU_ISA is invalid
};

IsaState initialState() {
    IsaState s;
    s.isa = bestIsa();
    const char* env = std::getenv("ATROUS_CPU_ISA");
    if (!env || !*env) return s;
    try {
        const Isa want = parseIsa(env, "ATROUS_CPU_ISA");
        if (!isaSupported(want))
            throw InputError(std::string("ATROUS_CPU_ISA=") + env + ": this CPU cannot run the " + isaName(want) +
                             " loops (the best it runs: " + isaName(bestIsa()) + ")");
        s.isa = want;
    } catch (const InputError& e) {
        s.error = e.what();
    }
    return s;
}

IsaState& state() {
    static IsaState s = initialState();
    return s;
}

}  // namespace

const char* isaName(Isa isa) {
    switch (isa) {
        case Isa::Avx2: return "avx2";
        case Isa::Avx512: return "avx512";
        default: return "baseline";
    }
}

bool isaSupported(Isa isa) {
#if ATROUS_CPU_MULTI_ISA
    __builtin_cpu_init();
    const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                      __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
                      __builtin_cpu_supports("f16c") && __builtin_cpu_supports("lzcnt") &&
                      __builtin_cpu_supports("movbe");
    switch (isa) {
        case Isa::Baseline: return true;
        case Isa::Avx2: return avx2;
        case Isa::Avx512:
            return avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                   __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
    }
    return false;
#else
    return isa == Isa::Baseline;
#endif
}

Isa bestIsa() {
    if (isaSupported(Isa::Avx512)) return Isa::Avx512;
    if (isaSupported(Isa::Avx2)) return Isa::Avx2;
    return Isa::Baseline;
}

Isa parseIsa(const std::string& name, const char* what) {
    for (Isa i : {Isa::Baseline, Isa::Avx2, Isa::Avx512})
        if (name == isaName(i)) return i;
    throw InputError(std::string(what) + "=" + name + ": unknown CPU ISA (expected baseline, avx2 or avx512)");
}

Isa activeIsa() {
    const IsaState& s = state();
    if (!s.error.empty()) throw InputError(s.error);
    return s.isa;
}

Isa activeIsaOrBaseline() {
    const IsaState& s = state();
    return s.error.empty() ? s.isa : Isa::Baseline;
}

void setActiveIsa(Isa isa) {
    if (!isaSupported(isa))
        throw InputError(std::string("CPU ISA ") + isaName(isa) + ": this CPU cannot run it (the best it runs: " +
                         isaName(bestIsa()) + ")");
    IsaState& s = state();
    s.isa = isa;
    s.error.clear();
    avx512Switch() = isa == Isa::Avx512;
}

bool& avx512Switch() {
    static bool enabled = activeIsaOrBaseline() == Isa::Avx512;
    return enabled;
}

std::string isaDescription() {
    const IsaState& s = state();
    if (!s.error.empty()) return "invalid ATROUS_CPU_ISA";
    switch (s.isa) {
        case Isa::Avx2: return "avx2 (x86-64-v3)";
        case Isa::Avx512: return "avx512 (AVX-512 F/VL/BW/DQ)";
        default: return "baseline (x86-64, SSE2)";
    }
}

}  // namespace atrous::cpu

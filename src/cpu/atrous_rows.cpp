// The switches of the CPU row engine (src/cpu/atrous_rows.h), one pair for every policy. The
// AVX-512 switch starts as "the ISA in use is AVX-512" (src/cpu/cpu_isa.h); cpu::setActiveIsa
// sets it too.
#include "cpu/cpu_simd.h"
#include "filters/atrous_level.h"

namespace atrous::filters {

bool& atrousCpuFastPath() {
    static bool enabled = true;
    return enabled;
}

bool& atrousCpuAvx512() {
    static bool enabled = cpu::activeIsaOrBaseline() == cpu::Isa::Avx512;
    return enabled;
}

}  // namespace atrous::filters

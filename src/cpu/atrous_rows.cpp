// The switches of the CPU row engine (src/cpu/atrous_rows.h), one pair for every policy. The
// AVX-512 switch is the dispatch's own (cpu::avx512Switch(), src/core/cpu_isa.h): it starts as
// "the ISA in use is AVX-512", and cpu::setActiveIsa sets it too.
#include "core/cpu_isa.h"
#include "filters/atrous_level.h"

namespace atrous::filters {

bool& atrousCpuFastPath() {
    static bool enabled = true;
    return enabled;
}

bool& atrousCpuAvx512() { return cpu::avx512Switch(); }

}  // namespace atrous::filters

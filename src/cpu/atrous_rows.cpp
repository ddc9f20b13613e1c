// The switches of the CPU row engine (src/cpu/atrous_rows.h), one pair for every policy.
#include "cpu/cpu_simd.h"
#include "filters/atrous_level.h"

namespace atrous::filters {

bool& atrousCpuFastPath() {
    static bool enabled = true;
    return enabled;
}

bool& atrousCpuAvx512() {
    static bool enabled = cpuHasAvx512();
    return enabled;
}

}  // namespace atrous::filters

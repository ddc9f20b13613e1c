// CPU path of one learned-filter level: the shared row engine (src/cpu/atrous_rows.h) with the
// LearnedStop policy (filters/learned.h), the same taps in the same order as the functor.
#include "core/parallel.h"
#include "cpu/atrous_rows.h"
#include "filters/learned.h"

namespace atrous::filters {

void runLearnedLevel(const CpuExec& exec, const LearnedStop& stop) {
    if (!atrousCpuFastPath()) {
        runAtrousLevelFunctor(exec, stop);
        return;
    }
    cpu::runAtrousRows(stop, atrousCpuAvx512());
}

}  // namespace atrous::filters

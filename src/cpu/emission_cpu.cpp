// CPU path of the emission filter level: TBB over rows, a plain (not force-vectorised) x loop so
// that the functor's early exit for pixels that need no filtering really skips the 25 taps.
#include "core/parallel.h"
#include "filters/emission_filter.h"

namespace atrous::filters {

void runEmissionLevel(const CpuExec&, const EmissionLevel& f) {
    const int w = f.eIn.width;
    parallelForRowsCpu(f.eIn.height, [&](int y) {
        for (int x = 0; x < w; ++x) f(x, y);
    });
}

}  // namespace atrous::filters

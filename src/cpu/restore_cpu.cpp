// CPU prefix sums of the firefly restore's difference image (filters::runRestorePrefix): rows on
// TBB threads as in the functor; columns in bands of 256 columns, each band adding its rows in
// order into double accumulators (the functor walks one column at a time, serial and strided on
// the CPU). The same sums in the same order as the functors, so the same values.
#include <algorithm>
#include <vector>

#include "core/parallel.h"
#include "filters/firefly_restore.h"

namespace atrous::filters {

void runRestorePrefix(const CpuExec&, const ImageView& plane) {
    const int w = plane.width, h = plane.height;
    const RestoreRowSum rows{plane};
    parallelForRowsCpu(h, [&](int y) { rows(0, y); });
    constexpr int kBand = 256;
    const int bands = (w + kBand - 1) / kBand;
    parallelForRowsCpu(bands * plane.channels, [&](int job) {
        const int c = job / bands, x0 = (job % bands) * kBand, x1 = std::min(x0 + kBand, w);
        double acc[kBand] = {};
        for (int y = 0; y < h; ++y) {
            float* row = plane.channel(c) + size_t(y) * size_t(w);
            for (int x = x0; x < x1; ++x) acc[x - x0] += row[x], row[x] = float(acc[x - x0]);
        }
    }, 1);
}

}  // namespace atrous::filters

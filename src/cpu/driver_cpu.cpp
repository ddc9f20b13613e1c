// CPU pieces of the still path (filters/still_state.h) that are not stages: the report's
// luminance after the firefly pass and its count of clamped pixels.
#include <vector>

#include "core/parallel.h"
#include "core/isa_dispatch.h"
#include "cpu/row_sums.h"
#include "filters/still_state.h"

namespace atrous::filters {

void reportLuminance(const CpuExec&, const ImageView& c, StillReport& report) {
    const int w = c.width, h = c.height;
    std::vector<double> sum(static_cast<size_t>(h)), count(static_cast<size_t>(h));
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 16, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            const size_t o = size_t(y) * size_t(w);
            cpu::finiteLuminanceRow(c.channel(0) + o, c.channel(1) + o, c.channel(2) + o, w, sum[size_t(y)],
                                    count[size_t(y)]);
        }
    });
    double s = 0, n = 0;
    for (int y = 0; y < h; ++y) s += sum[size_t(y)], n += count[size_t(y)];
    report.lumAfterSum = s, report.lumAfterCount = n;
}

void reportFireflies(const CpuExec&, const ImageView& flag, StillReport& report) {
    const int w = flag.width, h = flag.height;
    std::vector<int> count(static_cast<size_t>(h));
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 16, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            const float* f = flag.channel(0) + size_t(y) * size_t(w);
            int n = 0;
            for (int x = 0; x < w; ++x) n += f[x] > 0.5f;
            count[size_t(y)] = n;
        }
    });
    int clamped = 0;
    for (int n : count) clamped += n;
    report.firefliesClamped = clamped;
}

}  // namespace atrous::filters

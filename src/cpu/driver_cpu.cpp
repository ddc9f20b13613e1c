// CPU pieces of the still driver (filters/denoise_driver.h) that are not stages: the report's
// luminance after the firefly pass.
#include <vector>

#include "core/parallel.h"
#include "cpu/isa_dispatch.h"
#include "filters/denoise_driver.h"

namespace atrous::filters {

void reportLuminance(const CpuExec&, const ImageView& c, DriverReport& report) {
    const int w = c.width, h = c.height;
    std::vector<double> sum(static_cast<size_t>(h)), count(static_cast<size_t>(h));
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 16, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            const size_t o = size_t(y) * size_t(w);
            const float* r = c.channel(0) + o;
            const float* g = c.channel(1) + o;
            const float* b = c.channel(2) + o;
            double s = 0, n = 0;
#pragma omp simd reduction(+ : s, n)
            for (int x = 0; x < w; ++x) {
                const float l = lum(r[x], g[x], b[x]);
                const bool ok = finite(l);
                s += ok ? double(l) : 0.0;
                n += ok ? 1.0 : 0.0;
            }
            sum[size_t(y)] = s, count[size_t(y)] = n;
        }
    });
    double s = 0, n = 0;
    for (int y = 0; y < h; ++y) s += sum[size_t(y)], n += count[size_t(y)];
    report.lumAfterSum = s, report.lumAfterCount = n;
}

}  // namespace atrous::filters

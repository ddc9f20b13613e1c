// CPU fast path of the firefly pass (filters::FireflyClamp). The generic functor gathers its 3×3
// neighbourhood with clamped indices and did not vectorise (the per-pixel call stayed a call);
// here each task computes the luminance and luminance variance of the three rows once, and an x
// loop over the interior columns reads the 8 neighbours from those rows and runs the shared
// FireflyClamp::apply. Rows clamp as in the functor (row pointers of y±1 clamped); the two border
// columns go through the functor itself.
// FP exceptions are never unmasked or tested here; without -ftrapping-math GCC if-converts the
// selects of the firefly rule, which it otherwise keeps as branches (no vectorisation). Results
// are the same: no reassociation or contraction is allowed by this.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-trapping-math")
#endif
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <vector>

#include "core/parallel.h"
#include "filters/prepass.h"

namespace atrous::filters {

void runFireflyClamp(const CpuExec& exec, const FireflyClamp& f) {
    const int w = f.cIn.width, h = f.cIn.height;
    if (w < 3) {
        exec.forEachPixel(w, h, f);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& r) {
        const FireflyClamp g = f;  // a local copy: its views cannot alias the stores
        std::vector<float> rowsL(size_t(3) * w), rowsV(size_t(3) * w);
        std::vector<float> scratch(w);  // flag row when no flag view was given
        for (int y = r.begin(); y < r.end(); ++y) {
            for (int k = 0; k < 3; ++k) {
                const int yy = clampIdx(y + k - 1, h - 1);
                const size_t o = size_t(yy) * w;
                const float* ATROUS_RESTRICT cr = g.cIn.channel(0) + o;
                const float* ATROUS_RESTRICT cg = g.cIn.channel(1) + o;
                const float* ATROUS_RESTRICT cb = g.cIn.channel(2) + o;
                const float* ATROUS_RESTRICT vr = g.vIn.channel(0) + o;
                const float* ATROUS_RESTRICT vg = g.vIn.channel(1) + o;
                const float* ATROUS_RESTRICT vb = g.vIn.channel(2) + o;
                float* ATROUS_RESTRICT L = rowsL.data() + size_t(k) * w;
                float* ATROUS_RESTRICT V = rowsV.data() + size_t(k) * w;
#pragma omp simd
                for (int x = 0; x < w; ++x) {
                    L[x] = lum(cr[x], cg[x], cb[x]);
                    V[x] = lum(lum(1, 0, 0) * vr[x], lum(0, 1, 0) * vg[x], lum(0, 0, 1) * vb[x]);
                }
            }
            const float* ATROUS_RESTRICT L0 = rowsL.data();
            const float* ATROUS_RESTRICT L1 = L0 + w;
            const float* ATROUS_RESTRICT L2 = L1 + w;
            const float* ATROUS_RESTRICT V0 = rowsV.data();
            const float* ATROUS_RESTRICT V1 = V0 + w;
            const float* ATROUS_RESTRICT V2 = V1 + w;
            g(0, y);
            float* ATROUS_RESTRICT flag = g.flag.valid() ? g.flag.channel(0) + size_t(y) * w : scratch.data();
#pragma omp simd
            for (int x = 1; x < w - 1; ++x) {
                const float l[8] = {L0[x - 1], L0[x], L0[x + 1], L1[x - 1], L1[x + 1], L2[x - 1], L2[x], L2[x + 1]};
                const float lv[8] = {V0[x - 1], V0[x], V0[x + 1], V1[x - 1], V1[x + 1], V2[x - 1], V2[x], V2[x + 1]};
                flag[x] = g.apply(x, y, l, lv);
            }
            g(w - 1, y);
        }
    });
}

}  // namespace atrous::filters

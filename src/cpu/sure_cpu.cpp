// CPU fast path of the SURE window passes (filters::SureBoxH, filters::SureChoose). The generic
// functors clamp every window index, which kept their x loops scalar; here the horizontal pass
// adds one window offset at a time over the columns whose window is inside the row (the border columns
// through the functor), and the vertical pass adds the clamped window rows into a row buffer one
// row at a time, then picks s per pixel with the shared sureChoose. Sums are taken in the same
// order as in the functors, so the results are the same.
// FP exceptions are never unmasked or tested here; without -ftrapping-math GCC if-converts the
// selects (results unchanged: no reassociation or contraction is allowed by this).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-trapping-math")
#endif

#include <vector>

#include "core/parallel.h"
#include "cpu/isa_dispatch.h"
#include "filters/sure.h"

namespace atrous::filters {

void runSureBoxH(const CpuExec& exec, const SureBoxH& f) {
    const int w = f.in.width, h = f.in.height, r = f.radius;
    if (w <= 2 * r) {
        exec.forEachPixel(w, h, f);
        return;
    }
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 16, [&](int range0, int range1) {
        const SureBoxH g = f;
        for (int y = range0; y < range1; ++y) {
            const size_t o = size_t(y) * w;
            const float* ATROUS_RESTRICT d = g.in.channel(0) + o;
            const float* ATROUS_RESTRICT v = g.in.channel(1) + o;
            float* ATROUS_RESTRICT od = g.out.channel(0) + o;
            float* ATROUS_RESTRICT ov = g.out.channel(1) + o;
            for (int x = 0; x < r; ++x) g(x, y);
            // One tap offset at a time over the row (the same order of additions per pixel as
            // the functor's loop over dx), so each loop is a plain vectorised x loop.
            for (int x = r; x < w - r; ++x) od[x] = ov[x] = 0.0f;
            for (int dx = -r; dx <= r; ++dx) {
#pragma omp simd
                for (int x = r; x < w - r; ++x) {
                    od[x] += d[x + dx];
                    ov[x] += v[x + dx];
                }
            }
            for (int x = w - r; x < w; ++x) g(x, y);
        }
    });
}

namespace {

template <int kJamesStein>
void chooseRows(const SureChoose& f, int y0, int y1) {
    const int w = f.boxH.width, h = f.boxH.height, r = f.p.radius;
    SureChoiceParams p = f.p;
    p.jamesStein = kJamesStein;  // a constant: no branch left in the x loop
    std::vector<float> sumDRow(w), sumVRow(w), sScratch(w);
    const size_t plane = size_t(w) * h;
    for (int y = y0; y < y1; ++y) {
        float* ATROUS_RESTRICT sumD = sumDRow.data();
        float* ATROUS_RESTRICT sumV = sumVRow.data();
        for (int x = 0; x < w; ++x) sumD[x] = sumV[x] = 0.0f;
        for (int dy = -r; dy <= r; ++dy) {
            const int yy = clampIdx(y + dy, h - 1);
            const float* ATROUS_RESTRICT bd = f.boxH.channel(0) + size_t(yy) * w;
            const float* ATROUS_RESTRICT bv = f.boxH.channel(1) + size_t(yy) * w;
#pragma omp simd
            for (int x = 0; x < w; ++x) {
                sumD[x] += bd[x];
                sumV[x] += bv[x];
            }
        }
        const size_t o = size_t(y) * w;
        const float* ATROUS_RESTRICT ci = f.cI.data + o;
        const float* ATROUS_RESTRICT cn = f.cNext.data + o;
        float* ATROUS_RESTRICT acc = f.acc.data + o;
        float* ATROUS_RESTRICT sOut = f.sOut.valid() ? f.sOut.data + o : sScratch.data();
#pragma omp simd
        for (int x = 0; x < w; ++x) {
            const float s = sureChoose(p, sumD[x], sumV[x]);
            acc[x] += s * (ci[x] - cn[x]);
            acc[x + plane] += s * (ci[x + plane] - cn[x + plane]);
            acc[x + 2 * plane] += s * (ci[x + 2 * plane] - cn[x + 2 * plane]);
            sOut[x] = s;
        }
    }
}

}  // namespace

void runSureChoose(const CpuExec&, const SureChoose& f) {
    const int h = f.boxH.height;
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 16, [&](int range0, int range1) {
        if (f.p.jamesStein)
            chooseRows<1>(f, range0, range1);
        else
            chooseRows<0>(f, range0, range1);
    });
}

}  // namespace atrous::filters

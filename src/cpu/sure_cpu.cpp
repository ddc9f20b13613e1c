// CPU fast path of the SURE window passes (filters::SureBoxH, filters::SureChoose) and of the albedo
// give-back (filters::runAlbedoGiveBack, safety_net.h). The generic
// functors clamp every window index, which kept their x loops scalar; here the horizontal pass
// adds one window offset at a time over the columns whose window is inside the row (the border columns
// through the functor), and the vertical pass adds the clamped window rows into a row buffer one
// row at a time, then picks s per pixel with the shared sureChoose. Sums are taken in the same
// order as in the functors, so the results are the same.
// FP exceptions are never unmasked or tested here; without -ftrapping-math GCC if-converts the
// selects (results unchanged: no reassociation or contraction is allowed by this).
#include "atrous/platform.h"
ATROUS_NO_TRAPPING_MATH

#include <algorithm>
#include <vector>

#include "core/parallel.h"
#include "core/isa_dispatch.h"
#include "cpu/row_sums.h"
#include "filters/safety_net.h"
#include "filters/sure.h"

namespace atrous::filters {

namespace {
constexpr int kMaxWindowRadius = 10;  // SureParams / SafetyNetParams windowRadius and kGiveBackRadius
}

namespace {

// SureBoxH of row y into od/ov (w values each), for w > 2r: the border columns through the functor
// (g's out views are not used: its sums are taken here), the interior as sums of shifted rows.
void boxRow(const SureBoxH& g, int y, float* ATROUS_RESTRICT od, float* ATROUS_RESTRICT ov,
            std::vector<const float*>& shiftedD, std::vector<const float*>& shiftedV) {
    const int w = g.in.width, r = g.radius;
    const size_t o = size_t(y) * w;
    const float* d = g.in.channel(0) + o;
    const float* v = g.in.channel(1) + o;
    auto border = [&](int x) {
        float a = 0, b = 0;
        for (int dx = -r; dx <= r; ++dx) {
            const int xx = clampIdx(x + dx, w - 1);
            a += d[xx];
            b += v[xx];
        }
        od[x] = a, ov[x] = b;
    };
    for (int x = 0; x < r; ++x) border(x);
    for (int k = 0; k <= 2 * r; ++k) shiftedD[size_t(k)] = d + k, shiftedV[size_t(k)] = v + k;
    cpu::sumRows(shiftedD.data(), 2 * r + 1, od + r, size_t(w - 2 * r));
    cpu::sumRows(shiftedV.data(), 2 * r + 1, ov + r, size_t(w - 2 * r));
    for (int x = w - r; x < w; ++x) border(x);
}

}  // namespace

void runSureBoxH(const CpuExec& exec, const SureBoxH& f) {
    const int w = f.in.width, h = f.in.height, r = f.radius;
    if (w <= 2 * r) {
        exec.forEachPixel(w, h, f);
        return;
    }
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 16, [&](int range0, int range1) {
        const SureBoxH g = f;
        std::vector<const float*> shiftedD(static_cast<size_t>(2 * r + 1)), shiftedV(static_cast<size_t>(2 * r + 1));
        for (int y = range0; y < range1; ++y)
            boxRow(g, y, g.out.channel(0) + size_t(y) * w, g.out.channel(1) + size_t(y) * w, shiftedD, shiftedV);
    });
}

namespace {

// SureChoose's choice and accumulation for row y from the window sums sumD, sumV of its row.
template <int kJamesStein>
ATROUS_FORCE_INLINE inline void chooseFromSums(const SureChoose& f, int y, const float* sumD, const float* sumV,
                                               float* sScratch) {
    const int w = f.cI.width, h = f.cI.height;
    SureChoiceParams p = f.p;
    p.jamesStein = kJamesStein;  // a constant: no branch left in the x loop
    const size_t plane = size_t(w) * h;
    const size_t o = size_t(y) * w;
    const float* ATROUS_RESTRICT ci = f.cI.data + o;
    const float* ATROUS_RESTRICT cn = f.cNext.data + o;
    float* ATROUS_RESTRICT acc = f.acc.data + o;
    float* ATROUS_RESTRICT sOut = f.sOut.valid() ? f.sOut.data + o : sScratch;
    const float* ATROUS_RESTRICT sd = sumD;
    const float* ATROUS_RESTRICT sv = sumV;
#pragma omp simd
    for (int x = 0; x < w; ++x) {
        const float s = sureChoose(p, sd[x], sv[x]);
        acc[x] += s * (ci[x] - cn[x]);
        acc[x + plane] += s * (ci[x + plane] - cn[x + plane]);
        acc[x + 2 * plane] += s * (ci[x + 2 * plane] - cn[x + 2 * plane]);
        sOut[x] = s;
    }
}

// The same from the window's rows of horizontal sums (clamped: rows y - r..y + r) added in order
// dy = -r..r.
template <int kJamesStein>
ATROUS_FORCE_INLINE inline void chooseRow(const SureChoose& f, int y, const float* const* rowsD, const float* const* rowsV,
                                          float* sumD, float* sumV, float* sScratch) {
    const int w = f.cI.width, r = f.p.radius;
    cpu::sumRows(rowsD, 2 * r + 1, sumD, size_t(w));
    cpu::sumRows(rowsV, 2 * r + 1, sumV, size_t(w));
    chooseFromSums<kJamesStein>(f, y, sumD, sumV, sScratch);
}

template <int kJamesStein>
void chooseRows(const SureChoose& f, int y0, int y1) {
    const int w = f.boxH.width, h = f.boxH.height, r = f.p.radius;
    std::vector<float> sScratch(w), sumDRow(w), sumVRow(w);
    std::vector<const float*> rowsD(2 * r + 1), rowsV(2 * r + 1);
    for (int y = y0; y < y1; ++y) {
        for (int dy = -r; dy <= r; ++dy) {
            const int yy = clampIdx(y + dy, h - 1);
            rowsD[dy + r] = f.boxH.channel(0) + size_t(yy) * w;
            rowsV[dy + r] = f.boxH.channel(1) + size_t(yy) * w;
        }
        chooseRow<kJamesStein>(f, y, rowsD.data(), rowsV.data(), sumDRow.data(), sumVRow.data(), sScratch.data());
    }
}

// Both passes per band of rows: the horizontal sums of the band's rows and the r rows either side
// (clamped) into a ring of 2r + 1 rows, the choice of each row from its window's ring rows.
template <int kJamesStein>
void windowRows(const SureBoxH& box, const SureChoose& f, int y0, int y1) {
    constexpr int G = 4;  // interior rows whose window sums are taken together (cpu::sumRowRanges)
    const int w = box.in.width, h = box.in.height, r = box.radius;
    const int slots = 2 * r + G;
    const size_t n = static_cast<size_t>(slots);
    std::vector<float> ring(n * 2 * size_t(w)), sScratch(w), sums(size_t(G) * 2 * size_t(w));
    std::vector<const float*> rowsD(n), rowsV(n), shiftedD(n), shiftedV(n);
    std::vector<int> have(n, -1);
    auto slotOf = [&](int yy) {
        float* slot = ring.data() + size_t(yy % slots) * 2 * size_t(w);
        if (have[size_t(yy % slots)] != yy) {
            boxRow(box, yy, slot, slot + w, shiftedD, shiftedV);
            have[size_t(yy % slots)] = yy;
        }
        return slot;
    };
    for (int y = y0; y < y1;) {
        if (y - r >= 0 && y + G - 1 + r <= h - 1 && y + G <= y1) {
            // G interior rows: their windows are rows y - r .. y + G - 1 + r, no clamping.
            for (int k = 0; k < 2 * r + G; ++k) {
                const float* slot = slotOf(y - r + k);
                rowsD[size_t(k)] = slot, rowsV[size_t(k)] = slot + w;
            }
            int lo[G], hi[G];
            float* outD[G];
            float* outV[G];
            for (int j = 0; j < G; ++j) {
                lo[j] = j, hi[j] = j + 2 * r;
                outD[j] = sums.data() + size_t(2 * j) * w, outV[j] = outD[j] + w;
            }
            cpu::sumRowRanges<G>(rowsD.data(), lo, hi, outD, size_t(w));
            cpu::sumRowRanges<G>(rowsV.data(), lo, hi, outV, size_t(w));
            for (int j = 0; j < G; ++j) chooseFromSums<kJamesStein>(f, y + j, outD[j], outV[j], sScratch.data());
            y += G;
            continue;
        }
        for (int dy = -r; dy <= r; ++dy) {
            const float* slot = slotOf(clampIdx(y + dy, h - 1));
            rowsD[size_t(dy + r)] = slot, rowsV[size_t(dy + r)] = slot + w;
        }
        chooseRow<kJamesStein>(f, y, rowsD.data(), rowsV.data(), sums.data(), sums.data() + w, sScratch.data());
        ++y;
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

void runSureWindow(const CpuExec& exec, const SureBoxH& box, const SureChoose& choose) {
    const int w = box.in.width, h = box.in.height;
    if (w <= 2 * box.radius) {
        // Narrow images (the horizontal pass through its functor): the two passes.
        Image store;
        SureBoxH b = box;
        SureChoose c = choose;
        if (!b.out.valid()) store = Image::uninitialized(w, h, 2), b.out = store.view();
        c.boxH = b.out;
        runSureBoxH(exec, b);
        runSureChoose(exec, c);
        return;
    }
    // Bands of 32 rows: the ring recomputes the 2r rows either side (cheap horizontal sums).
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 32, [&](int y0, int y1) {
        if (choose.p.jamesStein)
            windowRows<1>(box, choose, y0, y1);
        else
            windowRows<0>(box, choose, y0, y1);
    });
}

namespace {

// Window sums along a row over the in-row taps, in tap order (as BoxSum<false>): the border columns
// one by one, the rest one tap offset at a time.
void rowWindowSums(const float* ATROUS_RESTRICT in, float* ATROUS_RESTRICT out, int w, int r) {
    auto border = [&](int x) {
        const int lo = x - r < 0 ? 0 : x - r, hi = x + r > w - 1 ? w - 1 : x + r;
        float s = 0.0f;
        for (int j = lo; j <= hi; ++j) s += in[j];
        out[x] = s;
    };
    for (int x = 0; x < r; ++x) border(x);
    if (r <= kMaxWindowRadius) {
        const float* shifted[2 * kMaxWindowRadius + 1];
        for (int k = 0; k <= 2 * r; ++k) shifted[k] = in + k;
        cpu::sumRows(shifted, 2 * r + 1, out + r, size_t(w - 2 * r));  // taps in order from 0 (as BoxSum)
    } else {
        for (int x = r; x < w - r; ++x) border(x);
    }
    for (int x = w - r; x < w; ++x) border(x);
}

// The window's column sums (rows y - r..y + r inside the image, added in order, as BoxSum<true>) of
// row-summed rows, for the rows y0..y1 - 1 of a band: rowFn(j, dst) writes row j's `channels` × w
// values into dst; each is computed once per band into a ring of 2r + 1 rows (so the row sums of
// the whole image are never stored), and use(y, sums) takes each row's column sums.
template <class RowFn, class UseFn>
void bandColumnSums(int y0, int y1, int h, int w, int r, int channels, RowFn rowFn, UseFn use) {
    constexpr int G = 4;  // output rows whose column sums are taken together (cpu::sumRowRanges)
    const int slots = 2 * r + G;
    const size_t rowSize = size_t(channels) * w;
    std::vector<float> ring(rowSize * slots), sums(rowSize * G);
    std::vector<const float*> rows(static_cast<size_t>(slots));
    int next = y0 - r < 0 ? 0 : y0 - r;  // the first row not computed yet
    for (int y = y0; y < y1; y += G) {
        const int g = y1 - y < G ? y1 - y : G;
        const int base = y - r < 0 ? 0 : y - r;  // rows[k] is image row base + k
        int lo[G], hi[G];
        float* out[G];
        for (int j = 0; j < G; ++j) {
            const int t = y + (j < g ? j : g - 1);  // (a short last group repeats its last row)
            lo[j] = (t - r < 0 ? 0 : t - r) - base;
            hi[j] = (t + r > h - 1 ? h - 1 : t + r) - base;
            out[j] = sums.data() + rowSize * size_t(j);
        }
        const int top = hi[G - 1] + base;
        for (; next <= top; ++next) rowFn(next, ring.data() + rowSize * size_t(next % slots));
        for (int k = 0; k <= top - base; ++k) rows[size_t(k)] = ring.data() + rowSize * size_t((base + k) % slots);
        // Each output's rows lo..hi added in order from 0, as BoxSum<true>.
        cpu::sumRowRanges<G>(rows.data(), lo, hi, out, rowSize);
        for (int j = 0; j < g; ++j) use(y + j, out[j]);
    }
}

}  // namespace

// 1 / boxTaps(r, x, y) for the pixels of row y: the interior's count is one value, so one division
// (and one per border column) instead of one per pixel and channel.
void tapReciprocals(int r, int y, int w, int h, float* ATROUS_RESTRICT inv) {
    const float interior = 1.0f / boxTaps(r, std::min(r, w - 1), y, w, h);
    for (int x = 0; x < w; ++x) inv[x] = interior;
    for (int x = 0; x < std::min(r, w); ++x) inv[x] = 1.0f / boxTaps(r, x, y, w, h);
    for (int x = std::max(0, w - r); x < w; ++x) inv[x] = 1.0f / boxTaps(r, x, y, w, h);
}

// The give-back's passes fused into row loops over bands of rows: (1) each row's moments
// (GiveBackMoments) summed along x, their column sums and the fit (giveBackSlope) per pixel into
// the coefficients; (2) the coefficients summed along x, their column sums and cN ← F +
// giveBackTerm. The same per-pixel arithmetic and order of additions as the functors
// (tests/albedo_giveback_test.cpp compares the two), with no image-sized window sums stored.
void runAlbedoGiveBack(const CpuExec& exec, const ImageView& input, const ImageView& cN, const ImageView& detailSum,
                       const ImageView& albedo, int radius, float significance, const GiveBackScratch* scratch) {
    const int w = input.width, h = input.height, r = radius;
    if (w <= 2 * r) {
        runAlbedoGiveBack<CpuExec>(exec, input, cN, detailSum, albedo, radius, significance);
        return;
    }
    constexpr int K = kGiveBackMoments;
    constexpr int kBand = 64;  // rows per task: the ring's 2r rows recomputed per band are ~12% more
    // The coefficients A (rgb) and b (rgb): the caller's spare planes, or new (every pixel is
    // written by the fit).
    Image coefStore;
    float* coef[6];
    if (scratch && scratch->count >= 6) {
        for (int k = 0; k < 6; ++k) coef[k] = scratch->plane[k];
    } else {
        coefStore = Image::uninitialized(w, h, 6);
        for (int k = 0; k < 6; ++k) coef[k] = coefStore.view().channel(k);
    }
    const bool sure = detailSum.valid();
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, kBand, [&](int y0, int y1) {
        std::vector<float> m(size_t(K) * w);
        auto moments = [&](int j, float* dst) {
            const size_t o = size_t(j) * w;
            for (int c = 0; c < 3; ++c) {
                const float* ATROUS_RESTRICT in = input.channel(c) + o;
                const float* ATROUS_RESTRICT fc = cN.channel(c) + o;
                const float* ATROUS_RESTRICT ds = sure ? detailSum.channel(c) + o : fc;
                const float* ATROUS_RESTRICT al = albedo.channel(c) + o;
                float* ATROUS_RESTRICT m0 = m.data() + size_t(5 * c) * w;
#pragma omp simd
                for (int x = 0; x < w; ++x) {
                    float f = fc[x];
                    if (sure) f += ds[x];
                    const float rr = in[x] - f, a = al[x];
                    m0[x] = a;
                    m0[w + x] = rr;
                    m0[2 * w + x] = a * a;
                    m0[3 * w + x] = a * rr;
                    m0[4 * w + x] = rr * rr;
                }
            }
            for (int k = 0; k < K; ++k) rowWindowSums(m.data() + size_t(k) * w, dst + size_t(k) * w, w, r);
        };
        std::vector<float> invNRow(static_cast<size_t>(w));
        auto fit = [&](int y, const float* s) {
            const size_t o = size_t(y) * w;
            float* ATROUS_RESTRICT invN = invNRow.data();
            tapReciprocals(r, y, w, h, invN);
            for (int c = 0; c < 3; ++c) {
                const float* ATROUS_RESTRICT q = s + size_t(5 * c) * w;
                float* ATROUS_RESTRICT A = coef[c] + o;
                float* ATROUS_RESTRICT b = coef[3 + c] + o;
#pragma omp simd
                for (int x = 0; x < w; ++x)
                    giveBackSlopeInv(significance, boxTaps(r, x, y, w, h), invN[x], q[x], q[w + x], q[2 * w + x],
                                     q[3 * w + x], q[4 * w + x], A[x], b[x]);
            }
        };
        bandColumnSums(y0, y1, h, w, r, K, moments, fit);
    });
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, kBand, [&](int y0, int y1) {
        auto coefRow = [&](int j, float* dst) {
            for (int k = 0; k < 6; ++k) rowWindowSums(coef[k] + size_t(j) * w, dst + size_t(k) * w, w, r);
        };
        std::vector<float> invNRow(static_cast<size_t>(w));
        auto apply = [&](int y, const float* s) {
            const size_t o = size_t(y) * w;
            float* ATROUS_RESTRICT invN = invNRow.data();
            tapReciprocals(r, y, w, h, invN);
            for (int c = 0; c < 3; ++c) {
                float* ATROUS_RESTRICT fc = cN.channel(c) + o;
                const float* ATROUS_RESTRICT ds = sure ? detailSum.channel(c) + o : fc;
                const float* ATROUS_RESTRICT al = albedo.channel(c) + o;
                const float* sA = s + size_t(c) * w;
                const float* sB = s + size_t(3 + c) * w;
#pragma omp simd
                for (int x = 0; x < w; ++x) {
                    float f = fc[x];
                    if (sure) f += ds[x];
                    fc[x] = f + giveBackTermInv(sA[x], sB[x], invN[x], al[x]);
                }
            }
        };
        bandColumnSums(y0, y1, h, w, r, 6, coefRow, apply);
    });
}

}  // namespace atrous::filters

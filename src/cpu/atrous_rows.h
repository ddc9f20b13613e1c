// The CPU row engine of the à-trous cascade, written once for every edge-stop policy
// (filters/atrous_level.h): the same taps as AtrousLevel<Stop>, in the same order per pixel,
// organised for SIMD. TBB over row blocks; for each of the 5 tap rows a contiguous, branch-free x
// loop over the interior columns with the 5 taps of that row unrolled; the columns within 2·step
// of the left/right border run one loop per tap over the columns where that tap is inside the
// image (not the scalar functor: docs/decisions.md, "Speed"), so the loads
// stay contiguous and every pixel still sums its taps in the functor's order. The policy's taps
// read through the centre row's plane pointers plus one row offset (one index per tap rather than
// a second set of row pointers, which the x loop had to reload from the stack).
//
// The same row loops are compiled three times, for baseline x86-64 (SSE2, what the library is
// compiled for), AVX2 (x86-64-v3) and AVX-512, chosen at run time (parallelForIsa, cpu_isa.h):
// EAW's tap loop needs ~30 live vectors (16 ymm
// registers spilled to the stack on every tap) and 16 lanes halve the instruction count where the
// core has 512-bit units (docs/decisions.md, "Speed").
//
// Plain floats and small structs only in the loop bodies; everything they call is force-inlined.
#pragma once
#include <cstddef>
#include <vector>

#include "core/isa_dispatch.h"
#include "filters/atrous_level.h"

namespace atrous::cpu {

// The pixel's running sums to and from the row buffers (acc[k][x]), fully unrolled.
template <int K, bool kFromZero>
ATROUS_FORCE_INLINE inline void loadSums(filters::AtrousSums<K>& a, float* const* acc, int x) {
    for (int k = 0; k < K; ++k) a.s[k] = kFromZero ? 0.0f : acc[k][x];
}
template <int K, bool kAdd>
ATROUS_FORCE_INLINE inline void storeSums(const filters::AtrousSums<K>& a, float* const* acc, int x) {
    for (int k = 0; k < K; ++k) acc[k][x] = kAdd ? acc[k][x] + a.s[k] : a.s[k];
}

template <class Stop>
struct AtrousRows {
    Stop stop;
    static constexpr int K = Stop::kSums;
    static constexpr bool kPartial = Stop::kRowPartialSums;
    using Row = typename Stop::Row;
    using TapRow = typename Stop::TapRow;
    using Sums = filters::AtrousSums<K>;

    // Taps QX... of tap row (dRow, hy) for the columns [lo, hi).
    template <bool kCentreRow>
    ATROUS_FORCE_INLINE void interior(const Stop& P, const Row& R, float* const* acc, int lo, int hi, int s,
                                      ptrdiff_t dRow, float hy, const TapRow& T) const {
        const float h0 = hy * filters::b3(-2), h1 = hy * filters::b3(-1), h2 = hy * filters::b3(0),
                    h3 = hy * filters::b3(1), h4 = hy * filters::b3(2);
#pragma omp simd
        for (int x = lo; x < hi; ++x) {
            const typename Stop::Centre c = P.centre(R, x);
            Sums a;
            loadSums<K, kPartial>(a, acc, x);
            P.template tap<-2, false>(R, c, a, ptrdiff_t(x) - 2 * s + dRow, h0, T);
            P.template tap<-1, false>(R, c, a, ptrdiff_t(x) - s + dRow, h1, T);
            P.template tap<0, kCentreRow>(R, c, a, ptrdiff_t(x) + dRow, h2, T);
            P.template tap<1, false>(R, c, a, ptrdiff_t(x) + s + dRow, h3, T);
            P.template tap<2, false>(R, c, a, ptrdiff_t(x) + 2 * s + dRow, h4, T);
            storeSums<K, kPartial>(a, acc, x);
        }
    }

    // Tap QX alone over the columns of [xa, xb) where it is inside the image.
    template <int QX, bool kCentre>
    ATROUS_FORCE_INLINE void border(const Stop& P, const Row& R, float* const* acc, int xa, int xb, int w, int s,
                                    ptrdiff_t dRow, float hy, const TapRow& T) const {
        const int lo = xa > -QX * s ? xa : -QX * s;
        const int hi = xb < w - QX * s ? xb : w - QX * s;
        const float hxy = hy * filters::b3(QX);
#pragma omp simd
        for (int x = lo; x < hi; ++x) {
            const typename Stop::Centre c = P.centre(R, x);
            Sums a;
            loadSums<K, kPartial>(a, acc, x);
            P.template tap<QX, kCentre>(R, c, a, ptrdiff_t(x) + QX * s + dRow, hxy, T);
            storeSums<K, kPartial>(a, acc, x);
        }
    }

    template <bool kCentreRow>
    ATROUS_FORCE_INLINE void tapRow(const Stop& P, const Row& R, float* const* acc, int x0, int x1, int w, int s,
                                    ptrdiff_t dRow, float hy, const TapRow& T) const {
        interior<kCentreRow>(P, R, acc, x0, x1, s, dRow, hy, T);
        for (int side = 0; side < 2; ++side) {
            const int xa = side == 0 ? 0 : x1, xb = side == 0 ? x0 : w;
            border<-2, false>(P, R, acc, xa, xb, w, s, dRow, hy, T);
            border<-1, false>(P, R, acc, xa, xb, w, s, dRow, hy, T);
            border<0, kCentreRow>(P, R, acc, xa, xb, w, s, dRow, hy, T);
            border<1, false>(P, R, acc, xa, xb, w, s, dRow, hy, T);
            border<2, false>(P, R, acc, xa, xb, w, s, dRow, hy, T);
        }
    }

    // Rows [y0, y1).
    ATROUS_FORCE_INLINE void operator()(int y0, int y1) const {
        // A local copy of the policy, so that its views are known not to alias the stores.
        const Stop P = stop;
        const int w = P.width(), h = P.height(), s = P.step();
        const int x0 = s * 2 < w ? s * 2 : w;
        const int x1 = w - s * 2 > x0 ? w - s * 2 : x0;
        std::vector<float> buf(size_t(K) * size_t(w));
        float* acc[K];
        for (int k = 0; k < K; ++k) acc[k] = buf.data() + size_t(k) * size_t(w);
        for (int y = y0; y < y1; ++y) {
            for (size_t i = 0; i < buf.size(); ++i) buf[i] = 0.0f;
            const Row R = P.row(y);
            for (int qy = -2; qy <= 2; ++qy) {
                const int yq = y + qy * s;
                if (yq < 0 || yq >= h) continue;  // dropped tap row, as in the functor
                const ptrdiff_t dRow = ptrdiff_t(yq - y) * w;
                const float hy = filters::b3(qy);
                const TapRow T = P.tapRow(qy);
                if constexpr (Stop::kCentreTap) {
                    if (qy == 0)
                        tapRow<true>(P, R, acc, x0, x1, w, s, dRow, hy, T);
                    else
                        tapRow<false>(P, R, acc, x0, x1, w, s, dRow, hy, T);
                } else {
                    tapRow<false>(P, R, acc, x0, x1, w, s, dRow, hy, T);
                }
            }
#pragma omp simd
            for (int x = 0; x < w; ++x) {
                Sums a;
                loadSums<K, false>(a, acc, x);
                P.finish(R, x, y, a);
            }
        }
    }
};

// One level of `stop` on the CPU's cores.
template <class Stop>
void runAtrousRows(const Stop& stop, Isa isa) {
    parallelForIsa(isa, 0, stop.height(), 8, AtrousRows<Stop>{stop});
}
// With the row engine's switch (filters::atrousCpuAvx512()).
template <class Stop>
void runAtrousRows(const Stop& stop, bool avx512) {
    runAtrousRows(stop, isaFromAvx512Switch(avx512));
}
// Rows [y0, y1) of the level only (the others are not written).
template <class Stop>
void runAtrousRows(const Stop& stop, bool avx512, int y0, int y1) {
    parallelForIsa(isaFromAvx512Switch(avx512), y0, y1, 8, AtrousRows<Stop>{stop});
}

}  // namespace atrous::cpu

// CPU path of the noise estimate without a variance buffer (filters/noise_estimate.h,
// docs/algorithms.md "Noise without a variance buffer"): the global MAD σ and the local
// per-pixel estimate, as row loops with the functors' arithmetic in the functors' order.
//
// Global σ (globalNoiseSigma): per band of rows, the demodulated colour rows (Demodulate's
// (c - 0)·(1/a')) in a ring of five rows padded by two replicated pixels either side, so the
// 25-tap double sum of MadDetail runs branch-free over every column; the detail plane's median per
// channel by a radix histogram of its bits and a selection within the one bin holding the median
// (the median is an element, so it is the element nth_element finds). Through the functors: a
// demodulated copy, MadDetail's clamped scalar taps and a partition + nth_element of each plane.
//
// Local estimate (runLocalNoise): DetailEnergy's 25 taps as a vectorised x loop over the interior
// columns (the two border columns either side through the functor), into one 3-plane temporary;
// then per band of rows the row half-sums of QuadrantRows into a ring of 2r+1 rows and
// LocalVariance's quadrant sums, choice and clamp over them (the 8-plane temporary of the functor
// path is never stored). Same sums in the same order: bit-equal (tests/noise_fit_test.cpp).
// FP exceptions are never unmasked or tested here; without -ftrapping-math GCC if-converts the
// selects (results unchanged: no reassociation or contraction is allowed by this).
#include "atrous/platform.h"
ATROUS_NO_TRAPPING_MATH

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/parallel.h"
#include "core/isa_dispatch.h"
#include "cpu/modulation_rows.h"
#include "cpu/row_sums.h"
#include "filters/noise_estimate.h"

namespace atrous::filters {

namespace {

// ---------------------------------------------------------------------------------------------
// The median of the finite values (NaN and +Inf left out, as medianFinite's partition does) of n
// floats, without reordering them: a histogram of the top 12 bits of an order-preserving key,
// then nth_element over the values of the bin that holds rank m/2.

inline uint32_t orderKey(float v) {
    uint32_t b;
    std::memcpy(&b, &v, sizeof b);
    return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}
inline bool counted(float v) { return v == v && v != INFINITY; }

constexpr int kBinBits = 12;
constexpr int kBins = 1 << kBinBits;

float radixMedian(const float* d, size_t n, float none) {
    const size_t chunk = 1 << 16;
    const size_t chunks = (n + chunk - 1) / chunk;
    // One histogram per chunk, with a last bin for the values left out (no branch per value).
    std::vector<uint32_t> hist(chunks * (kBins + 1), 0);
    tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
        uint32_t* H = hist.data() + k * (kBins + 1);
        const size_t i1 = std::min(n, (k + 1) * chunk);
        for (size_t i = k * chunk; i < i1; ++i) ++H[counted(d[i]) ? orderKey(d[i]) >> (32 - kBinBits) : kBins];
    });
    std::vector<size_t> total(kBins, 0);
    size_t m = 0;
    for (size_t k = 0; k < chunks; ++k)
        for (int b = 0; b < kBins; ++b) total[b] += hist[k * (kBins + 1) + size_t(b)];
    for (int b = 0; b < kBins; ++b) m += total[b];
    if (!m) return none;
    const size_t rank = m / 2;
    size_t before = 0;
    int bin = 0;
    for (; bin < kBins; ++bin) {
        if (rank < before + total[bin]) break;
        before += total[bin];
    }
    std::vector<std::vector<float>> found(chunks);
    tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
        const size_t i1 = std::min(n, (k + 1) * chunk);
        for (size_t i = k * chunk; i < i1; ++i)
            if (counted(d[i]) && int(orderKey(d[i]) >> (32 - kBinBits)) == bin) found[k].push_back(d[i]);
    });
    std::vector<float> cand;
    cand.reserve(total[bin]);
    for (auto& f : found) cand.insert(cand.end(), f.begin(), f.end());
    std::nth_element(cand.begin(), cand.begin() + long(rank - before), cand.end());
    return cand[rank - before];
}

// ---------------------------------------------------------------------------------------------
// Global σ.

// The double-precision finite test of the 25-tap sum (a non-finite tap makes it Inf or NaN).
ATROUS_FORCE_INLINE inline bool finiteD(double s) { return s - s == 0.0; }

struct MadBand {
    ImageView color, albedo, detail;
    AlbedoRule rule;
    ATROUS_FORCE_INLINE void operator()(int y0, int y1) const {
        const int w = color.width, h = color.height;
        const size_t pw = size_t(w) + 4;
        std::vector<float> ring(5 * 3 * pw), abuf(3 * size_t(w) + cpu::modulationRowScratch(w));
        int have[5] = {-1, -1, -1, -1, -1};
        float* const a[3] = {abuf.data(), abuf.data() + w, abuf.data() + 2 * size_t(w)};
        auto slot = [&](int j, int c) { return ring.data() + (size_t(j % 5) * 3 + size_t(c)) * pw; };
        auto fill = [&](int j) {
            const bool demod = albedo.valid();
            if (demod) cpu::modulationRow(rule, albedo, j, a, abuf.data() + 3 * size_t(w));
            for (int c = 0; c < 3; ++c) {
                const float* ATROUS_RESTRICT src = color.channel(c) + size_t(j) * w;
                float* ATROUS_RESTRICT dst = slot(j, c) + 2;
                const float* ATROUS_RESTRICT ac = a[c];
                if (demod) {
                    // Demodulate without emission or variance: (c - 0) · (1/a').
#pragma omp simd
                    for (int x = 0; x < w; ++x) dst[x] = (src[x] - 0.0f) * (1.0f / ac[x]);
                } else {
                    for (int x = 0; x < w; ++x) dst[x] = src[x];
                }
                dst[-2] = dst[-1] = dst[0];
                dst[w] = dst[w + 1] = dst[w - 1];
            }
            have[j % 5] = j;
        };
        for (int y = y0; y < y1; ++y) {
            for (int j = std::max(0, y - 2); j <= std::min(h - 1, y + 2); ++j)
                if (have[j % 5] != j) fill(j);
            for (int c = 0; c < 3; ++c) {
                const float* r[5];
                for (int k = 0; k < 5; ++k) r[k] = slot(clampIdx(y + k - 2, h - 1), c) + 2;
                const float *ATROUS_RESTRICT r0 = r[0], *ATROUS_RESTRICT r1 = r[1], *ATROUS_RESTRICT r2 = r[2],
                            *ATROUS_RESTRICT r3 = r[3], *ATROUS_RESTRICT r4 = r[4];
                float* ATROUS_RESTRICT out = detail.channel(c) + size_t(y) * w;
#pragma omp simd
                for (int x = 0; x < w; ++x) {
                    // MadDetail's sum: rows qy = -2..2, columns qx = -2..2, weights b3·b3 in
                    // float times the value in double (exact products), ws = 1 exactly.
                    double s = 0;
                    const float* rows[5] = {r0, r1, r2, r3, r4};
#pragma GCC unroll 5
                    for (int qy = -2; qy <= 2; ++qy)
#pragma GCC unroll 5
                        for (int qx = -2; qx <= 2; ++qx) s += double(b3(qx) * b3(qy)) * rows[qy + 2][x + qx];
                    const float v = r2[x];
                    out[x] = selectF(finite(v) & finiteD(s), fabsf(float(v - s / 1.0)), INFINITY);
                }
            }
        }
    }
};

// ---------------------------------------------------------------------------------------------
// Local estimate.

// DetailEnergy at interior pixel x of a row (taps x-2..x+2 inside the row): the functor's
// arithmetic without the index clamps. c/n: per channel the five rows (qy = -2..2); z: five rows.
template <bool kN, bool kZ>
ATROUS_FORCE_INLINE inline void energyAt(const float* const (&c)[3][5], const float* const (&n)[3][5],
                                         const float* const (&z)[5], const float (&maxDiff2)[3], int x, float& e0,
                                         float& e1, float& e2) {
    const float nx = kN ? n[0][2][x] : 0.0f, ny = kN ? n[1][2][x] : 0.0f, nz = kN ? n[2][2][x] : 0.0f;
    const float zp = kZ ? z[2][x] : 0.0f;
    const float cp0 = c[0][2][x], cp1 = c[1][2][x], cp2 = c[2][2][x];
    float s0 = 0, s1 = 0, s2 = 0, ws = 0, w2 = 0;
    // The taps unrolled (GCC vectorises the x loop only around straight-line code), selects for
    // the functor's conditionals: the same values.
#pragma GCC unroll 5
    for (int qy = -2; qy <= 2; ++qy) {
#pragma GCC unroll 5
        for (int qx = -2; qx <= 2; ++qx) {
            const int xx = x + qx, k = qy + 2;
            const float dn = kN ? sq(nx - n[0][k][xx]) + sq(ny - n[1][k][xx]) + sq(nz - n[2][k][xx]) : 0.0f;
            const float dz = kZ ? fabsf(zp - z[k][xx]) : 0.0f;
            const float q0 = c[0][k][xx], q1 = c[1][k][xx], q2 = c[2][k][xx];
            const bool near = (sq(q0 - cp0) <= maxDiff2[0]) & (sq(q1 - cp1) <= maxDiff2[1]) & (sq(q2 - cp2) <= maxDiff2[2]);
            const bool same = (dn <= kNoiseNormalDist2) & (dz <= kNoiseDepthRel * fabsf(zp)) & near;
            const float wt = selectF(same, b3(qx) * b3(qy), 0.0f);
            ws += wt;
            w2 += wt * wt;
            s0 += wt * q0;
            s1 += wt * q1;
            s2 += wt * q2;
        }
    }
    const float wp = b3(0) * b3(0);
    const float factor = 1.0f - 2.0f * wp / ws + w2 / (ws * ws);
    const bool use = factor > 1e-3f;
    const float d0 = cp0 - s0 / ws, d1 = cp1 - s1 / ws, d2 = cp2 - s2 / ws;
    e0 = selectF(use, d0 * d0 / factor, 0.0f);
    e1 = selectF(use, d1 * d1 / factor, 0.0f);
    e2 = selectF(use, d2 * d2 / factor, 0.0f);
}

template <bool kN, bool kZ>
struct EnergyRows {
    LocalNoise f;
    DetailEnergy de;  // the border columns
    ImageView energy;
    ATROUS_FORCE_INLINE void operator()(int y0, int y1) const {
        const int w = f.color.width, h = f.color.height;
        for (int y = y0; y < y1; ++y) {
            const float* c[3][5];
            const float* n[3][5];
            const float* z[5];
            for (int k = 0; k < 5; ++k) {
                const size_t o = size_t(clampIdx(y + k - 2, h - 1)) * size_t(w);
                for (int ch = 0; ch < 3; ++ch) {
                    c[ch][k] = f.color.channel(ch) + o;
                    n[ch][k] = kN ? f.normal.channel(ch) + o : nullptr;
                }
                z[k] = kZ ? f.depth.channel(0) + o : nullptr;
            }
            const size_t o = size_t(y) * size_t(w);
            float* ATROUS_RESTRICT e0 = energy.channel(0) + o;
            float* ATROUS_RESTRICT e1 = energy.channel(1) + o;
            float* ATROUS_RESTRICT e2 = energy.channel(2) + o;
            const int x0 = std::min(2, w), x1 = std::max(x0, w - 2);
            for (int x = 0; x < x0; ++x) de(x, y);
            float maxDiff2[3] = {f.maxDiff2[0], f.maxDiff2[1], f.maxDiff2[2]};
#pragma omp simd
            for (int x = x0; x < x1; ++x) energyAt<kN, kZ>(c, n, z, maxDiff2, x, e0[x], e1[x], e2[x]);
            for (int x = x1; x < w; ++x) de(x, y);
        }
    }
};

struct VarianceBands {
    LocalNoise f;
    ImageView energy;
    AlbedoRule rule;
    ATROUS_FORCE_INLINE void operator()(int y0, int y1) const {
        const int w = f.color.width, h = f.color.height, r = f.radius;
        const int slots = 2 * r + 1;
        const size_t rowSize = 6 * size_t(w);
        std::vector<float> ring(rowSize * size_t(slots));
        std::vector<float> abuf(3 * size_t(w) + cpu::modulationRowScratch(w));
        float* const a[3] = {abuf.data(), abuf.data() + w, abuf.data() + 2 * size_t(w)};
        // QuadrantRows of row j into its slot: left (x - i, i = 0..r) and right (x + i) sums per
        // channel, inside the row, in order i = 0..r. The energy row is copied between r zeros
        // either side, so every column takes the same branch-free sums: a tap outside the row
        // adds +0 to a sum of energies (>= +0), which leaves it as it is, bit for bit.
        std::vector<float> padded(size_t(w) + 2 * size_t(r), 0.0f);
        std::vector<const float*> left(size_t(r) + 1), right(size_t(r) + 1);
        auto quadRow = [&](int j) {
            float* dst = ring.data() + rowSize * size_t(j % slots);
            for (int ch = 0; ch < 3; ++ch) {
                std::memcpy(padded.data() + r, energy.channel(ch) + size_t(j) * w, size_t(w) * sizeof(float));
                const float* e = padded.data() + r;
                for (int i = 0; i <= r; ++i) left[size_t(i)] = e - i, right[size_t(i)] = e + i;
                cpu::sumRows(left.data(), r + 1, dst + size_t(ch) * w, size_t(w));
                cpu::sumRows(right.data(), r + 1, dst + size_t(3 + ch) * w, size_t(w));
            }
        };
        int next = std::max(0, y0 - r);
        std::vector<const float*> up(size_t(r) + 1), down(size_t(r) + 1), rowPtrs(size_t(r) + 1);
        std::vector<float> qsum(12 * size_t(w));
        const bool bgTest = f.normal.valid();
        for (int y = y0; y < y1; ++y) {
            for (; next <= std::min(h - 1, y + r); ++next) quadRow(next);
            // The rows of the up (y, y-1, ..) and down (y, y+1, ..) halves, in LocalVariance's order.
            int nUp = 0, nDown = 0;
            for (int j = 0; j <= r; ++j) {
                if (y - j >= 0) up[size_t(nUp++)] = ring.data() + rowSize * size_t((y - j) % slots);
                if (y + j < h) down[size_t(nDown++)] = ring.data() + rowSize * size_t((y + j) % slots);
            }
            cpu::modulationRowOrOne(rule, f.albedo, y, w, a, abuf.data() + 3 * size_t(w));
            // The quadrant sums q[k][ch] (up-left, up-right, down-left, down-right) of each pixel:
            // the half rows added in LocalVariance's order (up: y, y-1, ..; down: y, y+1, ..).
            for (int k = 0; k < 4; ++k)
                for (int ch = 0; ch < 3; ++ch) {
                    const int half = k / 2, side = k % 2;
                    const std::vector<const float*>& src = half == 0 ? up : down;
                    for (int j = 0; j < (half == 0 ? nUp : nDown); ++j)
                        rowPtrs[size_t(j)] = src[size_t(j)] + size_t(3 * side + ch) * w;
                    cpu::sumRows(rowPtrs.data(), half == 0 ? nUp : nDown, qsum.data() + size_t(3 * k + ch) * w, size_t(w));
                }
            const size_t o = size_t(y) * size_t(w);
            const float* ATROUS_RESTRICT Q = qsum.data();
            const float* ATROUS_RESTRICT nx = bgTest ? f.normal.channel(0) + o : nullptr;
            const float* ATROUS_RESTRICT ny = bgTest ? f.normal.channel(1) + o : nullptr;
            const float* ATROUS_RESTRICT nz = bgTest ? f.normal.channel(2) + o : nullptr;
            float* ATROUS_RESTRICT v0 = f.var.channel(0) + o;
            float* ATROUS_RESTRICT v1 = f.var.channel(1) + o;
            float* ATROUS_RESTRICT v2 = f.var.channel(2) + o;
            const float* ATROUS_RESTRICT a0 = a[0];
            const float* ATROUS_RESTRICT a1 = a[1];
            const float* ATROUS_RESTRICT a2 = a[2];
            const float fUp = float(nUp), fDown = float(nDown);
            const float floorVar[3] = {f.floorVar[0], f.floorVar[1], f.floorVar[2]};
            const float capMul = f.capMul;
#pragma omp simd
            for (int x = 0; x < w; ++x) {
                float q[4][3];
#pragma GCC unroll 4
                for (int k = 0; k < 4; ++k)
#pragma GCC unroll 3
                    for (int ch = 0; ch < 3; ++ch) q[k][ch] = Q[size_t(3 * k + ch) * w + x];
                // The tap counts (sums of small integers, exact): rows × columns of each quadrant.
                const float nl = float((x < r ? x : r) + 1), nr = float((w - 1 - x < r ? w - 1 - x : r) + 1);
                const float cnt[4] = {fUp * nl, fUp * nr, fDown * nl, fDown * nr};
                int best = 0;
                float bestMean = 3.0e38f;
#pragma GCC unroll 4
                for (int k = 0; k < 4; ++k) {
                    const float m = (q[k][0] + q[k][1] + q[k][2]) / cnt[k];
                    const bool better = m < bestMean;
                    bestMean = selectF(better, m, bestMean);
                    best = better ? k : best;
                }
                float qb0 = q[0][0], qb1 = q[0][1], qb2 = q[0][2], nb = cnt[0];
#pragma GCC unroll 3
                for (int k = 1; k < 4; ++k) {
                    const bool pick = best == k;
                    qb0 = selectF(pick, q[k][0], qb0), qb1 = selectF(pick, q[k][1], qb1), qb2 = selectF(pick, q[k][2], qb2);
                    nb = selectF(pick, cnt[k], nb);
                }
                const bool bg = bgTest ? (nx[x] == 0.0f) & (ny[x] == 0.0f) & (nz[x] == 0.0f) : false;
                const float fm = selectF(bg, kNoiseBackgroundFloor, 1.0f);
                const float av[3] = {a0[x], a1[x], a2[x]};
                const float qb[3] = {qb0, qb1, qb2};
                float out[3];
#pragma GCC unroll 3
                for (int ch = 0; ch < 3; ++ch) {
                    const float aa = av[ch];
                    const float local = selectF(bg, 0.0f, qb[ch] / nb);
                    const float v = minSel(maxSel(local, fm * floorVar[ch]), capMul * floorVar[ch]) * aa * aa;
                    const float res = selectF(finite(v), v, floorVar[ch] * aa * aa);
                    const float ia = 1.0f / aa;
                    out[ch] = res * (ia * ia);
                }
                v0[x] = out[0], v1[x] = out[1], v2[x] = out[2];
            }
        }
    }
};

}  // namespace

void globalNoiseSigma(const CpuExec& exec, const ImageView& color, const ImageView& albedo, float eps, float floor,
                      float sigma[3]) {
    globalNoiseSigma(exec, color, albedo, eps, floor, sigma, ImageView{});
}

void globalNoiseSigma(const CpuExec&, const ImageView& color, const ImageView& albedo, float eps, float floor,
                      float sigma[3], const ImageView& scratch) {
    const int w = color.width, h = color.height;
    Image store;
    const ImageView detail = scratch.valid() && scratch.channels >= 3 && scratch.sameSize(color)
                                 ? ImageView{scratch.data, w, h, 3}
                                 : (store = Image::uninitialized(w, h, 3)).view();
    MadBand band;
    band.color = color, band.albedo = albedo, band.detail = detail;
    band.rule.eps = eps, band.rule.floor = floor;  // the still rule (rim on, non-finite 0)
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 16, band);
    for (int c = 0; c < 3; ++c) {
        const float mid = radixMedian(detail.channel(c), detail.plane(), 0.0f);
        sigma[c] = float(double(mid) / 0.6745 / std::sqrt(double(kDetailVarFactor)));
    }
}

float medianFinite(const CpuExec&, const ImageView& v, float none) {
    return radixMedian(v.data, v.plane(), none);
}

void runLocalNoise(const CpuExec& exec, const LocalNoise& f) {
    const int w = f.color.width, h = f.color.height;
    Image store;
    const ImageView energy = f.scratch.valid() && f.scratch.channels >= 3 && f.scratch.sameSize(f.color)
                                 ? ImageView{f.scratch.data, w, h, 3}
                                 : (store = Image::uninitialized(w, h, 3)).view();
    DetailEnergy de;
    de.color = f.color, de.energy = energy, de.normal = f.normal, de.depth = f.depth;
    for (int c = 0; c < 3; ++c) de.maxDiff2[c] = f.maxDiff2[c];
    const bool n = f.normal.valid(), z = f.depth.valid();
    const cpu::Isa isa = cpu::activeIsa();
    if (n && z) cpu::parallelForIsa(isa, 0, h, 4, EnergyRows<true, true>{f, de, energy});
    else if (n) cpu::parallelForIsa(isa, 0, h, 4, EnergyRows<true, false>{f, de, energy});
    else if (z) cpu::parallelForIsa(isa, 0, h, 4, EnergyRows<false, true>{f, de, energy});
    else cpu::parallelForIsa(isa, 0, h, 4, EnergyRows<false, false>{f, de, energy});
    VarianceBands vb;
    vb.f = f, vb.energy = energy;
    vb.rule.eps = f.eps, vb.rule.floor = f.floor;  // LocalVariance's pixelModulationAlbedo defaults
    // Bands of 32 rows: the ring recomputes 2r row sums per band (cheap next to the energy).
    cpu::parallelForIsa(isa, 0, h, 32, vb);
    (void)exec;
}

}  // namespace atrous::filters

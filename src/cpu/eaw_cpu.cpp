// CPU fast path of one EAW level. Same math as filters::EawLevel (eawColorRecip, eawExponent,
// expNeg, b3 and EawLevel::finish are shared; taps are summed in the same order), organised for
// SIMD: TBB over row blocks, and for each of the 5 tap rows a contiguous, branch-free x loop over
// the interior columns with the 5 taps of that row unrolled. Columns within 2·step of the
// left/right border run one contiguous loop per tap over the columns where it is inside the image
// (through the scalar generic functor they took 19% of the time for 5% of the work).
//
// Where it pays:
// - the pair's 1/σ_c² is max(r(p), r(q)) of a per-pixel plane r = eawColorRecip(S) computed once
//   per level, not one division per tap;
// - the id term and the depth term are compiled out when they are off (their loads too);
// - tap loads go through the centre row's plane pointers plus one row offset: the loop then has
//   13-16 plane pointers instead of twice that (they did not fit in registers and were reloaded
//   from the stack for every tap);
// - the same row loops are compiled twice, for AVX2 (the build's baseline, x86-64-v3) and for
//   AVX-512, chosen at run time: the tap loop needs ~30 live vectors (16 ymm registers spilled to
//   the stack on every tap) and 16 lanes halve the instruction count where the core has 512-bit
//   units (measured 27% less CPU time for the level loop on the AMD EPYC build machine).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/scalable_allocator.h>

#include <memory>
#include <vector>

#include "atrous/error.h"
#include "core/parallel.h"
#include "cpu/cpu_simd.h"
#include "filters/eaw.h"

namespace atrous::filters {

bool& eawCpuFastPath() {
    static bool enabled = true;
    return enabled;
}

bool& eawCpuAvx512() {
    static bool enabled = cpuHasAvx512();
    return enabled;
}

namespace {

struct RowAcc {
    std::vector<float> ws, ar, ag, ab, vr, vg, vb;
    explicit RowAcc(int n) : ws(n), ar(n), ag(n), ab(n), vr(n), vg(n), vb(n) {}
    // The variance sums only when they are used (SURE): EAW reads them but ignores them.
    void clear(bool variance) {
        for (auto* v : {&ws, &ar, &ag, &ab}) std::fill(v->begin(), v->end(), 0.0f);
        if (variance)
            for (auto* v : {&vr, &vg, &vb}) std::fill(v->begin(), v->end(), 0.0f);
    }
};

// Rows [y0, y1) of one level. rS: the level's plane of eawColorRecip(S). kDepth/kIds = false
// (no depth stop / no ids) skip those loads; the terms are 0 either way. Always inlined into the
// per-ISA wrappers below, which decide the vector width.
template <bool kPropagate, bool kDepth, bool kIds>
ATROUS_FORCE_INLINE inline void levelRowsBody(const EawLevel& f, const float* rS, int y0, int y1) {
    const int w = f.cIn.width, h = f.cIn.height;
    const int s = f.p.step;
    const int x0 = s * 2 < w ? s * 2 : w;
    const int x1 = w - s * 2 > x0 ? w - s * 2 : x0;
    const int n = x1 - x0;
    RowAcc acc(w);  // indexed by x
    EawLevel g = f;
    g.p.propagate = kPropagate ? 1 : 0;  // a constant, so finish() has no branch left
    const EawLevelParams P = f.p;
    float posTap[25];
    for (int qy = -2; qy <= 2; ++qy)
        for (int qx = -2; qx <= 2; ++qx) posTap[(qy + 2) * 5 + qx + 2] = eawPositionTapScale(P, qx, qy);

    for (int y = y0; y < y1; ++y) {
        acc.clear(kPropagate);
        const size_t rowP = size_t(y) * w;
        const float* ATROUS_RESTRICT pr = f.cIn.channel(0) + rowP;
        const float* ATROUS_RESTRICT pg = f.cIn.channel(1) + rowP;
        const float* ATROUS_RESTRICT pb = f.cIn.channel(2) + rowP;
        const float* ATROUS_RESTRICT pS = rS + rowP;
        const float* ATROUS_RESTRICT pnx = f.normal.channel(0) + rowP;
        const float* ATROUS_RESTRICT pny = f.normal.channel(1) + rowP;
        const float* ATROUS_RESTRICT pnz = f.normal.channel(2) + rowP;
        const float* ATROUS_RESTRICT ppx = f.position.channel(0) + rowP;
        const float* ATROUS_RESTRICT ppy = f.position.channel(1) + rowP;
        const float* ATROUS_RESTRICT ppz = f.position.channel(2) + rowP;
        const float* ATROUS_RESTRICT pix = f.invX.channel(0) + rowP;
        const float* ATROUS_RESTRICT pz = f.depth.channel(0) + rowP;
        const float* ATROUS_RESTRICT piz = f.invZ.channel(0) + rowP;
        const float* ATROUS_RESTRICT pm0 = f.ids.channel(0) + rowP;
        const float* ATROUS_RESTRICT pm1 = f.ids.channel(1) + rowP;
        const float* ATROUS_RESTRICT pvr = kPropagate ? f.vIn.channel(0) + rowP : nullptr;
        const float* ATROUS_RESTRICT pvg = kPropagate ? f.vIn.channel(1) + rowP : nullptr;
        const float* ATROUS_RESTRICT pvb = kPropagate ? f.vIn.channel(2) + rowP : nullptr;
        float* ATROUS_RESTRICT aws = acc.ws.data();
        float* ATROUS_RESTRICT aar = acc.ar.data();
        float* ATROUS_RESTRICT aag = acc.ag.data();
        float* ATROUS_RESTRICT aab = acc.ab.data();
        float* ATROUS_RESTRICT avr = acc.vr.data();
        float* ATROUS_RESTRICT avg = acc.vg.data();
        float* ATROUS_RESTRICT avb = acc.vb.data();
        for (int qy = -2; qy <= 2; ++qy) {
            const int yq = y + qy * s;
            if (yq < 0 || yq >= h) continue;  // dropped tap row, as in the generic functor
            const size_t rowQ = size_t(yq) * w;
            const float hy = b3(qy);
            // Tap row q: the centre row's pointers plus dRow (one index per tap rather than a
            // second set of 13-16 row pointers, which the x loop had to reload from the stack).
            const ptrdiff_t dRow = ptrdiff_t(rowQ) - ptrdiff_t(rowP);
            const float* pt = posTap + (qy + 2) * 5;
            const float pt0 = pt[0], pt1 = pt[1], pt2 = pt[2], pt3 = pt[3], pt4 = pt[4];
#pragma omp simd
            for (int x = x0; x < x0 + n; ++x) {
                const float cr = pr[x], cg = pg[x], cb = pb[x], rp = pS[x];
                const float nx = pnx[x], ny = pny[x], nz = pnz[x];
                const float px = ppx[x], py = ppy[x], pz_ = ppz[x];
                const float ixp = pix[x], zp = kDepth ? pz[x] : 0.0f, izp = kDepth ? piz[x] : 0.0f;
                const float m0 = kIds ? pm0[x] : 0.0f, m1 = kIds ? pm1[x] : 0.0f;
                float ws = 0, ar = 0, ag = 0, ab = 0, vr = 0, vg = 0, vb = 0;
#define ATROUS_EAW_TAP(QX, PT)                                                         \
    {                                                                                  \
        const ptrdiff_t xqr = x + (QX)*s + dRow;                                       \
        const float r = pr[xqr], g = pg[xqr], b = pb[xqr];                             \
        const float dc2 = sq(cr - r) + sq(cg - g) + sq(cb - b);                        \
        const float dn2 = sq(nx - pnx[xqr]) + sq(ny - pny[xqr]) + sq(nz - pnz[xqr]);   \
        const float dx2 = sq(px - ppx[xqr]) + sq(py - ppy[xqr]) + sq(pz_ - ppz[xqr]);  \
        const float dz = kDepth ? (zp - pz[xqr]) * izp : 0.0f;                         \
        const float did2 = kIds ? sq(m0 - pm0[xqr]) + sq(m1 - pm1[xqr]) : 0.0f;        \
        const float e = eawExponent(P, dc2, rp, pS[xqr], dn2, dx2, ixp, PT, dz, did2); \
        const float wt = hy * b3(QX) * expNeg(-e);                                     \
        ws += wt;                                                                      \
        ar += wt * r;                                                                  \
        ag += wt * g;                                                                  \
        ab += wt * b;                                                                  \
        if (kPropagate) {                                                              \
            const float w2 = wt * wt;                                                  \
            vr += w2 * pvr[xqr];                                                       \
            vg += w2 * pvg[xqr];                                                       \
            vb += w2 * pvb[xqr];                                                       \
        }                                                                              \
    }
                ATROUS_EAW_TAP(-2, pt0)
                ATROUS_EAW_TAP(-1, pt1)
                ATROUS_EAW_TAP(0, pt2)
                ATROUS_EAW_TAP(1, pt3)
                ATROUS_EAW_TAP(2, pt4)
                aws[x] += ws;
                aar[x] += ar;
                aag[x] += ag;
                aab[x] += ab;
                if (kPropagate) {
                    avr[x] += vr;
                    avg[x] += vg;
                    avb[x] += vb;
                }
            }
            // Border columns (within 2·step of the left/right edge): one loop per tap over the
            // columns where that tap is inside the image (the others are dropped, as in the
            // generic functor), so the loads stay contiguous and the loop branch-free.
#define ATROUS_EAW_BORDER_TAP(QX, PT, XA, XB)                                                   \
    {                                                                                           \
        const int lo = (XA) > -(QX)*s ? (XA) : -(QX)*s;                                         \
        const int hi = (XB) < w - (QX)*s ? (XB) : w - (QX)*s;                                   \
        _Pragma("omp simd") for (int x = lo; x < hi; ++x) {                                     \
            const float cr = pr[x], cg = pg[x], cb = pb[x], rp = pS[x];                         \
            const float nx = pnx[x], ny = pny[x], nz = pnz[x];                                  \
            const float px = ppx[x], py = ppy[x], pz_ = ppz[x];                                 \
            const float ixp = pix[x], zp = kDepth ? pz[x] : 0.0f, izp = kDepth ? piz[x] : 0.0f; \
            const float m0 = kIds ? pm0[x] : 0.0f, m1 = kIds ? pm1[x] : 0.0f;                   \
            float ws = 0, ar = 0, ag = 0, ab = 0, vr = 0, vg = 0, vb = 0;                       \
            ATROUS_EAW_TAP(QX, PT)                                                              \
            aws[x] += ws;                                                                       \
            aar[x] += ar;                                                                       \
            aag[x] += ag;                                                                       \
            aab[x] += ab;                                                                       \
            if (kPropagate) {                                                                   \
                avr[x] += vr;                                                                   \
                avg[x] += vg;                                                                   \
                avb[x] += vb;                                                                   \
            }                                                                                   \
        }                                                                                       \
    }
            for (int side = 0; side < 2; ++side) {
                const int xa = side == 0 ? 0 : x1, xb = side == 0 ? x0 : w;
                ATROUS_EAW_BORDER_TAP(-2, pt0, xa, xb)
                ATROUS_EAW_BORDER_TAP(-1, pt1, xa, xb)
                ATROUS_EAW_BORDER_TAP(0, pt2, xa, xb)
                ATROUS_EAW_BORDER_TAP(1, pt3, xa, xb)
                ATROUS_EAW_BORDER_TAP(2, pt4, xa, xb)
            }
#undef ATROUS_EAW_BORDER_TAP
#undef ATROUS_EAW_TAP
        }
        // A local copy of the functor, so that its views are known not to alias the stores and
        // the normalisation loop vectorises (it was a scalar loop: ~1/25 of the tap work).
#pragma omp simd
        for (int x = 0; x < w; ++x) g.finish(x, y, aws[x], aar[x], aag[x], aab[x], avr[x], avg[x], avb[x]);
    }
}

// r = eawColorRecip(S) of rows [y0, y1).
ATROUS_FORCE_INLINE inline void colorRecipBody(const EawLevelParams& P, const float* ATROUS_RESTRICT S,
                                               float* ATROUS_RESTRICT r, size_t i0, size_t i1) {
#pragma omp simd
    for (size_t i = i0; i < i1; ++i) r[i] = eawColorRecip(P, S[i]);
}

template <bool kPropagate, bool kDepth, bool kIds>
void levelRowsAvx2(const EawLevel& f, const float* rS, int y0, int y1) {
    levelRowsBody<kPropagate, kDepth, kIds>(f, rS, y0, y1);
}
void colorRecipAvx2(const EawLevelParams& P, const float* S, float* r, size_t i0, size_t i1) {
    colorRecipBody(P, S, r, i0, i1);
}

#if ATROUS_CPU_AVX512
template <bool kPropagate, bool kDepth, bool kIds>
ATROUS_TARGET_AVX512 void levelRowsAvx512(const EawLevel& f, const float* rS, int y0, int y1) {
    levelRowsBody<kPropagate, kDepth, kIds>(f, rS, y0, y1);
}
ATROUS_TARGET_AVX512 void colorRecipAvx512(const EawLevelParams& P, const float* S, float* r, size_t i0, size_t i1) {
    colorRecipBody(P, S, r, i0, i1);
}
#endif

using LevelRowsFn = void (*)(const EawLevel&, const float*, int, int);

template <bool kPropagate, bool kDepth, bool kIds>
LevelRowsFn pickLevelRows(bool avx512) {
#if ATROUS_CPU_AVX512
    if (avx512) return &levelRowsAvx512<kPropagate, kDepth, kIds>;
#else
    (void)avx512;
#endif
    return &levelRowsAvx2<kPropagate, kDepth, kIds>;
}

template <bool kPropagate>
LevelRowsFn pickLevelRows(bool avx512, bool depth, bool ids) {
    if (depth)
        return ids ? pickLevelRows<kPropagate, true, true>(avx512) : pickLevelRows<kPropagate, true, false>(avx512);
    return ids ? pickLevelRows<kPropagate, false, true>(avx512) : pickLevelRows<kPropagate, false, false>(avx512);
}

}  // namespace

void runEawLevel(const CpuExec& exec, const EawLevel& f) {
    if (!eawCpuFastPath()) {
        exec.forEachPixel(f.cIn.width, f.cIn.height, f);
        return;
    }
    const int w = f.cIn.width, h = f.cIn.height;
    const bool avx512 = eawCpuAvx512();
    // The level's r = 1/(colorMul · 2S + ε) plane (see eawColorRecip).
    // (Not an Image: that would zero-fill it first.)
    std::unique_ptr<float, void (*)(void*)> rS(static_cast<float*>(scalable_aligned_malloc(size_t(w) * h * 4, 64)),
                                               scalable_aligned_free);
    if (!rS) throw RuntimeError("out of host memory for the EAW colour scale plane");
    float* r = rS.get();
    const float* S = f.S.channel(0);
    const size_t count = size_t(w) * h;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 16384), [&](const tbb::blocked_range<size_t>& b) {
#if ATROUS_CPU_AVX512
        if (avx512) {
            colorRecipAvx512(f.p, S, r, b.begin(), b.end());
            return;
        }
#endif
        colorRecipAvx2(f.p, S, r, b.begin(), b.end());
    });
    const bool depth = f.p.invDepth > 0.0f, ids = f.p.idPenalty > 0.0f;
    const LevelRowsFn rows =
        f.p.propagate ? pickLevelRows<true>(avx512, depth, ids) : pickLevelRows<false>(avx512, depth, ids);
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 8),
                      [&](const tbb::blocked_range<int>& b) { rows(f, r, b.begin(), b.end()); });
}

}  // namespace atrous::filters

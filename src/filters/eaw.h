// The edge-avoiding à-trous edge stop (Dammertz et al. 2010, docs/algorithms-eaw-sure.md) as a
// policy of the shared à-trous level (filters/atrous_level.h): the functor both backends launch
// and the CPU row engine (src/cpu/atrous_rows.h) run the same EawStop::tap.
#pragma once
#include "atrous/image.h"
#include "filters/atrous_level.h"
#include "filters/filter_math.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::filters {

// Per-level constants, derived on the host from EawParams (still_cascades.h).
struct EawLevelParams {
    int step = 1;               // 2^i: tap spacing of level i
    float colorMul = 1.0f;      // factor^(2i): σ_c,i² = colorMul · 2 min(S(p), S(q))
    float colorEps = 1e-12f;    // keeps σ_c,i² > 0 where the variance is exactly 0
    float invNormal = 0.0f;     // 1/σ_n² (÷ step² with normalStepScale); 0 = no normal stop
    int autoPosition = 1;       // 1: σ_x scales with the tap's pixel offset (invX = 1/(k_x F)²)
    float invDepth = 0.0f;      // 1/σ_z²; 0 = no depth stop
    float idPenalty = 0.0f;     // exponent per unit squared id difference (0 = ids ignored)
    int propagate = 0;          // SURE: propagate variance and write the detail maps
    float detailVarScale = 1.0f;  // α_i: correlation correction of v_i (1 = independence)
};

// 1/σ_c² factor of one pixel at this level: r = 1/(colorMul · 2S + ε). The pair's σ_c² uses
// 2·min(S(p), S(q)) (symmetric, so the filter stays mean-preserving, and a quiet pixel never takes
// in a noisy bright neighbour: with S(p) + S(q) the sun seen directly leaked into the sky around
// it), and since s -> 1/(colorMul · 2s + ε) is decreasing (and float rounding is monotone),
// 1/σ_c²(p, q) = max(r(p), r(q)) exactly: the CPU fast path computes r once per pixel and level
// instead of one division per tap.
ATROUS_INLINE float eawColorRecip(const EawLevelParams& P, float S) {
    return 1.0f / (P.colorMul * (2.0f * S) + P.colorEps);
}

// Exponent of the combined edge-stopping weight w = exp(-e) of one tap: the colour, normal,
// position, depth and id terms summed so that a single exp is evaluated per tap.
//   dc2 = |c_i(p) - c_i(q)|², rp/rq = eawColorRecip of S(p)/S(q), dn2 = |n(p) - n(q)|²,
//   dx2 = |x(p) - x(q)|², invXp = 1/σ_x² at p, posTap = 1/|pixel offset|² (auto) or 1,
//   dzRel = (z_p - z_q)/z_p, did2 = squared mesh + material id difference.
ATROUS_INLINE float eawExponent(const EawLevelParams& P, float dc2, float rp, float rq, float dn2, float dx2,
                                float invXp, float posTap, float dzRel, float did2) {
    return dc2 * maxSel(rp, rq) + dn2 * P.invNormal + dx2 * invXp * posTap + dzRel * dzRel * P.invDepth +
           did2 * P.idPenalty;
}

// 1/|offset|² of tap q at step s for the automatic σ_x (1 for the raw form; the centre tap has
// zero distance, so its value does not matter).
ATROUS_INLINE float eawPositionTapScale(const EawLevelParams& P, int qx, int qy) {
    if (!P.autoPosition) return 1.0f;
    int d2 = (qx * qx + qy * qy) * P.step * P.step;
    return d2 > 0 ? 1.0f / float(d2) : 1.0f;
}

// Buffers of one level. Every feature view is present (zero-filled when the user gave none, so
// its term vanishes); channel counts: c/var/normal/position 3, S/rS/invX/invZ/depth 1, ids 2,
// detail 2 (D = Σ_ch d_i², V = Σ_ch v_i).
struct EawLevel {
    EawLevelParams p;
    ImageView cIn, cOut;     // c_i -> c_{i+1}
    ImageView vIn, vOut;     // var(c_i) -> var(c_{i+1}) (propagate only)
    ImageView detail;        // D, V of d_i = c_i - c_{i+1} (propagate only)
    ImageView S;             // colour scale per pixel
    ImageView rS;            // scratch: runEawLevel writes eawColorRecip(S) of this level here
                             // (allocated by it when invalid)
    ImageView normal, position, invX, depth, invZ, ids;
};

// r = eawColorRecip(S) per pixel: the taps read the pair's 1/σ_c² as max(r(p), r(q)).
struct EawColorRecip {
    EawLevelParams p;
    ImageView S, r;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const { r(x, y, 0) = eawColorRecip(p, S(x, y, 0)); }
};

// The EAW edge-stop policy of the à-trous level (filters/atrous_level.h): colour, normal,
// position, depth and id terms summed into one exponent per tap, w = h exp(-e). With kPropagate
// it is SURE's: the variance is propagated with squared weights and the detail maps are written.
// kDepth/kIds = false compile the depth/id terms and their loads out (the CPU row engine picks
// them when those stops are off; the terms are 0 either way).
template <bool kPropagate, bool kDepth = true, bool kIds = true>
struct EawStop {
    EawLevel f;

    static constexpr int kSums = kPropagate ? 7 : 4;  // Σw, Σwc (3), Σw² var (3)
    static constexpr bool kCentreTap = false;
    static constexpr bool kRowPartialSums = true;
    static constexpr bool kScalarTaps = false;

    struct Row {
        const float *r, *g, *b, *rS, *nx, *ny, *nz, *px, *py, *pz, *ix, *z, *iz, *m0, *m1, *vr, *vg, *vb;
    };
    struct Centre {
        float r, g, b, rp, nx, ny, nz, px, py, pz, ix, z, iz, m0, m1;
    };
    struct TapRow {
        float pt[5];  // eawPositionTapScale of the row's taps
    };

    ATROUS_HOST_DEVICE int width() const { return f.cIn.width; }
    ATROUS_HOST_DEVICE int height() const { return f.cIn.height; }
    ATROUS_HOST_DEVICE int step() const { return f.p.step; }

    ATROUS_HOST_DEVICE Row row(int y) const {
        const size_t o = size_t(y) * size_t(f.cIn.width);
        Row R;
        R.r = f.cIn.channel(0) + o, R.g = f.cIn.channel(1) + o, R.b = f.cIn.channel(2) + o;
        R.rS = f.rS.channel(0) + o;
        R.nx = f.normal.channel(0) + o, R.ny = f.normal.channel(1) + o, R.nz = f.normal.channel(2) + o;
        R.px = f.position.channel(0) + o, R.py = f.position.channel(1) + o, R.pz = f.position.channel(2) + o;
        R.ix = f.invX.channel(0) + o;
        // The depth and id planes are not read (may be absent) when their terms are compiled out.
        R.z = kDepth ? f.depth.channel(0) + o : nullptr, R.iz = kDepth ? f.invZ.channel(0) + o : nullptr;
        R.m0 = kIds ? f.ids.channel(0) + o : nullptr, R.m1 = kIds ? f.ids.channel(1) + o : nullptr;
        R.vr = R.vg = R.vb = nullptr;
        if (kPropagate) R.vr = f.vIn.channel(0) + o, R.vg = f.vIn.channel(1) + o, R.vb = f.vIn.channel(2) + o;
        return R;
    }
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE Centre centre(const Row& R, int x) const {
        Centre c;
        c.r = R.r[x], c.g = R.g[x], c.b = R.b[x], c.rp = R.rS[x];
        c.nx = R.nx[x], c.ny = R.ny[x], c.nz = R.nz[x];
        c.px = R.px[x], c.py = R.py[x], c.pz = R.pz[x];
        c.ix = R.ix[x], c.z = kDepth ? R.z[x] : 0.0f, c.iz = kDepth ? R.iz[x] : 0.0f;
        c.m0 = kIds ? R.m0[x] : 0.0f, c.m1 = kIds ? R.m1[x] : 0.0f;
        return c;
    }
    ATROUS_HOST_DEVICE TapRow tapRow(int qy) const {
        TapRow T;
        for (int qx = -2; qx <= 2; ++qx) T.pt[qx + 2] = eawPositionTapScale(f.p, qx, qy);
        return T;
    }
    template <int QX, bool kCentre>
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void tap(const Row& R, const Centre& c, AtrousSums<kSums>& a, ptrdiff_t q,
                                                    float hxy, const TapRow& T) const {
        const float r = R.r[q], g = R.g[q], b = R.b[q];
        const float dc2 = sq(c.r - r) + sq(c.g - g) + sq(c.b - b);
        const float dn2 = sq(c.nx - R.nx[q]) + sq(c.ny - R.ny[q]) + sq(c.nz - R.nz[q]);
        const float dx2 = sq(c.px - R.px[q]) + sq(c.py - R.py[q]) + sq(c.pz - R.pz[q]);
        const float dz = kDepth ? (c.z - R.z[q]) * c.iz : 0.0f;
        const float did2 = kIds ? sq(c.m0 - R.m0[q]) + sq(c.m1 - R.m1[q]) : 0.0f;
        const float e = eawExponent(f.p, dc2, c.rp, R.rS[q], dn2, dx2, c.ix, T.pt[QX + 2], dz, did2);
        const float wt = hxy * fastExp(-e);
        a.s[0] += wt;
        a.s[1] += wt * r;
        a.s[2] += wt * g;
        a.s[3] += wt * b;
        if constexpr (kPropagate) {
            const float w2 = wt * wt;
            a.s[4] += w2 * R.vr[q];
            a.s[5] += w2 * R.vg[q];
            a.s[6] += w2 * R.vb[q];
        }
    }

    // Normalisation and the SURE detail maps. Σw >= h(0) > 0 because the centre tap always has
    // weight h(0)·exp(0).
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void finish(const Row&, int x, int y, const AtrousSums<kSums>& a) const {
        const float inv = 1.0f / a.s[0];
        const float nr = a.s[1] * inv, ng = a.s[2] * inv, nb = a.s[3] * inv;
        f.cOut(x, y, 0) = nr;
        f.cOut(x, y, 1) = ng;
        f.cOut(x, y, 2) = nb;
        if constexpr (kPropagate) {
            // var(c_{i+1}) = Σ a_q² var(c_i(q)), a_q = h w / k (independence assumption).
            const float inv2 = inv * inv;
            const float v1r = a.s[4] * inv2, v1g = a.s[5] * inv2, v1b = a.s[6] * inv2;
            f.vOut(x, y, 0) = v1r;
            f.vOut(x, y, 1) = v1g;
            f.vOut(x, y, 2) = v1b;
            // v_i = var(c_i) + var(c_{i+1}) - 2 a_p var(c_i), a_p = h(0)/k, times α_i.
            const float ap2 = 2.0f * 0.140625f * inv;
            const float v0r = f.vIn(x, y, 0), v0g = f.vIn(x, y, 1), v0b = f.vIn(x, y, 2);
            const float vd = (v0r + v1r - ap2 * v0r) + (v0g + v1g - ap2 * v0g) + (v0b + v1b - ap2 * v0b);
            const float dr = f.cIn(x, y, 0) - nr, dg = f.cIn(x, y, 1) - ng, db = f.cIn(x, y, 2) - nb;
            f.detail(x, y, 0) = dr * dr + dg * dg + db * db;
            f.detail(x, y, 1) = maxSel(vd, 0.0f) * f.p.detailVarScale;
        }
    }
};
// SURE's level is EAW's with the variance propagated and the detail maps written.
using SureStop = EawStop<true>;

// Runs one level on `exec` (f.p.propagate picks EAW or SURE's policy): the rS plane, then the
// functor. The CpuExec overload (src/cpu/eaw_cpu.cpp) runs both through vectorised row loops
// (the row engine, src/cpu/atrous_rows.h).
template <class Exec>
void runEawLevel(const Exec& exec, const EawLevel& level) {
    Image store;
    EawLevel f = level;
    f.rS = levelPlane(exec, f.rS, f.cIn.width, f.cIn.height, store);
    if (f.p.propagate)
        runAtrousLevelFunctor(exec, EawColorRecip{f.p, f.S, f.rS}, SureStop{f});
    else
        runAtrousLevelFunctor(exec, EawColorRecip{f.p, f.S, f.rS}, EawStop<false>{f});
    if (!store.empty()) exec.synchronize();  // before `store` dies
}
void runEawLevel(const CpuExec& exec, const EawLevel& f);

// Old names of the row engine's switches (filters/atrous_level.h), shared with SVGF.
inline bool& eawCpuFastPath() { return atrousCpuFastPath(); }
inline bool& eawCpuAvx512() { return atrousCpuAvx512(); }

}  // namespace atrous::filters

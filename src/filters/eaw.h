// One level of the edge-avoiding à-trous cascade (Dammertz et al. 2010, docs/denoising.md) as a
// per-pixel functor shared by the CPU and CUDA backends, plus the tap-weight math that the CPU
// fast path (src/cpu/eaw_cpu.cpp) reuses so both compute the same thing.
#pragma once
#include "atrous/image.h"
#include "filters/filter_math.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::filters {

// Per-level constants, derived on the host from EawParams (denoise_driver.h).
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
// its term vanishes); channel counts: c/var/normal/position 3, S/invX/invZ/depth 1, ids 2,
// detail 2 (D = Σ_ch d_i², V = Σ_ch v_i).
struct EawLevel {
    EawLevelParams p;
    ImageView cIn, cOut;     // c_i -> c_{i+1}
    ImageView vIn, vOut;     // var(c_i) -> var(c_{i+1}) (propagate only)
    ImageView detail;        // D, V of d_i = c_i - c_{i+1} (propagate only)
    ImageView S;             // colour scale per pixel
    ImageView normal, position, invX, depth, invZ, ids;

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = cIn.width, h = cIn.height;
        const float cr = cIn(x, y, 0), cg = cIn(x, y, 1), cb = cIn(x, y, 2);
        const float rp = eawColorRecip(p, S(x, y, 0));
        const float nx = normal(x, y, 0), ny = normal(x, y, 1), nz = normal(x, y, 2);
        const float px = position(x, y, 0), py = position(x, y, 1), pz = position(x, y, 2);
        const float ixp = invX(x, y, 0), zp = depth(x, y, 0), izp = invZ(x, y, 0);
        const float m0 = ids(x, y, 0), m1 = ids(x, y, 1);
        float ws = 0, ar = 0, ag = 0, ab = 0, vr = 0, vg = 0, vb = 0;
        for (int qy = -2; qy <= 2; ++qy) {
            // Taps outside the image are dropped (weight 0) rather than clamped: clamping would
            // count a border pixel several times and break the variance propagation.
            const int yq = y + qy * p.step;
            if (yq < 0 || yq >= h) continue;
            const float hy = b3(qy);
            for (int qx = -2; qx <= 2; ++qx) {
                const int xq = x + qx * p.step;
                if (xq < 0 || xq >= w) continue;
                const float qr = cIn(xq, yq, 0), qg = cIn(xq, yq, 1), qb = cIn(xq, yq, 2);
                const float dc2 = sq(cr - qr) + sq(cg - qg) + sq(cb - qb);
                const float dn2 = sq(nx - normal(xq, yq, 0)) + sq(ny - normal(xq, yq, 1)) + sq(nz - normal(xq, yq, 2));
                const float dx2 =
                    sq(px - position(xq, yq, 0)) + sq(py - position(xq, yq, 1)) + sq(pz - position(xq, yq, 2));
                const float dz = (zp - depth(xq, yq, 0)) * izp;
                const float did2 = sq(m0 - ids(xq, yq, 0)) + sq(m1 - ids(xq, yq, 1));
                const float e = eawExponent(p, dc2, rp, eawColorRecip(p, S(xq, yq, 0)), dn2, dx2, ixp,
                                            eawPositionTapScale(p, qx, qy), dz, did2);
                const float wt = hy * b3(qx) * expNeg(-e);
                ws += wt;
                ar += wt * qr;
                ag += wt * qg;
                ab += wt * qb;
                if (p.propagate) {
                    const float w2 = wt * wt;
                    vr += w2 * vIn(xq, yq, 0);
                    vg += w2 * vIn(xq, yq, 1);
                    vb += w2 * vIn(xq, yq, 2);
                }
            }
        }
        finish(x, y, ws, ar, ag, ab, vr, vg, vb);
    }

    // Normalisation and the SURE detail maps; shared with the CPU fast path. ws >= h(0) > 0
    // because the centre tap always has weight h(0)·exp(0).
    ATROUS_HOST_DEVICE void finish(int x, int y, float ws, float ar, float ag, float ab, float vr, float vg,
                                   float vb) const {
        const float inv = 1.0f / ws;
        const float nr = ar * inv, ng = ag * inv, nb = ab * inv;
        cOut(x, y, 0) = nr;
        cOut(x, y, 1) = ng;
        cOut(x, y, 2) = nb;
        if (p.propagate) {
            // var(c_{i+1}) = Σ a_q² var(c_i(q)), a_q = h w / k (independence assumption).
            const float inv2 = inv * inv;
            const float v1r = vr * inv2, v1g = vg * inv2, v1b = vb * inv2;
            vOut(x, y, 0) = v1r;
            vOut(x, y, 1) = v1g;
            vOut(x, y, 2) = v1b;
            // v_i = var(c_i) + var(c_{i+1}) - 2 a_p var(c_i), a_p = h(0)/k, times α_i.
            const float ap2 = 2.0f * 0.140625f * inv;
            const float v0r = vIn(x, y, 0), v0g = vIn(x, y, 1), v0b = vIn(x, y, 2);
            const float vd = (v0r + v1r - ap2 * v0r) + (v0g + v1g - ap2 * v0g) + (v0b + v1b - ap2 * v0b);
            const float dr = cIn(x, y, 0) - nr, dg = cIn(x, y, 1) - ng, db = cIn(x, y, 2) - nb;
            detail(x, y, 0) = dr * dr + dg * dg + db * db;
            detail(x, y, 1) = maxSel(vd, 0.0f) * p.detailVarScale;
        }
    }
};

// Runs one level on `exec`. The generic version launches the functor; the CpuExec overload
// (src/cpu/eaw_cpu.cpp) runs a row-vectorised interior with the same math.
template <class Exec>
void runEawLevel(const Exec& exec, const EawLevel& f) {
    exec.forEachPixel(f.cIn.width, f.cIn.height, f);
}
void runEawLevel(const CpuExec& exec, const EawLevel& f);

// The CPU fast path is on by default; tests switch it off to compare with the generic functor.
bool& eawCpuFastPath();
// The fast path's AVX-512 row loops: on where the CPU has AVX-512 (F/VL/BW/DQ); tests switch it
// off to run the AVX2 loops too. Setting it on a CPU without AVX-512 is not allowed.
bool& eawCpuAvx512();

}  // namespace atrous::filters

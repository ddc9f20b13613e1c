// SVGF stage 5: one level of the variance-guided à-trous wavelet filter (docs/algorithms-svgf.md),
// as an edge-stop policy of the shared à-trous level (filters/atrous_level.h).
// 5x5 B3 kernel at step 2^i; per tap q
//   w = h(q) exp(-|l_p - l_q| / (σ_l sqrt(g3x3(var)_p) + ε) - |z_p - z_q| / (σ_z |∇z_p·(p - q)| + ε))
//       * max(0, n_p·n_q)^σ_n
// The illumination is the normalised weighted mean; the variance is propagated with squared
// weights, var' = Σ w² var_q / (Σ w)², so the next level's luminance stop tightens as noise drops.
#pragma once
#include "filters/atrous_level.h"
#include "filters/svgf_common.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::svgf {

// Per-tap math of the à-trous level, shared by the functor (both backends) and the CPU row engine
// so that they compute the same thing; what the row loops call is branch-free (selectF) so that
// they vectorise. Multiply-adds are explicit fmaf here and below, so every backend rounds the
// same way (see dotFma in svgf_common.h).

// A tap whose geometry log-weight is below this is dropped (weight < 4e-18 of the centre's).
constexpr float kAtrousMinLogWeight = -40.0f;

// 1/(σ_l sqrt(g3x3(var)_p) + ε) of the luminance stop. ε keeps the stop finite where the variance
// is exactly 0 (then only equal luminance passes).
ATROUS_FORCE_INLINE ATROUS_INLINE float atrousLumStopRecip(float sigmaL, float prefilteredVar) {
    return 1.0f / fmaf(sigmaL, sqrtf(selectF(prefilteredVar > 0.0f, prefilteredVar, 0.0f)), 1e-10f);
}

// Depth and normal stops of tap q at pixel offset (dx, dy), as one log-weight. The functor (one
// pixel at a time, CPU reference and GPU) uses the scalar stops, which compute only the case that
// applies; the CPU row loops use the Sel version: the same value, bit for bit, without branches.
ATROUS_INLINE float atrousGeometryLogWeight(float zp, float zq, float gx, float gy, Vec3 np, Vec3 nq, float dx,
                                            float dy, float sigmaZ, float sigmaN) {
    return depthLogWeight(zp, zq, gx, gy, dx, dy, sigmaZ) + normalLogWeight(np, nq, sigmaN);
}

ATROUS_FORCE_INLINE ATROUS_INLINE float atrousGeometryLogWeightSel(float zp, float zq, float gx, float gy, float npx,
                                                                   float npy, float npz, float nqx, float nqy,
                                                                   float nqz, float dx, float dy, float sigmaZ,
                                                                   float sigmaN) {
    return depthLogWeightSel(zp, zq, gx, gy, dx, dy, sigmaZ) +
           normalLogWeightSel(Vec3(npx, npy, npz), Vec3(nqx, nqy, nqz), sigmaN);
}

// w of tap q: h(q) exp(lwGeo - |l_p - l_q| / (σ_l sqrt(g3x3(var)_p) + ε)), hxy = h(q); 0 where q
// is empty (history length 0) or across an edge (lwGeo < kAtrousMinLogWeight). lwGeo = 0 for the
// centre tap.
ATROUS_FORCE_INLINE ATROUS_INLINE float atrousTapWeight(float hxy, float lwGeo, float lp, float lq, float invLumDenom,
                                                        float lenq) {
    const float lw = fmaf(-fabsf(lp - lq), invLumDenom, lwGeo);
    const float wq = hxy * fastExp(lw);
    return selectF(!(lenq <= 0.0f) & !(lwGeo < kAtrousMinLogWeight), wq, 0.0f);
}

// g3x3: 3x3 Gaussian ([1,2,1]/4 separable) of the variance at (x, y), renormalised at the border.
// It smooths the noisy variance estimate before it steers the luminance stop.
ATROUS_INLINE float prefilteredVariance(const ImageView& variance, int x, int y) {
    float sum = 0.0f, sumK = 0.0f;
    for (int j = -1; j <= 1; ++j) {
        int qy = y + j;
        if (qy < 0 || qy >= variance.height) continue;
        for (int i = -1; i <= 1; ++i) {
            int qx = x + i;
            if (qx < 0 || qx >= variance.width) continue;
            float k = (i == 0 ? 0.5f : 0.25f) * (j == 0 ? 0.5f : 0.25f);
            sum = fmaf(k, variance(qx, qy, 0), sum);
            sumK += k;
        }
    }
    return sum / sumK;
}

// The luminance stop's 1/(σ_l sqrt(g3x3(var)) + ε) per pixel, computed once per level before the
// taps (they read it at the centre pixel).
struct AtrousLumStop {
    float sigmaL = 4.0f;
    ImageView variance, out;  // 1 channel each
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        out(x, y, 0) = atrousLumStopRecip(sigmaL, prefilteredVariance(variance, x, y));
    }
};

// Buffers and parameters of one level.
struct Atrous {
    float sigmaL = 4.0f, sigmaN = 128.0f, sigmaZ = 1.0f;
    int step = 1;  // 2^level

    ImageView illum, variance;           // in: 3 + 1 channels
    ImageView length;                    // accumulated history length; 0 = pixel has no information
    ImageView depth, normal, depthGrad;  // sanitised G-buffer
    ImageView outIllum, outVariance;     // out: 3 + 1 channels
    ImageView lumStop;                   // scratch: runSvgfAtrous writes AtrousLumStop here
                                         // (allocated by it when invalid)
};

// The SVGF edge-stop policy of the à-trous level (filters/atrous_level.h): per tap q
//   w = h(q) exp(-|l_p - l_q| / (σ_l sqrt(g3x3(var)_p) + ε) + depth and normal log-weights);
// the variance is propagated with squared weights. Empty pixels (history length 0) and taps
// across an edge (geometry log-weight below kAtrousMinLogWeight) get weight 0; where no tap has
// any weight the input is kept. tap is branch-free (selects) for the CPU row engine; tapScalar,
// which the functor runs (the GPU), skips the loads of dropped taps and gives the same sums: a
// weight-0 tap adds exactly nothing as long as its illumination and variance are finite, which
// the pipeline guarantees (Demodulate replaces non-finite colour and clamps to ±kMaxIllum, every
// later stage takes weighted means of those values).
struct SvgfStop {
    Atrous f;

    static constexpr int kSums = 5;  // Σw, Σw l (3), Σw² var
    static constexpr bool kCentreTap = true;  // the centre's geometry log-weight is 0 by definition
    static constexpr bool kRowPartialSums = false;
    static constexpr bool kScalarTaps = true;

    struct Row {
        const float *r, *g, *b, *v, *len, *z, *nx, *ny, *nz, *gx, *gy, *il;
        float *oR, *oG, *oB, *oV;
    };
    struct Centre {
        float lp, zp, gx, gy, il, npx, npy, npz;
    };
    struct TapRow {
        float dy;  // the tap row's pixel offset qy·step
    };

    ATROUS_HOST_DEVICE int width() const { return f.illum.width; }
    ATROUS_HOST_DEVICE int height() const { return f.illum.height; }
    ATROUS_HOST_DEVICE int step() const { return f.step; }

    ATROUS_HOST_DEVICE Row row(int y) const {
        const size_t o = size_t(y) * size_t(f.illum.width);
        Row R;
        R.r = f.illum.channel(0) + o, R.g = f.illum.channel(1) + o, R.b = f.illum.channel(2) + o;
        R.v = f.variance.channel(0) + o, R.len = f.length.channel(0) + o, R.z = f.depth.channel(0) + o;
        R.nx = f.normal.channel(0) + o, R.ny = f.normal.channel(1) + o, R.nz = f.normal.channel(2) + o;
        R.gx = f.depthGrad.channel(0) + o, R.gy = f.depthGrad.channel(1) + o, R.il = f.lumStop.channel(0) + o;
        R.oR = f.outIllum.channel(0) + o, R.oG = f.outIllum.channel(1) + o, R.oB = f.outIllum.channel(2) + o;
        R.oV = f.outVariance.channel(0) + o;
        return R;
    }
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE Centre centre(const Row& R, int x) const {
        Centre c;
        c.lp = filters::lum(R.r[x], R.g[x], R.b[x]);
        c.zp = R.z[x], c.gx = R.gx[x], c.gy = R.gy[x], c.il = R.il[x];
        c.npx = R.nx[x], c.npy = R.ny[x], c.npz = R.nz[x];
        return c;
    }
    ATROUS_HOST_DEVICE TapRow tapRow(int qy) const { return TapRow{float(qy * f.step)}; }

    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE static void add(filters::AtrousSums<kSums>& a, float wq, float qr, float qg,
                                                           float qb, float vq) {
        a.s[1] = fmaf(wq, qr, a.s[1]);
        a.s[2] = fmaf(wq, qg, a.s[2]);
        a.s[3] = fmaf(wq, qb, a.s[3]);
        a.s[4] = fmaf(wq * wq, vq, a.s[4]);
        a.s[0] += wq;
    }
    template <int QX, bool kCentre>
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void tap(const Row& R, const Centre& c, filters::AtrousSums<kSums>& a,
                                                    ptrdiff_t q, float hxy, const TapRow& T) const {
        const float qr = R.r[q], qg = R.g[q], qb = R.b[q];
        const float lwGeo = kCentre ? 0.0f
                                    : atrousGeometryLogWeightSel(c.zp, R.z[q], c.gx, c.gy, c.npx, c.npy, c.npz,
                                                                 R.nx[q], R.ny[q], R.nz[q], float(QX * f.step), T.dy,
                                                                 f.sigmaZ, f.sigmaN);
        const float wq = atrousTapWeight(hxy, lwGeo, c.lp, filters::lum(qr, qg, qb), c.il, R.len[q]);
        add(a, wq, qr, qg, qb, R.v[q]);
    }
    template <int QX, bool kCentre>
    ATROUS_HOST_DEVICE void tapScalar(const Row& R, const Centre& c, filters::AtrousSums<kSums>& a, ptrdiff_t q,
                                      float hxy, const TapRow& T) const {
        const float lenq = R.len[q];
        if (lenq <= 0.0f) return;  // empty pixel: contributes nothing
        float lwGeo = 0.0f;
        if (!kCentre) {
            // Geometry first: across an edge the tap is dropped without touching its colour.
            lwGeo = atrousGeometryLogWeight(c.zp, R.z[q], c.gx, c.gy, Vec3(c.npx, c.npy, c.npz),
                                            Vec3(R.nx[q], R.ny[q], R.nz[q]), float(QX * f.step), T.dy, f.sigmaZ,
                                            f.sigmaN);
            if (lwGeo < kAtrousMinLogWeight) return;
        }
        const float qr = R.r[q], qg = R.g[q], qb = R.b[q];
        add(a, atrousTapWeight(hxy, lwGeo, c.lp, filters::lum(qr, qg, qb), c.il, lenq), qr, qg, qb, R.v[q]);
    }

    // Normalisation, or the input where nothing with information was in reach (Σw = 0).
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void finish(const Row& R, int x, int, const filters::AtrousSums<kSums>& a) const {
        const float sw = a.s[0];
        const bool keep = !(sw <= 0.0f);
        const float inv = 1.0f / sw;  // Inf where sw = 0: that pixel takes the input instead
        R.oR[x] = selectF(keep, a.s[1] * inv, R.r[x]);
        R.oG[x] = selectF(keep, a.s[2] * inv, R.g[x]);
        R.oB[x] = selectF(keep, a.s[3] * inv, R.b[x]);
        R.oV[x] = selectF(keep, a.s[4] * inv * inv, R.v[x]);
    }
};

// Runs one level on `exec`: the luminance stop plane, then the functor (CudaExec). The CpuExec
// overload (src/cpu/svgf_atrous_cpu.cpp) runs both through vectorised row loops (the row engine,
// src/cpu/atrous_rows.h).
template <class Exec>
void runSvgfAtrous(const Exec& exec, const Atrous& level) {
    Image scratch;
    Atrous f = level;
    f.lumStop = filters::levelPlane(exec, f.lumStop, f.illum.width, f.illum.height, scratch);
    filters::runAtrousLevelFunctor(exec, AtrousLumStop{f.sigmaL, f.variance, f.lumStop}, SvgfStop{f});
    if (!scratch.empty()) exec.synchronize();  // before `scratch` dies
}
void runSvgfAtrous(const CpuExec& exec, const Atrous& f);

// Old names of the row engine's switches (filters/atrous_level.h), shared with EAW and SURE.
inline bool& svgfCpuFastPath() { return filters::atrousCpuFastPath(); }
inline bool& svgfCpuAvx512() { return filters::atrousCpuAvx512(); }

}  // namespace atrous::svgf

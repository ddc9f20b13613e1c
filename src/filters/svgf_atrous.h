// SVGF stage 5: one level of the variance-guided à-trous wavelet filter (docs/svgf.md, "Stages").
// 5x5 B3 kernel at step 2^i; per tap q
//   w = h(q) exp(-|l_p - l_q| / (σ_l sqrt(g3x3(var)_p) + ε) - |z_p - z_q| / (σ_z |∇z_p·(p - q)| + ε))
//       * max(0, n_p·n_q)^σ_n
// The illumination is the normalised weighted mean; the variance is propagated with squared
// weights, var' = Σ w² var_q / (Σ w)², so the next level's luminance stop tightens as noise drops.
#pragma once
#include "filters/svgf_common.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::svgf {

// Per-tap math of the à-trous level, shared by Atrous::operator() (both backends) and the CPU
// fast path (src/cpu/svgf_atrous_cpu.cpp) so that they compute the same thing; what the row loops
// call is branch-free (selectF) so that they vectorise.

// A tap whose geometry log-weight is below this is dropped (weight < 4e-18 of the centre's).
constexpr float kAtrousMinLogWeight = -40.0f;

// 1/(σ_l sqrt(g3x3(var)_p) + ε) of the luminance stop. ε keeps the stop finite where the variance
// is exactly 0 (then only equal luminance passes).
ATROUS_FORCE_INLINE ATROUS_INLINE float atrousLumStopRecip(float sigmaL, float prefilteredVar) {
    return 1.0f / fmaf(sigmaL, sqrtf(selectF(prefilteredVar > 0.0f, prefilteredVar, 0.0f)), 1e-10f);
}

// Luminance of an illumination value (plain floats: the CPU row loops must not construct a Vec3
// themselves, see svgf_atrous_cpu.cpp). Multiply-adds are explicit fmaf here and below, so every
// backend rounds the same way (see dotFma in svgf_common.h).
ATROUS_FORCE_INLINE ATROUS_INLINE float atrousLuminance(float r, float g, float b) {
    return fmaf(0.0722f, b, fmaf(0.7152f, g, 0.2126f * r));  // Rec. 709, as luminance()
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

struct Atrous {
    float sigmaL = 4.0f, sigmaN = 128.0f, sigmaZ = 1.0f;
    int step = 1;  // 2^level

    ImageView illum, variance;           // in: 3 + 1 channels
    ImageView length;                    // accumulated history length; 0 = pixel has no information
    ImageView depth, normal, depthGrad;  // sanitised G-buffer
    ImageView outIllum, outVariance;     // out: 3 + 1 channels

    // g3x3: 3x3 Gaussian ([1,2,1]/4 separable) of the variance, renormalised at the border. It
    // smooths the noisy variance estimate before it steers the luminance stop.
    ATROUS_HOST_DEVICE float prefilteredVariance(int x, int y) const {
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

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = illum.width, h = illum.height;
        Vec3 cp = readVec3(illum, x, y);
        float lp = atrousLuminance(cp.x, cp.y, cp.z);
        float zp = depth(x, y, 0);
        Vec3 np = readVec3(normal, x, y);
        float gx = depthGrad(x, y, 0), gy = depthGrad(x, y, 1);
        float invLumDenom = atrousLumStopRecip(sigmaL, prefilteredVariance(x, y));

        Vec3 sumC(0.0f);
        float sumV = 0.0f, sumW = 0.0f;
        for (int j = -2; j <= 2; ++j) {
            int qy = y + j * step;
            if (qy < 0 || qy >= h) continue;
            float hy = b3Tap(j);
            for (int i = -2; i <= 2; ++i) {
                int qx = x + i * step;
                if (qx < 0 || qx >= w) continue;
                // Dropped taps (empty pixel, across an edge) skip their loads here; the CPU fast
                // path gives them weight 0 instead, which adds exactly nothing.
                const float lenq = length(qx, qy, 0);
                if (lenq <= 0.0f) continue;  // empty pixel: contributes nothing
                float lwGeo = 0.0f;
                if (i != 0 || j != 0) {
                    // Geometry first: across an edge the tap is dropped without touching its colour.
                    lwGeo = atrousGeometryLogWeight(zp, depth(qx, qy, 0), gx, gy, np, readVec3(normal, qx, qy),
                                                    float(i * step), float(j * step), sigmaZ, sigmaN);
                    if (lwGeo < kAtrousMinLogWeight) continue;
                }
                Vec3 cq = readVec3(illum, qx, qy);
                float wq =
                    atrousTapWeight(hy * b3Tap(i), lwGeo, lp, atrousLuminance(cq.x, cq.y, cq.z), invLumDenom, lenq);
                sumC = Vec3(fmaf(wq, cq.x, sumC.x), fmaf(wq, cq.y, sumC.y), fmaf(wq, cq.z, sumC.z));
                sumV = fmaf(wq * wq, variance(qx, qy, 0), sumV);
                sumW += wq;
            }
        }
        if (sumW <= 0.0f) {  // nothing with information in reach: keep the input
            writeVec3(outIllum, x, y, cp);
            outVariance(x, y, 0) = variance(x, y, 0);
            return;
        }
        float inv = 1.0f / sumW;
        writeVec3(outIllum, x, y, sumC * inv);
        outVariance(x, y, 0) = sumV * inv * inv;
    }
};

// Runs one level on `exec`. The generic version launches the functor (CudaExec); the CpuExec
// overload (src/cpu/svgf_atrous_cpu.cpp) runs vectorised row loops with the same math.
template <class Exec>
void runSvgfAtrous(const Exec& exec, const Atrous& f) {
    exec.forEachPixel(f.illum.width, f.illum.height, f);
}
void runSvgfAtrous(const CpuExec& exec, const Atrous& f);

// The CPU fast path is on by default; tests switch it off to compare with the generic functor.
bool& svgfCpuFastPath();
// Its AVX-512 row loops: on where the CPU has AVX-512 (F/VL/BW/DQ); tests switch it off to run
// the AVX2 loops too. Setting it on a CPU without AVX-512 is not allowed.
bool& svgfCpuAvx512();

}  // namespace atrous::svgf

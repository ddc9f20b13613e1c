// SVGF stage 5: one level of the variance-guided à-trous wavelet filter (ALGORITHMS.md §4.5).
// 5x5 B3 kernel at step 2^i; per tap q
//   w = h(q) exp(-|l_p - l_q| / (σ_l sqrt(g3x3(var)_p) + ε) - |z_p - z_q| / (σ_z |∇z_p·(p - q)| + ε))
//       * max(0, n_p·n_q)^σ_n
// The illumination is the normalised weighted mean; the variance is propagated with squared
// weights, var' = Σ w² var_q / (Σ w)², so the next level's luminance stop tightens as noise drops.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

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
                sum += k * variance(qx, qy, 0);
                sumK += k;
            }
        }
        return sum / sumK;
    }

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = illum.width, h = illum.height;
        Vec3 cp = readVec3(illum, x, y);
        float lp = luminance(cp);
        float zp = depth(x, y, 0);
        Vec3 np = readVec3(normal, x, y);
        float gx = depthGrad(x, y, 0), gy = depthGrad(x, y, 1);
        // ε keeps the stop finite where the variance is exactly 0 (then only equal luminance passes).
        float invLumDenom = 1.0f / (sigmaL * sqrtf(maxf(prefilteredVariance(x, y), 0.0f)) + 1e-10f);

        Vec3 sumC(0.0f);
        float sumV = 0.0f, sumW = 0.0f;
        for (int j = -2; j <= 2; ++j) {
            int qy = y + j * step;
            if (qy < 0 || qy >= h) continue;
            float hy = b3Tap(j);
            for (int i = -2; i <= 2; ++i) {
                int qx = x + i * step;
                if (qx < 0 || qx >= w) continue;
                if (length(qx, qy, 0) <= 0.0f) continue;  // empty pixel: contributes nothing
                float lw = 0.0f;
                if (i != 0 || j != 0) {
                    float dx = float(i * step), dy = float(j * step);
                    // Geometry first: across an edge the tap is dropped without touching its colour.
                    lw = depthLogWeight(zp, depth(qx, qy, 0), gx, gy, dx, dy, sigmaZ) +
                         normalLogWeight(np, readVec3(normal, qx, qy), sigmaN);
                    if (lw < -40.0f) continue;  // weight < 4e-18 of the centre's
                }
                Vec3 cq = readVec3(illum, qx, qy);
                lw -= fabsf(lp - luminance(cq)) * invLumDenom;
                float wq = hy * b3Tap(i) * fastExp(lw);
                sumC += wq * cq;
                sumV += wq * wq * variance(qx, qy, 0);
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

}  // namespace atrous::svgf

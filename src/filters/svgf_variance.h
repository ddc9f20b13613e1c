// SVGF stage 4: variance estimate (docs/svgf.md, "Stages"). Where the history holds at least
// `spatialFrames` frames, the temporal moments give var = μ2 - μ1²; younger pixels (just
// disoccluded, or the first frames) use a 7x7 spatial bilateral estimate of the same moments,
// weighted by depth and normal similarity only (a luminance weight would exclude exactly the
// spread we are measuring and bias the estimate low).
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

struct Variance {
    float spatialFrames = 4.0f;
    float sigmaN = 128.0f;
    float sigmaZ = 1.0f;
    int radius = 3;  // 7x7

    ImageView moments, length;               // accumulated, 2 + 1 channels
    ImageView depth, normal, depthGrad;      // sanitised G-buffer
    ImageView variance;                      // out: 1 channel

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float n = length(x, y, 0);
        if (n >= spatialFrames) {
            float m0 = moments(x, y, 0);
            variance(x, y, 0) = maxf(0.0f, moments(x, y, 1) - m0 * m0);
            return;
        }
        float zp = depth(x, y, 0);
        Vec3 np = readVec3(normal, x, y);
        float gx = depthGrad(x, y, 0), gy = depthGrad(x, y, 1);
        float sumW = 0.0f, s0 = 0.0f, s1 = 0.0f;
        for (int j = -radius; j <= radius; ++j) {
            int qy = y + j;
            if (qy < 0 || qy >= depth.height) continue;
            for (int i = -radius; i <= radius; ++i) {
                int qx = x + i;
                if (qx < 0 || qx >= depth.width) continue;
                if (length(qx, qy, 0) <= 0.0f) continue;  // no information there
                float lw = depthLogWeight(zp, depth(qx, qy, 0), gx, gy, float(i), float(j), sigmaZ) +
                           normalLogWeight(np, readVec3(normal, qx, qy), sigmaN);
                float w = fastExp(lw);
                sumW += w;
                s0 += w * moments(qx, qy, 0);
                s1 += w * moments(qx, qy, 1);
            }
        }
        if (sumW <= 0.0f) {
            variance(x, y, 0) = 0.0f;
            return;
        }
        float m0 = s0 / sumW;
        variance(x, y, 0) = maxf(0.0f, s1 / sumW - m0 * m0);
    }
};

}  // namespace atrous::svgf

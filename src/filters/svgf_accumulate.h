// SVGF stage 3: temporal accumulation (ALGORITHMS.md §4.3). An exponential moving average whose
// weight starts as a plain running mean: α = max(alpha, 1/n) with n the (capped) history length,
// for the illumination and for the first and second moments of its luminance.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

struct Accumulate {
    float alpha = 0.2f;
    float momentsAlpha = 0.2f;
    float historyCap = 32.0f;

    ImageView illum, valid;                          // this frame (demodulated), 3 + 1 channels
    ImageView histIllum, histMoments, histLength;    // reprojected history, 3 + 2 + 1 channels
    ImageView outIllum, outMoments, outLength;       // out: 3 + 2 + 1 channels

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float n = histLength(x, y, 0);
        Vec3 h = readVec3(histIllum, x, y);
        float hm0 = histMoments(x, y, 0), hm1 = histMoments(x, y, 1);
        if (valid(x, y, 0) == 0.0f) {
            // No sample this frame: carry the history unchanged (length not incremented); with no
            // history either the pixel stays empty (length 0) and the spatial stages skip it.
            writeVec3(outIllum, x, y, h);
            outMoments(x, y, 0) = hm0;
            outMoments(x, y, 1) = hm1;
            outLength(x, y, 0) = n;
            return;
        }
        float len = minf(n + 1.0f, historyCap);
        float a = maxf(alpha, 1.0f / len);
        float am = maxf(momentsAlpha, 1.0f / len);
        Vec3 c = readVec3(illum, x, y);
        float l = luminance(c);
        writeVec3(outIllum, x, y, h + (c - h) * a);
        outMoments(x, y, 0) = hm0 + (l - hm0) * am;
        outMoments(x, y, 1) = hm1 + (l * l - hm1) * am;
        outLength(x, y, 0) = len;
    }
};

}  // namespace atrous::svgf

// SVGF stage 3: temporal accumulation (docs/svgf.md, "Stages"). An exponential moving average whose
// weight starts as a plain running mean: α = max(alpha, 1/n) with n the (capped) history length,
// for the illumination and for the first and second moments of its luminance.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

struct Accumulate {
    float alpha = 0.2f;
    float momentsAlpha = 0.2f;
    float historyCap = 32.0f;
    // History clipping (SvgfParams::historyClip): the reprojected illumination's luminance is
    // clipped into m ± γ s of this frame's 3x3 luminance samples (0 = off).
    float historyClip = 0.0f;

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
        if (historyClip > 0.0f && n > 0.0f) h = clipHistory(x, y, h);
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

    // The history scaled so that its luminance lies in [m - γ s, m + γ s] (m, s² the mean and
    // variance of the valid 3x3 current samples' luminance): a highlight that moved away, whose
    // reprojected history is far above everything this frame sees around the pixel, no longer
    // lingers for 1/alpha frames. Scaling keeps the history's chroma.
    ATROUS_HOST_DEVICE Vec3 clipHistory(int x, int y, Vec3 h) const {
        const int w = illum.width, hgt = illum.height;
        float sum = 0.0f, sum2 = 0.0f, cnt = 0.0f;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= w || yy >= hgt || valid(xx, yy, 0) == 0.0f) continue;
                const float l = luminance(readVec3(illum, xx, yy));
                sum += l;
                sum2 += l * l;
                cnt += 1.0f;
            }
        const float m = sum / cnt;  // cnt >= 1: the pixel itself is valid here
        const float sd = sqrtf(maxf(sum2 / cnt - m * m, 0.0f));
        const float lo = m - historyClip * sd, hi = m + historyClip * sd;
        const float lh = luminance(h);
        if (lh > hi && lh > 0.0f) return h * (maxf(hi, 0.0f) / lh);
        if (lh < lo && lh > 0.0f) return h * (lo / lh);
        return h;
    }
};

}  // namespace atrous::svgf

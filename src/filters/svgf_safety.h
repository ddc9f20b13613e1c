// SVGF's per-frame safety net (SvgfParams::safetyNet; docs/svgf.md "Never worse than per frame"):
// the still default (auto) denoises the frame alone, and SVGF's output gives way to it where the
// two disagree by more than noise explains. The test is on luminance: per pixel the signed
// relative difference d = (L_svgf - L_still) / (min(|L_svgf|, |L_still|) + 0.02) over the 3x3
// neighbourhood, r = max(|mean d|, mean |d| / 2): the signed mean, in which zero-mean residual
// noise cancels while a ghost, a lagging or smeared light, a trail keeps its sign, catches those
// at tau; the unsigned one, at 2 tau, catches speckle of either sign (glass at 1 spp). The output is
//   lerp(svgf, still, clamp((r - tau) / tau, 0, 1))
// i.e. SVGF's up to tau, the still filter's from 2 tau on. The min() in the denominator makes a
// bright ghost on a dark surface and a dark hole in a light both large.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

struct SafetyDifference {
    ImageView svgf, still;  // 3 channels each
    ImageView rel;          // out: 1 channel, the signed relative luminance difference d
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float ls = filters::lum(svgf(x, y, 0), svgf(x, y, 1), svgf(x, y, 2));
        const float lp = filters::lum(still(x, y, 0), still(x, y, 1), still(x, y, 2));
        const float d = (ls - lp) / (fminf(fabsf(ls), fabsf(lp)) + 0.02f);
        rel(x, y, 0) = isFiniteF(d) ? d : 0.0f;
    }
};

struct SafetyBlend {
    float tau = 0.05f;
    ImageView svgf, still, rel;  // 3, 3, 1 channels
    ImageView out;               // out: 3 channels
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = rel.width, h = rel.height;
        float sum = 0.0f, sumAbs = 0.0f;
        for (int j = -1; j <= 1; ++j)
            for (int i = -1; i <= 1; ++i) {
                const float d = rel(clampi(x + i, 0, w - 1), clampi(y + j, 0, h - 1), 0);
                sum += d;
                sumAbs += fabsf(d);
            }
        const float r = fmaxf(fabsf(sum), 0.5f * sumAbs) * (1.0f / 9.0f);
        const float t = fminf(fmaxf((r - tau) / tau, 0.0f), 1.0f);
        for (int c = 0; c < 3; ++c) out(x, y, c) = svgf(x, y, c) + (still(x, y, c) - svgf(x, y, c)) * t;
    }
};

}  // namespace atrous::svgf

// SVGF: temporal accumulation of the emission buffer (issue 5). The remodulation adds emission
// back unfiltered (output = albedo·illumination + emission). At 1 spp a pixel on the edge of a
// visible light sees the light (radiance ~17) or the ceiling (0 emission) at random from frame to
// frame, so its emission flickers by the light's full radiance and dominates the whole image's
// temporal error. This stage averages it over time with the illumination's reprojection
// (p + motion(p); Catmull-Rom resampling), but with a consistency test suited to emission:
//   - no mesh-id / depth / normal test: on the edge the primary hit alternates between the light
//     and the ceiling, so such a test would reset the history every frame, exactly where it is
//     needed;
//   - instead a TAA-style neighbourhood clamp: the reprojected history is clamped per channel into
//     [min, max] of the current frame's 3x3 emission. Away from a light's edge the window is all
//     light or all non-light, the box collapses to the current value and stale history (a light
//     that moved away, a disocclusion) is rejected at once; on the edge the window spans both and
//     the history is kept, so the edge converges to its coverage-weighted mean.
// Blend: e_out = lerp(clamp(e_hist), e, α), α = max(alpha, 1/n, κ|m·ĝ|): n the capped history
// length (the colour's rule, docs/svgf.md, "Stages"); the last term raises α where the light's edge
// moves across pixels (m the motion, ĝ the direction of the history's emission gradient), since
// there the resampled history lags (a halo on the ceiling beside the light's edge without it,
// docs/decisions.md). alpha = 1 reproduces the raw emission.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

// Catmull-Rom cubic weights of the taps at -1, 0, 1, 2 for a position t in [0, 1) past tap 0
// (they sum to 1; t = 0 gives 0, 1, 0, 0).
ATROUS_INLINE void catmullRomWeights(float t, float w[4]) {
    w[0] = t * (-0.5f + t * (1.0f - 0.5f * t));
    w[1] = 1.0f + t * t * (-2.5f + 1.5f * t);
    w[2] = t * (0.5f + t * (2.0f - 1.5f * t));
    w[3] = t * t * (-0.5f + 0.5f * t);
}

struct AccumulateEmission {
    float alpha = 0.1f;         // minimum blend weight of the current frame, (0, 1]
    float motionAlpha = 0.0f;   // κ: α >= κ |motion across the edge| (pixels per frame), >= 0
    float historyCap = 32.0f;   // n saturates here
    bool havePrevious = false;  // false on the first frame after a reset

    ImageView emission;                 // this frame's raw emission (optional: missing -> 0), 3 channels
    ImageView motion;                   // sanitised motion (previous - current, pixels), 2 channels
    ImageView prevEmission, prevLength; // last frame's accumulated emission and history length, 3 + 1
    ImageView outEmission, outLength;   // out: 3 + 1 channels

    ATROUS_HOST_DEVICE void write(int x, int y, Vec3 e, float n) const {
        writeVec3(outEmission, x, y, e);
        outLength(x, y, 0) = n;
    }

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = outEmission.width, h = outEmission.height;
        Vec3 e = sanitizedEmission(emission, x, y);
        float mx = motion(x, y, 0), my = motion(x, y, 1);
        if (!havePrevious || !(fabsf(mx) < kMaxMotion) || !(fabsf(my) < kMaxMotion)) {
            write(x, y, e, 1.0f);
            return;
        }
        // History at p + motion (integer pixel centres, as Reproject), resampled with a 4x4
        // Catmull-Rom filter rather than bilinearly: a light's edge moving a fraction of a pixel
        // per frame would otherwise be blurred by every frame's bilinear resampling, and the
        // clamp below keeps that blur on the edge (a halo next to the light). Its negative lobes are removed by the same clamp. Taps beyond the image border
        // repeat the border; a position more than half a pixel outside the image is a reset.
        float px = float(x) + mx, py = float(y) + my;
        if (!(px >= -0.5f && py >= -0.5f && px <= float(w) - 0.5f && py <= float(h) - 0.5f)) {
            write(x, y, e, 1.0f);
            return;
        }
        float fx0 = floorf(px), fy0 = floorf(py);
        int x0 = int(fx0), y0 = int(fy0);
        // The history length only sets α: the bilinear mean of the inner 2x2 is enough.
        float fx = px - fx0, fy = py - fy0, n = 0.0f;
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i)
                n += (i ? fx : 1.0f - fx) * (j ? fy : 1.0f - fy) *
                     prevLength(clampi(x0 + i, 0, w - 1), clampi(y0 + j, 0, h - 1), 0);
        // Neighbourhood clamp: the box of this frame's 3x3 emission (edge pixels replicated).
        Vec3 lo = e, hi = e;
        for (int j = -1; j <= 1; ++j) {
            for (int i = -1; i <= 1; ++i) {
                Vec3 q = sanitizedEmission(emission, clampi(x + i, 0, w - 1), clampi(y + j, 0, h - 1));
                lo = minv(lo, q);
                hi = maxv(hi, q);
            }
        }
        // A uniform window (most pixels: no light in reach, or inside a light) collapses the box
        // to e, so the clamped history is e and so is the blend, exactly: skip the 16 history taps.
        if (lo.x == hi.x && lo.y == hi.y && lo.z == hi.z) {
            write(x, y, e, minf(n + 1.0f, historyCap));
            return;
        }
        float wx[4], wy[4];
        catmullRomWeights(px - fx0, wx);
        catmullRomWeights(py - fy0, wy);
        Vec3 hist(0.0f);
        for (int j = 0; j < 4; ++j) {
            int qy = clampi(y0 - 1 + j, 0, h - 1);
            for (int i = 0; i < 4; ++i) hist += (wx[i] * wy[j]) * readVec3(prevEmission, clampi(x0 - 1 + i, 0, w - 1), qy);
        }
        hist = minv(maxv(hist, lo), hi);
        float len = minf(n + 1.0f, historyCap);
        // Under motion the resampled history of a sub-pixel edge lags behind (no resampling
        // filter transports a one-pixel coverage ramp exactly), but only the motion across the
        // edge changes a pixel's coverage: α >= κ |m·ĝ|, ĝ the direction of the history's
        // emission gradient (central differences at the reprojected pixel; smooth, unlike this
        // frame's 1-spp emission). Along an edge, or where the history is flat, this is 0.
        float a = maxf(alpha, 1.0f / len);
        if (motionAlpha > 0.0f) {
            int cx = clampi(int(floorf(px + 0.5f)), 0, w - 1), cy = clampi(int(floorf(py + 0.5f)), 0, h - 1);
            float gx = luminance(readVec3(prevEmission, mini(cx + 1, w - 1), cy)) -
                       luminance(readVec3(prevEmission, maxi(cx - 1, 0), cy));
            float gy = luminance(readVec3(prevEmission, cx, mini(cy + 1, h - 1))) -
                       luminance(readVec3(prevEmission, cx, maxi(cy - 1, 0)));
            float g2 = gx * gx + gy * gy;
            if (g2 > 0.0f) a = maxf(a, minf(1.0f, motionAlpha * fabsf(mx * gx + my * gy) / sqrtf(g2)));
        }
        write(x, y, hist + (e - hist) * a, len);
    }
};

}  // namespace atrous::svgf

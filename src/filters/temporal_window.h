// The offline sequence denoiser's per-pixel stages (include/atrous/temporal.h, docs/temporal.md):
// local colour statistics per frame and one hop of a neighbour's track toward or away from the
// centre frame, gathering what the hop reaches. Host/device: the CPU driver is
// src/filters/temporal.cpp. The G-buffer of every frame is first sanitised by SVGF's functors
// (svgf_gbuffer.h), so depth, normal, ids and motion follow SVGF's rules here too.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::temporal {

using svgf::hasNormal;
using svgf::isBackground;
using svgf::kMaxMotion;

// atrous::kTemporalStaticMotion (include/atrous/temporal.h; temporal.cpp checks they agree): a hop
// under this many pixels keeps a track static.
constexpr float kStaticMotion = 0.05f;
using svgf::readVec3;
using svgf::writeVec3;

// A frame's sanitised G-buffer (svgf::SanitizeGbuffer, svgf::DepthGradient) and raw buffers.
struct FrameViews {
    ImageView depth, normal, ids, motion, grad;           // sanitised: 1, 3, 1, 2, 2 channels
    ImageView color, albedo, normalRaw, emission, variance;  // as given (albedo ... optional)
    ImageView stats;  // 3 channels: the 3x3 mean of the demodulated luminance, that mean's variance, the luminance
    ImageView still;  // 1 channel: 1 where nothing in the pixel's 3x3 neighbourhood moves (StillAround), else 0
};

// Channel 2 of `stats`: lum((c - e) / a') per pixel (SVGF's albedo rule; NaN where not finite),
// read by LocalStats.
struct DemodulatedLum {
    FrameViews f;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float a[3];
        svgf::albedoRule().at(f.albedo, x, y, a);
        const Vec3 e = svgf::sanitizedEmission(f.emission, x, y);
        const float l = filters::lum((f.color(x, y, 0) - e.x) / a[0], (f.color(x, y, 1) - e.y) / a[1],
                                     (f.color(x, y, 2) - e.z) / a[2]);
        f.stats(x, y, 2) = isFiniteF(l) ? l : NAN;
    }
};

// Channels 0 and 1 of `stats`: the 3x3 mean of channel 2 and the variance of that mean (the 3x3
// sample variance over the number of samples), non-finite samples left out (what else was tried:
// docs/decisions.md, "Sequences").
struct LocalStats {
    FrameViews f;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float s = 0.0f, s2 = 0.0f, n = 0.0f;
        for (int j = -1; j <= 1; ++j) {
            for (int i = -1; i <= 1; ++i) {
                const int qx = x + i, qy = y + j;
                if (qx < 0 || qy < 0 || qx >= f.color.width || qy >= f.color.height) continue;
                const float l = f.stats(qx, qy, 2);
                if (!isFiniteF(l)) continue;
                s += l, s2 += l * l, n += 1.0f;
            }
        }
        const float m = n > 0.0f ? s / n : 0.0f;
        f.stats(x, y, 0) = m;
        f.stats(x, y, 1) = n > 1.0f ? fmaxf(s2 / n - m * m, 0.0f) / (n - 1.0f) : 0.0f;
    }
};

// FrameViews::still: 1 where nothing in the 3x3 neighbourhood of the pixel moves. A pixel next to
// a moving object's edge is not static even where its own (one sample's) motion is zero: the
// object covers part of it in one frame and not in the next.
struct StillAround {
    FrameViews f;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float s = 1.0f;
        for (int j = -1; j <= 1; ++j)
            for (int i = -1; i <= 1; ++i) {
                const int nx = x + i, ny = y + j;
                if (nx < 0 || ny < 0 || nx >= f.motion.width || ny >= f.motion.height) continue;
                if (!(fabsf(f.motion(nx, ny, 0)) < kStaticMotion && fabsf(f.motion(nx, ny, 1)) < kStaticMotion))
                    s = 0.0f;
            }
        f.still(x, y, 0) = s;
    }
};

// Every track starts at its own pixel, alive.
struct StartTracks {
    ImageView track, alive;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        track(x, y, 0) = float(x), track(x, y, 1) = float(y), alive(x, y, 0) = 1.0f;
    }
};

// One hop: the track of centre pixel p is at `track` in frame `from` (the centre, or the last
// frame it reached); this finds it in frame `to` (the next frame away from the centre), tests
// the taps, and adds `to`'s colour, albedo, normal, emission and variance there to the sums.
// backward: `to` is the previous frame, reached through `from`'s motion (previous - current).
// Forward: `to` is the next frame, whose own motion points back to `from`; the position q with
// q + motion_to(q) = track is found by a fixed-point iteration from the constant-velocity guess.
// A track that fails (leaves the image, a disocclusion, a colour change) stops: the frames
// farther out are not reached through it either.
struct Hop {
    FrameViews from, to, centre;
    bool backward = true;
    float depthTolerance = 2.0f, normalCos = 0.9f, colorSigmas = 3.0f;
    float weight = 1.0f;  // this frame's weight in the average (the centre's is 1); 0: the track stops
    // The weight of a track that has not moved yet (TemporalParams::staticRadius); `alive` is 1
    // for such a track and 0.5 once it has moved.
    float staticWeight = 1.0f;
    ImageView track;  // 2 channels: the position in `from`, then in `to`
    ImageView alive;  // 1 channel: 1 while the track holds
    ImageView sumColor, sumAlbedo, sumNormal, sumEmission, sumVariance, count;

    ATROUS_HOST_DEVICE bool inside(int x, int y) const {
        return x >= 0 && y >= 0 && x < to.depth.width && y < to.depth.height;
    }

    // SVGF's reprojection test (svgf_reproject.h) between `from` at (fx, fy) (its anchor: read once
    // for the five taps of a hop) and `to` at (qx, qy).
    struct Anchor {
        float z, tol, id;
        Vec3 n;
        bool background, hasN;
    };
    ATROUS_HOST_DEVICE Anchor anchor(int fx, int fy) const {
        Anchor a;
        a.z = from.depth(fx, fy, 0);
        a.id = from.ids(fx, fy, 0);
        a.background = isBackground(a.z);
        a.tol = depthTolerance * (fabsf(from.grad(fx, fy, 0)) + fabsf(from.grad(fx, fy, 1)) + 0.01f * fabsf(a.z));
        a.n = readVec3(from.normal, fx, fy);
        a.hasN = hasNormal(a.n);
        return a;
    }
    ATROUS_HOST_DEVICE bool consistent(const Anchor& a, int qx, int qy) const {
        if (!inside(qx, qy)) return false;
        if (to.ids(qx, qy, 0) != a.id) return false;
        const float zq = to.depth(qx, qy, 0);
        const bool bq = isBackground(zq);
        if (a.background || bq) return a.background && bq;
        if (!(fabsf(zq - a.z) <= a.tol)) return false;
        const Vec3 nq = readVec3(to.normal, qx, qy);
        if (a.hasN != hasNormal(nq)) return false;
        return !a.hasN || dot(a.n, nq) >= normalCos;
    }

    ATROUS_HOST_DEVICE static int nearest(float v) { return int(floorf(v + 0.5f)); }

    // A track that has not moved, in a hop through a still camera's frames (stillHop): the
    // reached pixel is the same footprint, and its sample may have hit any surface the footprint
    // covers. A renderer's depth, normal and id are one sample's (at 1 spp, the pixel's only one),
    // so a pixel on an edge (a light in a ceiling, a silhouette) shows one side in one frame and
    // the other in the next, and the test against the pixel's own G-buffer would keep only the
    // frames that agree with the centre's sample. Here a tap is also kept where it passes the test
    // against a pixel of the 3x3 neighbourhood in `from`: a surface next to the pixel. Such a
    // track is not `moved`, so nothing in that neighbourhood moves (from.still): a moving
    // object's edge is never such a surface.
    bool stillHop = false;
    ATROUS_HOST_DEVICE bool consistentNear(const Anchor& a, int fx, int fy, int qx, int qy, bool moved) const {
        if (consistent(a, qx, qy)) return true;
        if (moved || !stillHop) return false;
        for (int j = -1; j <= 1; ++j)
            for (int i = -1; i <= 1; ++i) {
                const int nx = fx + i, ny = fy + j;
                if ((!i && !j) || nx < 0 || ny < 0 || nx >= from.depth.width || ny >= from.depth.height) continue;
                if (consistent(anchor(nx, ny), qx, qy)) return true;
            }
        return false;
    }

    ATROUS_HOST_DEVICE void stop(int x, int y) const { alive(x, y, 0) = 0.0f; }

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        if (alive(x, y, 0) == 0.0f) return;
        bool moved = alive(x, y, 0) < 1.0f;
        const float tx = track(x, y, 0), ty = track(x, y, 1);
        const int fx = nearest(tx), fy = nearest(ty);
        if (fx < 0 || fy < 0 || fx >= from.depth.width || fy >= from.depth.height) return stop(x, y);
        float px, py;
        if (backward) {
            const float mx = from.motion(fx, fy, 0), my = from.motion(fx, fy, 1);
            if (!(fabsf(mx) < kMaxMotion) || !(fabsf(my) < kMaxMotion)) return stop(x, y);
            px = tx + mx, py = ty + my;
        } else {
            // Constant velocity: the step to the next frame is minus the step to the previous one.
            float mx = from.motion(fx, fy, 0), my = from.motion(fx, fy, 1);
            if (!(fabsf(mx) < kMaxMotion) || !(fabsf(my) < kMaxMotion)) mx = my = 0.0f;
            px = tx - mx, py = ty - my;
            for (int it = 0; it < 4; ++it) {
                const int qx = nearest(px), qy = nearest(py);
                if (!inside(qx, qy)) return stop(x, y);
                const float ux = to.motion(qx, qy, 0), uy = to.motion(qx, qy, 1);
                if (!(fabsf(ux) < kMaxMotion) || !(fabsf(uy) < kMaxMotion)) return stop(x, y);
                px = tx - ux, py = ty - uy;
            }
            const int qx = nearest(px), qy = nearest(py);
            if (!inside(qx, qy)) return stop(x, y);
            // The found pixel must map back onto the track (a fold of the motion field does not).
            const float rx = float(qx) + to.motion(qx, qy, 0) - tx, ry = float(qy) + to.motion(qx, qy, 1) - ty;
            if (!(fabsf(rx) <= 1.0f && fabsf(ry) <= 1.0f)) return stop(x, y);
        }
        const int qx = nearest(px), qy = nearest(py);
        // The motion the hop read (from's at the track, to's at the reached pixel) is in these
        // masks, with the pixels around it.
        moved = moved || !stillHop || from.still(fx, fy, 0) == 0.0f || (inside(qx, qy) && to.still(qx, qy, 0) == 0.0f);
        const Anchor an = anchor(fx, fy);
        if (!consistentNear(an, fx, fy, qx, qy, moved)) return stop(x, y);
        if (colorSigmas > 0.0f) {
            // Two 3x3 means of independent noise: their difference has the sum of their variances.
            const float d = to.stats(qx, qy, 0) - centre.stats(x, y, 0);
            const float se2 = to.stats(qx, qy, 1) + centre.stats(x, y, 1);
            if (!(d * d <= colorSigmas * colorSigmas * se2 + 1e-12f)) return stop(x, y);
        }
        // Bilinear taps, each kept only where it passes the test against `from` too.
        const float fx0 = floorf(px), fy0 = floorf(py);
        const int x0 = int(fx0), y0 = int(fy0);
        const float ax = px - fx0, ay = py - fy0;
        float w = 0.0f, c[3] = {0, 0, 0}, a[3] = {0, 0, 0}, n[3] = {0, 0, 0}, e[3] = {0, 0, 0}, v[3] = {0, 0, 0};
        const int vc = to.variance.valid() ? (to.variance.channels < 3 ? to.variance.channels : 3) : 0;
        for (int j = 0; j < 2; ++j) {
            for (int i = 0; i < 2; ++i) {
                const float wt = (i ? ax : 1.0f - ax) * (j ? ay : 1.0f - ay);
                const int sx = x0 + i, sy = y0 + j;
                if (wt <= 0.0f || !consistentNear(an, fx, fy, sx, sy, moved)) continue;
                w += wt;
                for (int k = 0; k < 3; ++k) {
                    c[k] += wt * to.color(sx, sy, k);
                    if (to.albedo.valid()) a[k] += wt * to.albedo(sx, sy, k);
                    if (to.normalRaw.valid()) n[k] += wt * to.normalRaw(sx, sy, k);
                    if (to.emission.valid()) e[k] += wt * to.emission(sx, sy, k);
                }
                for (int k = 0; k < vc; ++k) v[k] += wt * to.variance(sx, sy, k);
            }
        }
        if (w < 0.01f) return stop(x, y);
        const float iw = 1.0f / w;
        bool finiteAll = true;
        for (int k = 0; k < 3; ++k) {
            c[k] *= iw, a[k] *= iw, n[k] *= iw, e[k] *= iw, v[k] *= iw;
            finiteAll = finiteAll && isFiniteF(c[k]) && isFiniteF(a[k]) && isFiniteF(n[k]) && isFiniteF(e[k]) &&
                        isFiniteF(v[k]);
        }
        if (!finiteAll) return stop(x, y);
        const float weight = moved ? this->weight : staticWeight;
        if (!(weight > 0.0f)) return stop(x, y);
        track(x, y, 0) = px;
        track(x, y, 1) = py;
        if (moved) alive(x, y, 0) = 0.5f;
        for (int k = 0; k < 3; ++k) {
            sumColor(x, y, k) += weight * c[k];
            if (sumAlbedo.valid()) sumAlbedo(x, y, k) += weight * a[k];
            if (sumNormal.valid()) sumNormal(x, y, k) += weight * n[k];
            if (sumEmission.valid()) sumEmission(x, y, k) += weight * e[k];
        }
        for (int k = 0; k < vc && sumVariance.valid(); ++k) sumVariance(x, y, k) += weight * weight * v[k];
        count(x, y, 0) += weight;
        count(x, y, 1) += weight * weight;
    }
};

// out = e × (the factor the firefly pass scaled this pixel's colour by: lum(after) / lum(before),
// 1 where the colour was not positive).
struct ScaleLikeColour {
    ImageView before, after, e, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float lb = filters::lum(before(x, y, 0), before(x, y, 1), before(x, y, 2));
        const float la = filters::lum(after(x, y, 0), after(x, y, 1), after(x, y, 2));
        const float s = lb > 0.0f && la < lb ? la / lb : 1.0f;
        for (int k = 0; k < 3; ++k) out(x, y, k) = e(x, y, k) * s;
    }
};

// Sums -> means in place: colour, albedo, emission / count; variance / count² (the variance of a
// mean of independent frames); the normal renormalised (a zero sum stays zero: background).
struct Finish {
    ImageView color, albedo, normal, emission, variance, count;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float n = count(x, y, 0), in = 1.0f / n;
        // Σw² var / (Σw)²; the effective number of frames (Σw)² / Σw² replaces the sum of weights.
        const float n2 = count(x, y, 1);
        for (int k = 0; k < 3; ++k) {
            color(x, y, k) *= in;
            if (albedo.valid()) albedo(x, y, k) *= in;
            if (emission.valid()) emission(x, y, k) *= in;
        }
        if (variance.valid())
            for (int k = 0; k < variance.channels; ++k) variance(x, y, k) *= in * in;
        count(x, y, 0) = n * n / n2;
        if (normal.valid()) {
            const Vec3 v = readVec3(normal, x, y);
            const float l2 = dot(v, v);
            if (l2 > 0.0f && isFiniteF(l2)) writeVec3(normal, x, y, v * (1.0f / sqrtf(l2)));
        }
    }
};

}  // namespace atrous::temporal

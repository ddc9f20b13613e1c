// SVGF G-buffer preparation: sanitised copies of the frame's features (which also become next
// frame's "previous" features) and the screen-space depth gradient ∇z used by the depth tests.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

// Copies depth, normal, id and motion into the filter's own buffers, replacing missing or
// non-finite values: depth -> background (1e30; missing buffer -> 1), normal -> 0 (missing buffer
// -> +z), id -> -1 (missing buffer -> 0), motion -> kMaxMotion (no history; missing buffer -> 0).
struct SanitizeGbuffer {
    ImageView depthIn, normalIn, idsIn, motionIn;  // optional inputs (channel 0 / 0..2 / 0 / 0..1)
    ImageView depth, normal, ids, motion;          // out: 1, 3, 1, 2 channels

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float z = 1.0f;
        if (depthIn.valid()) {
            z = depthIn(x, y, 0);
            if (!(z > 0.0f) || isBackground(z)) z = kBackgroundDepthValue;  // NaN, <= 0, Inf, far
        }
        depth(x, y, 0) = z;

        Vec3 n(0.0f, 0.0f, 1.0f);
        if (normalIn.valid()) {
            n = readVec3(normalIn, x, y);
            n = isFinite(n) ? normalize(n) : Vec3(0.0f);
        }
        writeVec3(normal, x, y, n);

        float id = 0.0f;
        if (idsIn.valid()) {
            id = idsIn(x, y, 0);
            id = isFiniteF(id) ? floorf(id + 0.5f) : -1.0f;
        }
        ids(x, y, 0) = id;

        float mx = 0.0f, my = 0.0f;
        if (motionIn.valid()) {
            mx = motionIn(x, y, 0);
            my = motionIn(x, y, 1);
            if (!(fabsf(mx) < kMaxMotion) || !(fabsf(my) < kMaxMotion)) mx = my = kMaxMotion;
        }
        motion(x, y, 0) = mx;
        motion(x, y, 1) = my;
    }
};

// ∇z per pixel (2 channels: dz/dx, dz/dy). Of the two one-sided differences the smaller in
// magnitude is used, so that a silhouette does not make its neighbours look steep; background
// neighbours are skipped, and a background pixel has gradient 0.
struct DepthGradient {
    ImageView depth;  // sanitised, 1 channel
    ImageView grad;   // out: 2 channels

    ATROUS_HOST_DEVICE float axis(int x, int y, int dx, int dy) const {
        float z = depth(x, y, 0);
        float best = 0.0f;
        bool found = false;
        for (int s = -1; s <= 1; s += 2) {
            int qx = x + s * dx, qy = y + s * dy;
            if (qx < 0 || qy < 0 || qx >= depth.width || qy >= depth.height) continue;
            float zq = depth(qx, qy, 0);
            if (isBackground(zq)) continue;
            float d = float(s) * (zq - z);
            if (!found || fabsf(d) < fabsf(best)) best = d;
            found = true;
        }
        return best;
    }

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        if (isBackground(depth(x, y, 0))) {
            grad(x, y, 0) = 0.0f;
            grad(x, y, 1) = 0.0f;
            return;
        }
        grad(x, y, 0) = axis(x, y, 1, 0);
        grad(x, y, 1) = axis(x, y, 0, 1);
    }
};

}  // namespace atrous::svgf

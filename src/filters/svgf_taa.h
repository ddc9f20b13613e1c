// Optional temporal anti-aliasing after SVGF (off by default): the previous output, reprojected
// bilinearly with the motion vectors, is clamped into the axis-aligned colour box of the current
// 3x3 neighbourhood (which rejects stale history without geometric tests) and blended with the
// current output: out = lerp(clamp(history), current, taaAlpha). Where the reprojected position
// leaves the image, or on the first frame, the current output passes through.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

struct Taa {
    float alpha = 0.1f;
    bool havePrevious = false;
    ImageView current, motion, history;  // 3, 2, 3 channels
    ImageView out;                       // out: 3 channels

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        Vec3 c = readVec3(current, x, y);
        float px = float(x) + motion(x, y, 0), py = float(y) + motion(x, y, 1);
        const int w = current.width, h = current.height;
        // Same integer-centre convention as Reproject; the footprint must lie inside the image.
        if (!havePrevious || !(px >= 0.0f && py >= 0.0f && px <= float(w - 1) && py <= float(h - 1))) {
            writeVec3(out, x, y, c);
            return;
        }
        int x0 = mini(int(px), w - 1), y0 = mini(int(py), h - 1);
        int x1 = mini(x0 + 1, w - 1), y1 = mini(y0 + 1, h - 1);
        float fx = px - float(x0), fy = py - float(y0);
        Vec3 hist = readVec3(history, x0, y0) * ((1.0f - fx) * (1.0f - fy)) + readVec3(history, x1, y0) * (fx * (1.0f - fy)) +
                    readVec3(history, x0, y1) * ((1.0f - fx) * fy) + readVec3(history, x1, y1) * (fx * fy);
        Vec3 lo = c, hi = c;
        for (int j = -1; j <= 1; ++j) {
            for (int i = -1; i <= 1; ++i) {
                int qx = clampi(x + i, 0, w - 1), qy = clampi(y + j, 0, h - 1);
                Vec3 q = readVec3(current, qx, qy);
                lo = minv(lo, q);
                hi = maxv(hi, q);
            }
        }
        hist = minv(maxv(hist, lo), hi);
        writeVec3(out, x, y, hist + (c - hist) * alpha);
    }
};

}  // namespace atrous::svgf

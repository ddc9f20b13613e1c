// One pixel of the reference-free flicker measure (include/atrous/metrics.h, computeFlicker;
// docs/temporal.md, "Flicker without a reference"): frame t's image against frame t-1's, warped onto
// t by frame t's motion, each bilinear tap kept only where the offline temporal filter's reprojection
// test holds between the two frames' G-buffers (temporal::Hop::consistent: ids, depth, normals). No
// colour test: the colour change is what is measured.
#pragma once
#include "filters/temporal_window.h"

namespace atrous::metrics {

// Taps that pass must weigh at least this much of the bilinear footprint, or the pixel is left out
// (one corner of a silhouette's footprint is no estimate of the pixel).
constexpr float kFlickerMinWeight = 0.5f;

struct FlickerStep {
    temporal::Hop hop;          // from: frame t, to: frame t-1 (sanitised G-buffers); its test and tolerances
    ImageView image, previous;  // the judged frames t and t-1 (3 channels)
    ImageView out;              // 2 channels: the pixel's relative squared difference (mean of the channels), and 1
                                // where it reprojects (else both 0)

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        out(x, y, 0) = 0.0f;
        out(x, y, 1) = 0.0f;
        const float mx = hop.from.motion(x, y, 0), my = hop.from.motion(x, y, 1);
        if (!(fabsf(mx) < temporal::kMaxMotion) || !(fabsf(my) < temporal::kMaxMotion)) return;
        const float px = float(x) + mx, py = float(y) + my;
        const float fx0 = floorf(px), fy0 = floorf(py);
        const int x0 = int(fx0), y0 = int(fy0);
        const float ax = px - fx0, ay = py - fy0;
        const temporal::Hop::Anchor a = hop.anchor(x, y);
        float w = 0.0f, c[3] = {0.0f, 0.0f, 0.0f};
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
                const float wt = (i ? ax : 1.0f - ax) * (j ? ay : 1.0f - ay);
                const int sx = x0 + i, sy = y0 + j;
                if (wt <= 0.0f || !hop.consistent(a, sx, sy)) continue;
                w += wt;
                for (int k = 0; k < 3; ++k) c[k] += wt * svgf::finiteOr(previous(sx, sy, k), 0.0f);
            }
        if (!(w >= kFlickerMinWeight)) return;
        float rel = 0.0f;
        for (int k = 0; k < 3; ++k) {
            const float v = svgf::finiteOr(image(x, y, k), 0.0f), p = c[k] / w, d = v - p, m = 0.5f * (v + p);
            rel += d * d / (m * m + 0.01f);
        }
        out(x, y, 0) = rel / 3.0f;
        out(x, y, 1) = 1.0f;
    }
};

}  // namespace atrous::metrics

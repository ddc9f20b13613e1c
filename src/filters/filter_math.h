// Small math shared by the filter functors on host and device: the albedo (de)modulation terms and
// window sums (the give-back's, the firefly pass's density).
// The B3 taps, the exponential, the luminance and the selects are in filters/atrous_math.h.
#pragma once
#include <cmath>

#include "atrous/image.h"
#include "atrous/platform.h"
#include "filters/atrous_math.h"

namespace atrous::filters {

// The albedo that demodulation divides by and remodulation multiplies by (docs/algorithms.md,
// "Albedo demodulation"), per channel: max(a_c, eps) on surfaces with an albedo, blended toward 1
// (no demodulation) where the pixel's largest channel m is below `floor`:
//   a'_c = 1 + t (max(a_c, eps) - 1),  t = min(m / floor, 1)^2.
// Other renderers write albedo 0 on glass, mirrors, emitters and the sky; dividing there by ~eps
// multiplied the noise by 1000 and the filter spread it into the rims ("dotted bright rims").
// The same a'_c on both sides keeps the pair an exact inverse. floor = 0: the plain max(a_c, eps).
// SVGF's floor. The still filters' default (DenoiseOptions::albedoFloor) is 0.05: a floor of 0.1
// half-demodulated a checker's dark squares, so the filter saw the texture as signal to smooth
// (docs/decisions.md).
constexpr float kDefaultAlbedoFloor = 0.1f;
// Beside a black-albedo pixel (max channel below kBlackAlbedoFraction · floor) the floor is
// kRimFloorMul times higher: such a pixel is on the rim of glass or a mirror, partly covered by the
// surface behind, so its small albedo explains little of its colour (dividing by it amplified the
// reflection into a bright rim; docs/decisions.md).
constexpr float kRimFloorMul = 2.0f;
constexpr float kBlackAlbedoFraction = 0.1f;
ATROUS_INLINE float modulationTerm(float m, float floor) {
    const float t = floor > 0.0f ? minSel(m / floor, 1.0f) : 1.0f;
    return finite(t) && t > 0.0f ? t * t : 0.0f;
}
// t = 1 (an ordinary surface) gives max(a, eps) exactly, so a' read back as an albedo (floor 0)
// is a' itself.
ATROUS_INLINE float modulationAlbedo(float a, float t, float eps) {
    const float m = maxSel(a, eps);
    return t >= 1.0f ? m : 1.0f + t * (m - 1.0f);
}
ATROUS_INLINE float maxChannel(float a, float b, float c) { return maxSel(maxSel(a, b), c); }

// a'_c of pixel (x, y), c = 0..2, from an albedo view (non-finite channels read as `nonFinite`);
// an invalid view gives 1 (no demodulation). The one place the filters (EAW, SURE and SVGF) turn
// an albedo pixel into divisors. rim: the rim rule below (EAW/SURE); SVGF calls it (through
// AlbedoRule, modulation.h) with rim = false and nonFinite = 1: its floor 0.1 without the rule
// (docs/decisions.md, "Still filters", albedoFloor).
ATROUS_INLINE void pixelModulationAlbedo(const ImageView& albedo, int x, int y, float eps, float floor, float (&a)[3],
                                         float nonFinite = 0.0f, bool rim = true) {
    if (!albedo.valid()) {
        a[0] = a[1] = a[2] = 1.0f;
        return;
    }
    float v[3];
    for (int c = 0; c < 3; ++c) {
        const float u = albedo(x, y, c);
        v[c] = finite(u) ? u : nonFinite;
    }
    // On the rim of a black-albedo surface (a 3x3 neighbour below kBlackAlbedoFraction · floor)
    // the floor is kRimFloorMul times higher.
    float nearBlack = 0.0f;
    const float mp = maxChannel(v[0], v[1], v[2]);
    if (rim && floor > 0.0f && mp > 0.0f && mp < kRimFloorMul * floor) {  // elsewhere t is the same either way
        float mn = 1e30f;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int xx = clampIdx(x + dx, albedo.width - 1), yy = clampIdx(y + dy, albedo.height - 1);
                const float m = maxChannel(albedo(xx, yy, 0), albedo(xx, yy, 1), albedo(xx, yy, 2));
                mn = minSel(mn, finite(m) ? m : 0.0f);
            }
        nearBlack = mn < kBlackAlbedoFraction * floor ? 1.0f : 0.0f;
    }
    const float t = modulationTerm(mp, floor * (1.0f + nearBlack * (kRimFloorMul - 1.0f)));
    for (int c = 0; c < 3; ++c) a[c] = modulationAlbedo(v[c], t, eps);
}

// Window sums of every channel along x (kVertical false: x - R..x + R) or y, over the taps inside
// the image, added in tap order (the CPU's fused give-back, src/cpu/sure_cpu.cpp, adds the same taps
// in the same order in its row loops).
template <bool kVertical>
struct BoxSum {
    int radius;
    ImageView in, out;  // the same channel count
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int n = kVertical ? in.height : in.width, i = kVertical ? y : x;
        const int lo = i - radius < 0 ? 0 : i - radius, hi = i + radius > n - 1 ? n - 1 : i + radius;
        for (int c = 0; c < in.channels; ++c) {
            float s = 0.0f;
            for (int j = lo; j <= hi; ++j) s += kVertical ? in(x, j, c) : in(j, y, c);
            out(x, y, c) = s;
        }
    }
};
template <class Exec, bool kVertical>
void runBoxSum(const Exec& exec, const BoxSum<kVertical>& f) {
    exec.forEachPixel(f.in.width, f.in.height, f);
}

// The number of in-image taps of p's window.
ATROUS_INLINE float boxTaps(int radius, int x, int y, int w, int h) {
    const int nx = (x + radius < w - 1 ? x + radius : w - 1) - (x - radius > 0 ? x - radius : 0) + 1;
    const int ny = (y + radius < h - 1 ? y + radius : h - 1) - (y - radius > 0 ? y - radius : 0) + 1;
    return float(nx * ny);
}

}  // namespace atrous::filters

// Small math shared by the filter functors on host and device.
#pragma once
#include <cmath>
#include <cstring>

#include "atrous/image.h"
#include "atrous/platform.h"

// Host-only forced inlining for the shared per-pixel math called from the CPU row loops: a call
// left in the x loop stops it vectorising.
#if defined(__GNUC__) && !defined(__CUDACC__)
#define ATROUS_FORCE_INLINE __attribute__((always_inline))
#else
#define ATROUS_FORCE_INLINE
#endif

namespace atrous::filters {

// B3 spline taps [1, 4, 6, 4, 1] / 16, indexed by q + 2.
ATROUS_INLINE float b3(int q) {
    return q == 0 ? 0.375f : ((q == 1 || q == -1) ? 0.25f : 0.0625f);
}

// exp(x) for x <= 0. On the host a branch-free 2^t polynomial (relative error below 3e-7 on
// [-87, 0]) so the per-row loops vectorise with AVX2 (libm's expf does not without -ffast-math);
// on the GPU the hardware __expf. Arguments below -80 (and -inf, never NaN) give exactly 0: a
// weight of e^-80 is irrelevant, and values that small would make denormal products (w·h, w²)
// that cost ~100 cycles each on x86.
ATROUS_INLINE float expNeg(float x) {
#if ATROUS_ON_DEVICE
    return x < -80.0f ? 0.0f : __expf(x);
#else
    // Written with masks rather than `cond ? a : b` on the result: GCC turns the latter into a
    // branch inside the unrolled tap loops and then refuses to vectorise them.
    const int keep = -int(x >= -80.0f);  // all ones, or 0 below -80 (and for -inf, NaN)
    // Clamp |x| to 80 in the integer domain (a float compare-select here also becomes a branch).
    int ax;
    std::memcpy(&ax, &x, sizeof(float));
    ax &= 0x7fffffff;
    ax = ax < 0x42A00000 ? ax : 0x42A00000;  // 0x42A00000 = 80.0f
    float a;
    std::memcpy(&a, &ax, sizeof(float));
    x = -a;  // x <= 0 is the domain, so x = -|x|
    float t = x * 1.44269504088896341f;  // t <= 0
    // Nearest integer by truncating t - 0.5 toward zero (t <= 0): plain conversions vectorise,
    // floorf and fmaxf do not under strict IEEE flags.
    const int ti = int(t - 0.5f);
    const float fi = float(ti);
    float f = t - fi;  // (-0.5, 0.5]
    // 2^f = exp(f ln2): Taylor to degree 6, remainder < 1.2e-7 relative on [-0.5, 0.5).
    float p = 1.540353039e-4f;
    p = p * f + 1.333355815e-3f;
    p = p * f + 9.618129108e-3f;
    p = p * f + 5.550410866e-2f;
    p = p * f + 2.402265070e-1f;
    p = p * f + 6.931471806e-1f;
    p = p * f + 1.0f;
    int e = ti + 127;
    int bits = (e << 23) & keep;  // scale = 2^ti, or exactly 0
    float scale;
    std::memcpy(&scale, &bits, sizeof(float));
    return p * scale;
#endif
}

ATROUS_INLINE float lum(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }
ATROUS_INLINE bool finite(float v) { return v - v == 0.0f; }
ATROUS_INLINE int clampIdx(int v, int hi) { return v < 0 ? 0 : (v > hi ? hi : v); }
ATROUS_INLINE float sq(float v) { return v * v; }
// max/min as selects: libm's fmaxf/fminf are calls on the host (strict IEEE flags), which stop the
// per-row loops from vectorising. Same result as fmaxf(a, b)/fminf(a, b) whenever a is not NaN
// (a NaN a gives b, as fmaxf does).
ATROUS_INLINE float maxSel(float a, float b) { return a > b ? a : b; }
ATROUS_INLINE float minSel(float a, float b) { return a < b ? a : b; }

// The albedo that demodulation divides by and remodulation multiplies by (docs/algorithms.md,
// "Albedo demodulation"), per channel: max(a_c, eps) on surfaces with an albedo, blended toward 1
// (no demodulation) where the pixel's largest channel m is below `floor`:
//   a'_c = 1 + t (max(a_c, eps) - 1),  t = min(m / floor, 1)^2.
// Other renderers write albedo 0 on glass, mirrors, emitters and the sky; dividing there by ~eps
// multiplied the noise by 1000 and the filter spread it into the rims ("dotted bright rims").
// The same a'_c on both sides keeps the pair an exact inverse. floor = 0: the plain max(a_c, eps).
// SVGF's floor. The still filters' default (DenoiseOptions::albedoFloor) is 0.05: on the corpus
// a floor of 0.1 half-demodulated a 40x checker's dark squares (albedo ~0.09), so the filter saw
// the texture as signal to smooth (Cycles textures at 16 spp, SURE: 0.021 -> 0.011; docs/quality.md).
constexpr float kDefaultAlbedoFloor = 0.1f;
// Beside a black-albedo pixel (max channel below kBlackAlbedoFraction · floor) the floor is
// kRimFloorMul times higher: such a pixel is on the rim of glass or a mirror, partly covered by the
// surface behind, so its small albedo explains little of its colour (dividing by it amplified the
// reflection into a bright rim). Measured on the corpus (docs/quality.md): the quick set's mirror
// scene at 4 spp 0.058 -> 0.043 (floor 0.05 alone had lost 32% there against 0.1); 2 and 4 equal.
constexpr float kRimFloorMul = 2.0f;
constexpr float kBlackAlbedoFraction = 0.1f;
ATROUS_INLINE float modulationTerm(float m, float floor) {
    const float t = floor > 0.0f ? minSel(m / floor, 1.0f) : 1.0f;
    return finite(t) && t > 0.0f ? t * t : 0.0f;
}
ATROUS_INLINE float modulationAlbedo(float a, float t, float eps) { return 1.0f + t * (maxSel(a, eps) - 1.0f); }
ATROUS_INLINE float maxChannel(float a, float b, float c) { return maxSel(maxSel(a, b), c); }

// a'_c of pixel (x, y), c = 0..2, from an albedo view (non-finite values read as 0); an invalid
// view gives 1 (no demodulation). The one place the filters turn an albedo pixel into divisors.
ATROUS_INLINE void pixelModulationAlbedo(const ImageView& albedo, int x, int y, float eps, float floor, float (&a)[3]) {
    if (!albedo.valid()) {
        a[0] = a[1] = a[2] = 1.0f;
        return;
    }
    float v[3];
    for (int c = 0; c < 3; ++c) {
        const float u = albedo(x, y, c);
        v[c] = finite(u) ? u : 0.0f;
    }
    // On the rim of a black-albedo surface (a 3x3 neighbour below kBlackAlbedoFraction · floor)
    // the floor is kRimFloorMul times higher.
    float nearBlack = 0.0f;
    if (floor > 0.0f) {
        float mn = 1e30f;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int xx = clampIdx(x + dx, albedo.width - 1), yy = clampIdx(y + dy, albedo.height - 1);
                const float m = maxChannel(albedo(xx, yy, 0), albedo(xx, yy, 1), albedo(xx, yy, 2));
                mn = minSel(mn, finite(m) ? m : 0.0f);
            }
        nearBlack = mn < kBlackAlbedoFraction * floor ? 1.0f : 0.0f;
    }
    const float t = modulationTerm(maxChannel(v[0], v[1], v[2]), floor * (1.0f + nearBlack * (kRimFloorMul - 1.0f)));
    for (int c = 0; c < 3; ++c) a[c] = modulationAlbedo(v[c], t, eps);
}

}  // namespace atrous::filters

// Small math shared by the filter functors on host and device.
#pragma once
#include <cmath>
#include <cstring>

#include "atrous/platform.h"

namespace atrous::filters {

// B3 spline taps [1, 4, 6, 4, 1] / 16, indexed by q + 2.
ATROUS_INLINE float b3(int q) {
    return q == 0 ? 0.375f : ((q == 1 || q == -1) ? 0.25f : 0.0625f);
}

// exp(x) for x <= 0. On the host a branch-free 2^t polynomial (relative error below 3e-7 on
// [-87, 0]) so the per-row loops vectorise with AVX2 (libm's expf does not without -ffast-math);
// on the GPU the hardware __expf. Very negative arguments (and -inf) give ~1e-38, never NaN.
ATROUS_INLINE float expNeg(float x) {
#if ATROUS_ON_DEVICE
    return __expf(fmaxf(x, -87.0f));
#else
    x = x < -87.0f ? -87.0f : x;  // also maps -inf to -87
    float t = x * 1.44269504088896341f;
    float fi = floorf(t + 0.5f);
    float f = t - fi;  // [-0.5, 0.5)
    // 2^f = exp(f ln2): Taylor to degree 6, remainder < 1.2e-7 relative on [-0.5, 0.5).
    float p = 1.540353039e-4f;
    p = p * f + 1.333355815e-3f;
    p = p * f + 9.618129108e-3f;
    p = p * f + 5.550410866e-2f;
    p = p * f + 2.402265070e-1f;
    p = p * f + 6.931471806e-1f;
    p = p * f + 1.0f;
    int e = int(fi) + 127;
    int bits = e << 23;
    float scale;
    std::memcpy(&scale, &bits, sizeof(float));
    return p * scale;
#endif
}

ATROUS_INLINE float lum(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }
ATROUS_INLINE bool finite(float v) { return v - v == 0.0f; }
ATROUS_INLINE int clampIdx(int v, int hi) { return v < 0 ? 0 : (v > hi ? hi : v); }
ATROUS_INLINE float sq(float v) { return v * v; }

}  // namespace atrous::filters

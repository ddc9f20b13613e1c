// The per-pixel math every filter of atrous shares, on host and device: the B3 taps, the one
// fast exponential, the luminance, and the selects that keep the CPU row loops branch-free.
// EAW, SURE and SVGF (and any new edge-stop policy, filters/atrous_level.h) use these and no
// private copies; docs/architecture.md, "The filter layer".
#pragma once
#include <cmath>
#include <cstring>

#include "atrous/platform.h"


namespace atrous::filters {

// B3 spline taps [1, 4, 6, 4, 1] / 16, indexed by the tap offset q in [-2, 2].
ATROUS_INLINE float b3(int q) {
    return q == 0 ? 0.375f : ((q == 1 || q == -1) ? 0.25f : 0.0625f);
}

// c ? a : b. On the host a bit mask: GCC turns a plain `?:` (or fmaxf/floorf) into a branch inside
// the CPU row loops and then refuses to vectorise them; the result is the same value either way.
// Arguments are evaluated unconditionally, so both must be safe to compute (an Inf or NaN in the
// unused one is harmless).
ATROUS_FORCE_INLINE ATROUS_INLINE float selectF(bool c, float a, float b) {
#if ATROUS_ON_DEVICE
    return c ? a : b;
#else
    int ai, bi;
    std::memcpy(&ai, &a, sizeof(float));
    std::memcpy(&bi, &b, sizeof(float));
    const int m = -int(c);  // all ones or 0
    const int ri = (ai & m) | (bi & ~m);
    float r;
    std::memcpy(&r, &ri, sizeof(float));
    return r;
#endif
}

// e^x for x <= 0, the one exponential of the filters: EAW, SURE, the emission filter and SVGF
// weight their taps with it. A branch-free 2^t polynomial (relative error below 3e-7 on [-80, 0];
// plus float rounding of t = x log2 e, ~5e-6 relative at the far end) instead of expf: several
// times faster on the CPU, vectorises with AVX2/AVX-512 (libm's expf does not without
// -ffast-math), and every multiply-add is spelled out as fmaf, so it is the same function on the
// host and the device (no __expf) and the backends agree to float rounding. Arguments below -80
// (and -inf and NaN) give exactly 0: a weight of e^-80 is irrelevant, and values that small
// would make denormal products (w·h, w²) that cost ~100 cycles each on x86.
ATROUS_FORCE_INLINE ATROUS_INLINE float fastExp(float x) {
    // Masks rather than `cond ? a : b` on the result: GCC turns the latter into a branch inside
    // the unrolled tap loops and then refuses to vectorise them.
    const int keep = -int(x >= -80.0f);  // all ones, or 0 below -80 (and for -inf, NaN)
    // Clamp |x| to 80 in the integer domain (a float compare-select here also becomes a branch).
    int ax;
    std::memcpy(&ax, &x, sizeof(float));
    ax &= 0x7fffffff;
    ax = ax < 0x42A00000 ? ax : 0x42A00000;  // 0x42A00000 = 80.0f
    float a;
    std::memcpy(&a, &ax, sizeof(float));
    x = -a;  // x <= 0 is the domain, so x = -|x|
    // t = x log2 e <= 0; ti = nearest integer to t by truncating t - 0.5 toward zero (plain
    // conversions vectorise, floorf does not under strict IEEE flags); f = t - ti in (-0.5, 0.5]
    // with the exact product (one rounding).
    const int ti = int(fmaf(x, 1.44269504088896341f, -0.5f));
    const float f = fmaf(x, 1.44269504088896341f, -float(ti));
    // 2^f = exp(f ln2): Taylor to degree 6, remainder < 1.2e-7 relative on [-0.5, 0.5).
    float p = 1.540353039e-4f;
    p = fmaf(p, f, 1.333355815e-3f);
    p = fmaf(p, f, 9.618129108e-3f);
    p = fmaf(p, f, 5.550410866e-2f);
    p = fmaf(p, f, 2.402265070e-1f);
    p = fmaf(p, f, 6.931471806e-1f);
    p = fmaf(p, f, 1.0f);
    const int bits = ((ti + 127) << 23) & keep;  // scale = 2^ti, or exactly 0
    float scale;
    std::memcpy(&scale, &bits, sizeof(float));
    return p * scale;
}

// Rec. 709 luminance of linear RGB, the multiply-adds spelled out: exactly the contraction GCC
// made of the plain 0.2126 r + 0.7152 g + 0.0722 b (so EAW/SURE's firefly pass, noise estimate and
// report kept their values), now fixed so that every backend rounds the same way.
ATROUS_FORCE_INLINE ATROUS_INLINE float lum(float r, float g, float b) {
    return fmaf(0.0722f, b, fmaf(0.2126f, r, 0.7152f * g));
}

ATROUS_INLINE bool finite(float v) { return v - v == 0.0f; }
ATROUS_INLINE int clampIdx(int v, int hi) { return v < 0 ? 0 : (v > hi ? hi : v); }
ATROUS_INLINE float sq(float v) { return v * v; }
// max/min as selects: libm's fmaxf/fminf are calls on the host (strict IEEE flags), which stop the
// per-row loops from vectorising. Same result as fmaxf(a, b)/fminf(a, b) whenever a is not NaN
// (a NaN a gives b, as fmaxf does).
ATROUS_INLINE float maxSel(float a, float b) { return a > b ? a : b; }
ATROUS_INLINE float minSel(float a, float b) { return a < b ? a : b; }

}  // namespace atrous::filters

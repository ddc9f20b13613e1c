// Helpers shared by the SVGF stage functors (docs/svgf.md): sanitising rules for the
// G-buffer and the three edge-stopping terms. Host/device, no STL.
#pragma once
#include <cstring>

#include "atrous/image.h"
#include "atrous/math.h"
#include "filters/modulation.h"  // AlbedoRule, Demodulate, Remodulate; atrous_math.h: b3, fastExp, lum, selectF

namespace atrous::svgf {

// Depth at or beyond this is background (the renderer writes 1e30; non-finite depth counts too).
constexpr float kBackgroundDepth = 1e29f;
constexpr float kBackgroundDepthValue = 1e30f;
// Motion at least this large (or non-finite) cannot be reprojected: the pixel's history resets.
constexpr float kMaxMotion = 1e5f;
// Demodulation divides by albedoRule()'s a' (max(albedo, kMinAlbedo) on surfaces); remodulation multiplies by the same value so
// the pair is an identity wherever the filter leaves a pixel alone.
constexpr float kMinAlbedo = 1e-3f;
// Illumination magnitudes are clamped here so the second moment (l^2) stays finite in float.
constexpr float kMaxIllum = 1e15f;

ATROUS_INLINE bool isBackground(float z) { return !(z < kBackgroundDepth); }  // NaN -> background

ATROUS_INLINE float finiteOr(float v, float fallback) { return isFiniteF(v) ? v : fallback; }

ATROUS_INLINE Vec3 readVec3(const ImageView& v, int x, int y) { return Vec3(v(x, y, 0), v(x, y, 1), v(x, y, 2)); }

ATROUS_INLINE void writeVec3(const ImageView& v, int x, int y, Vec3 c) {
    v(x, y, 0) = c.x;
    v(x, y, 1) = c.y;
    v(x, y, 2) = c.z;
}

// SVGF's albedo rule for the one demodulate/remodulate pair (filters/modulation.h): missing -> 1,
// non-finite channel -> 1, else max(a, kMinAlbedo), blended toward 1 where the albedo is near
// black: filters::pixelModulationAlbedo, the still filters' own, with SVGF's floor
// (kDefaultAlbedoFloor) and without their rim rule.
ATROUS_INLINE filters::AlbedoRule albedoRule() {
    filters::AlbedoRule r;
    r.eps = kMinAlbedo, r.floor = filters::kDefaultAlbedoFloor, r.rim = false, r.nonFinite = 1.0f;
    return r;
}

// Emission to subtract/add back: missing or non-finite -> 0.
ATROUS_INLINE Vec3 sanitizedEmission(const ImageView& emission, int x, int y) {
    if (!emission.valid()) return Vec3(0.0f);
    Vec3 e = readVec3(emission, x, y);
    return Vec3(finiteOr(e.x, 0.0f), finiteOr(e.y, 0.0f), finiteOr(e.z, 0.0f));
}

// a·b with every multiply-add written as fmaf. The edge-stop math below spells out its FMAs so
// that no compiler is free to contract a·b + c differently: the CPU row loops, the scalar functor
// and the GPU then round identically (bit-equal CPU paths; docs/decisions.md, "Sequences"), which matters
// because σ_n = 128 multiplies the rounding of n_p·n_q and the exponentials that of their argument.
ATROUS_INLINE float dotFma(Vec3 a, Vec3 b) { return fmaf(a.z, b.z, fmaf(a.y, b.y, a.x * b.x)); }

ATROUS_INLINE bool hasNormal(Vec3 n) { return dotFma(n, n) > 0.25f; }

// The shared selects and exponential (filters/atrous_math.h), by their SVGF names.
using filters::fastExp;
using filters::selectF;

// Smallest normal float: fastLog's argument is clamped here (its exponent trick needs a normal
// number); log(1.2e-38) = -87.3, so σ_n log d already gives a weight of 0 for any σ_n >= 1.
constexpr float kMinNormalFloat = 1.17549435e-38f;

// ln(d) for finite d >= kMinNormalFloat, to ~1.5e-7 relative on (0, 1] (the float rounding of
// s below; the series' truncation is 2e-9). Plain arithmetic, identical on host and device (so
// the two backends agree to float rounding, like fastExp), and branch-free so the CPU row loops
// vectorise (libm's logf is a call that does not; its cost: docs/decisions.md, "Speed").
// d = m·2^e with m in [√½, √2) read from the bits, then ln m = 2 atanh(s), s = (m − 1)/(m + 1),
// |s| <= 0.1716: the odd series 2s(1 + s²/3 + s⁴/5 + s⁶/7 + s⁸/9).
ATROUS_FORCE_INLINE ATROUS_INLINE float fastLog(float d) {
    int bits;
    memcpy(&bits, &d, sizeof(float));
    const int e = (bits - 0x3f3504f3) >> 23;  // 0x3f3504f3 = √½: e = 0 for d in [√½, √2)
    bits -= e * (1 << 23);                    // m = d / 2^e
    float m;
    memcpy(&m, &bits, sizeof(float));
    const float s = (m - 1.0f) / (m + 1.0f);
    const float s2 = s * s;
    const float p = s2 * fmaf(s2, fmaf(s2, fmaf(s2, 0.111111111f, 0.142857143f), 0.2f), 0.333333333f);
    const float s2x = 2.0f * s;
    return fmaf(float(e), 0.693147181f, fmaf(s2x, p, s2x));
}

// Normal edge stop, as a log-weight: σ_n log max(0, n_p·n_q). Two background (zero) normals
// match; a zero normal against a real one does not. Written for scalar code (the per-pixel
// functors): only the case that applies is computed. normalLogWeightSel is the same value
// without branches, for the vectorised loops.
ATROUS_INLINE float normalLogWeight(Vec3 np, Vec3 nq, float sigmaN) {
    const bool hp = hasNormal(np), hq = hasNormal(nq);
    if (!hp || !hq) return (hp == hq) ? 0.0f : -1e30f;
    const float d = dotFma(np, nq);
    if (!(d > 0.0f)) return -1e30f;
    if (!(d < 1.0f)) return 0.0f;  // unit normals, rounding: as σ_n fastLog(1) = 0
    return sigmaN * fastLog(maxf(d, kMinNormalFloat));
}

// normalLogWeight with selects (see selectF): every case computed, the one that applies kept.
ATROUS_FORCE_INLINE ATROUS_INLINE float normalLogWeightSel(Vec3 np, Vec3 nq, float sigmaN) {
    const bool hp = hasNormal(np), hq = hasNormal(nq);
    const float d = dotFma(np, nq);
    // d >= 1 gives exactly 0: fastLog(1) = 0.
    float dc = selectF(d < 1.0f, d, 1.0f);
    dc = selectF(dc > kMinNormalFloat, dc, kMinNormalFloat);
    const float lw = selectF(d > 0.0f, sigmaN * fastLog(dc), -1e30f);
    return selectF(hp & hq, lw, selectF(hp == hq, 0.0f, -1e30f));
}

// Depth edge stop, as a log-weight: -|z_p - z_q| / (σ_z |∇z_p·(p - q)| + ε). ε is relative to
// the depth (1e-3 z_p) so that the rule does not depend on the scene's units; two background
// pixels match, background against surface does not. depthLogWeightSel: the same without branches.
ATROUS_FORCE_INLINE ATROUS_INLINE float depthLogWeightDenom(float zp, float gx, float gy, float dx, float dy,
                                                             float sigmaZ) {
    return fmaf(sigmaZ, fabsf(fmaf(gx, dx, gy * dy)), fmaf(1e-3f, fabsf(zp), 1e-8f));
}

ATROUS_INLINE float depthLogWeight(float zp, float zq, float gx, float gy, float dx, float dy, float sigmaZ) {
    const bool bp = isBackground(zp), bq = isBackground(zq);
    if (bp || bq) return (bp == bq) ? 0.0f : -1e30f;
    return -fabsf(zp - zq) / depthLogWeightDenom(zp, gx, gy, dx, dy, sigmaZ);
}

ATROUS_FORCE_INLINE ATROUS_INLINE float depthLogWeightSel(float zp, float zq, float gx, float gy, float dx, float dy,
                                                           float sigmaZ) {
    const bool bp = isBackground(zp), bq = isBackground(zq);
    const float lw = -fabsf(zp - zq) / depthLogWeightDenom(zp, gx, gy, dx, dy, sigmaZ);
    return selectF(bp | bq, selectF(bp == bq, 0.0f, -1e30f), lw);
}

}  // namespace atrous::svgf

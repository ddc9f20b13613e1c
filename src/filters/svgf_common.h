// Helpers shared by the SVGF stage functors (ALGORITHMS.md §4): sanitising rules for the
// G-buffer and the three edge-stopping terms. Host/device, no STL.
#pragma once
#include <cstring>

#include "atrous/image.h"
#include "core/math.h"

namespace atrous::svgf {

// Depth at or beyond this is background (the renderer writes 1e30; non-finite depth counts too).
constexpr float kBackgroundDepth = 1e29f;
constexpr float kBackgroundDepthValue = 1e30f;
// Motion at least this large (or non-finite) cannot be reprojected: the pixel's history resets.
constexpr float kMaxMotion = 1e5f;
// Demodulation divides by max(albedo, kMinAlbedo); remodulation multiplies by the same value so
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

// Albedo used for (de)modulation: missing -> 1, non-finite -> 1, else max(a, kMinAlbedo).
ATROUS_INLINE Vec3 modulationAlbedo(const ImageView& albedo, int x, int y) {
    if (!albedo.valid()) return Vec3(1.0f);
    Vec3 a = readVec3(albedo, x, y);
    return Vec3(maxf(finiteOr(a.x, 1.0f), kMinAlbedo), maxf(finiteOr(a.y, 1.0f), kMinAlbedo),
                maxf(finiteOr(a.z, 1.0f), kMinAlbedo));
}

// Emission to subtract/add back: missing or non-finite -> 0.
ATROUS_INLINE Vec3 sanitizedEmission(const ImageView& emission, int x, int y) {
    if (!emission.valid()) return Vec3(0.0f);
    Vec3 e = readVec3(emission, x, y);
    return Vec3(finiteOr(e.x, 0.0f), finiteOr(e.y, 0.0f), finiteOr(e.z, 0.0f));
}

ATROUS_INLINE bool hasNormal(Vec3 n) { return dot(n, n) > 0.25f; }

// Normal edge stop, as a log-weight: σ_n log max(0, n_p·n_q). Two background (zero) normals
// match; a zero normal against a real one does not.
ATROUS_INLINE float normalLogWeight(Vec3 np, Vec3 nq, float sigmaN) {
    bool hp = hasNormal(np), hq = hasNormal(nq);
    if (!hp || !hq) return (hp == hq) ? 0.0f : -1e30f;
    float d = dot(np, nq);
    if (d <= 0.0f) return -1e30f;
    return d >= 1.0f ? 0.0f : sigmaN * logf(d);
}

// Depth edge stop, as a log-weight: -|z_p - z_q| / (σ_z |∇z_p·(p - q)| + ε). ε is relative to
// the depth (1e-3 z_p) so that the rule does not depend on the scene's units; two background
// pixels match, background against surface does not.
ATROUS_INLINE float depthLogWeight(float zp, float zq, float gx, float gy, float dx, float dy, float sigmaZ) {
    bool bp = isBackground(zp), bq = isBackground(zq);
    if (bp || bq) return (bp == bq) ? 0.0f : -1e30f;
    float denom = sigmaZ * fabsf(gx * dx + gy * dy) + 1e-3f * fabsf(zp) + 1e-8f;
    return -fabsf(zp - zq) / denom;
}

// e^x for the edge-stopping weights, to ~2e-7 relative error (below float rounding of the sums it
// feeds), 0 below e^-87. Plain arithmetic instead of expf: several times faster on the CPU, where
// the à-trous taps spend most of their time in expf, and identical on host and device so the two
// backends agree to float rounding.
ATROUS_INLINE float fastExp(float x) {
    if (!(x > -87.0f)) return 0.0f;  // also NaN -> 0
    x = minf(x, 88.0f);
    float t = x * 1.44269504f;  // log2(e)
    float k = floorf(t + 0.5f);
    float f = t - k;            // in [-0.5, 0.5]
    // 2^f by its Taylor series in f ln 2 to degree 6 (remainder < 1.3e-7 on [-0.5, 0.5]).
    float p = 1.0f + f * (0.693147181f + f * (0.240226507f + f * (0.0555041087f + f * (0.00961812911f +
                     f * (0.00133335581f + f * 0.000154035304f)))));
    int bits = (int(k) + 127) << 23;  // 2^k, k in [-126, 127]
    float scale;
    memcpy(&scale, &bits, sizeof(float));
    return p * scale;
}

// B3-spline taps [1, 4, 6, 4, 1] / 16.
ATROUS_INLINE float b3Tap(int i) {
    return i == 0 ? 0.375f : ((i == 1 || i == -1) ? 0.25f : 0.0625f);
}

}  // namespace atrous::svgf

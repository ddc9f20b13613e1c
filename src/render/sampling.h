// Sampling building blocks shared by host and device: warps from [0,1)^2, piecewise-constant 1D
// and 2D distributions stored as flat CDF arrays, the power heuristic, texture lookups.
#pragma once
#include "atrous/math.h"
#include "render/scene_data.h"

namespace atrous::pt {

ATROUS_INLINE Vec3 cosineHemisphere(float u1, float u2) {
    // Malley's method: uniform disk (concentric map) lifted to the hemisphere; pdf = cos / pi.
    float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
    float r, phi;
    if (a == 0.0f && b == 0.0f) return Vec3(0.0f, 0.0f, 1.0f);
    if (a * a > b * b) {
        r = a;
        phi = (kPi / 4.0f) * (b / a);
    } else {
        r = b;
        phi = (kPi / 2.0f) - (kPi / 4.0f) * (a / b);
    }
    float x = r * cosf(phi), y = r * sinf(phi);
    return Vec3(x, y, sqrtf(maxf(0.0f, 1.0f - x * x - y * y)));
}

ATROUS_INLINE Vec3 uniformSphere(float u1, float u2) {
    float z = 1.0f - 2.0f * u1;
    float r = sqrtf(maxf(0.0f, 1.0f - z * z));
    float phi = 2.0f * kPi * u2;
    return Vec3(r * cosf(phi), r * sinf(phi), z);
}

// Uniform point on a triangle as barycentrics (b1, b2) (Heitz 2019's low-distortion map would also do).
ATROUS_INLINE void uniformTriangle(float u1, float u2, float& b1, float& b2) {
    float s = sqrtf(u1);
    b1 = 1.0f - s;
    b2 = u2 * s;
}

// Power heuristic with beta = 2 (Veach 1997), pdfs in the same measure (solid angle).
ATROUS_INLINE float powerHeuristic(float pdfA, float pdfB) {
    float a = pdfA * pdfA, b = pdfB * pdfB;
    return a + b > 0.0f ? a / (a + b) : 0.0f;
}

// Index i of the segment of cdf[0..n] (cdf[0] = 0, cdf[n] = 1) that holds u: cdf[i] <= u < cdf[i+1].
ATROUS_INLINE int findSegment(const float* cdf, int n, float u) {
    int lo = 0, hi = n;  // invariant: cdf[lo] <= u, answer in [lo, hi)
    while (hi - lo > 1) {
        int mid = (lo + hi) >> 1;
        if (cdf[mid] <= u) lo = mid; else hi = mid;
    }
    return lo;
}

// Samples a piecewise-constant function on [0,1) with n cells from its CDF. Returns the continuous
// coordinate; `cell` and `pdf` (density w.r.t. the coordinate: func/integral = n * cell mass).
ATROUS_INLINE float sampleContinuous(const float* cdf, int n, float u, int& cell, float& pdf) {
    int i = findSegment(cdf, n, u);
    float mass = cdf[i + 1] - cdf[i];
    float du = mass > 0.0f ? (u - cdf[i]) / mass : 0.5f;
    cell = i;
    pdf = mass * float(n);
    return minf((float(i) + clampf(du, 0.0f, 1.0f)) / float(n), 0.99999994f);
}

// ---- textures ----

ATROUS_INLINE Vec3 texel(const SceneView& s, const Texture& t, int x, int y) {
    size_t plane = size_t(t.width) * size_t(t.height);
    const float* p = s.texels + t.offset + size_t(y) * size_t(t.width) + size_t(x);
    return Vec3(p[0], p[plane], p[2 * plane]);
}

// Bilinear lookup with wrap-around; uv (0,0) = bottom left of the image (OBJ convention).
ATROUS_INLINE Vec3 sampleTexture(const SceneView& s, int index, Vec2 uv) {
    const Texture& t = s.textures[index];
    float fx = (uv.x - floorf(uv.x)) * float(t.width) - 0.5f;
    float fy = (1.0f - (uv.y - floorf(uv.y))) * float(t.height) - 0.5f;
    float x0f = floorf(fx), y0f = floorf(fy);
    float ax = fx - x0f, ay = fy - y0f;
    int x0 = int(x0f), y0 = int(y0f);
    int x1 = x0 + 1, y1 = y0 + 1;
    x0 = (x0 % t.width + t.width) % t.width;
    x1 = (x1 % t.width + t.width) % t.width;
    y0 = (y0 % t.height + t.height) % t.height;
    y1 = (y1 % t.height + t.height) % t.height;
    return (texel(s, t, x0, y0) * (1.0f - ax) + texel(s, t, x1, y0) * ax) * (1.0f - ay) +
           (texel(s, t, x0, y1) * (1.0f - ax) + texel(s, t, x1, y1) * ax) * ay;
}

// ---- environment ----

ATROUS_INLINE Vec2 directionToLatLong(Vec3 d) {
    float u = atan2f(d.z, d.x) * (0.5f * kInvPi) + 0.5f;
    float v = acosf(clampf(d.y, -1.0f, 1.0f)) * kInvPi;
    return Vec2(u, v);
}

ATROUS_INLINE Vec3 latLongToDirection(float u, float v) {
    float phi = (u - 0.5f) * 2.0f * kPi, theta = v * kPi;
    float st = sinf(theta);
    return Vec3(st * cosf(phi), cosf(theta), st * sinf(phi));
}

// Nearest texel of the lat-long map (matches the piecewise-constant sampling distribution exactly,
// which keeps MIS weights and pdfs consistent).
ATROUS_INLINE Vec3 envMapTexel(const SceneView& s, float u, float v) {
    const Texture& t = s.textures[s.env.texture];
    int x = clampi(int(u * float(t.width)), 0, t.width - 1);
    int y = clampi(int(v * float(t.height)), 0, t.height - 1);
    return texel(s, t, x, y);
}

ATROUS_INLINE Vec3 envRadiance(const SceneView& s, Vec3 dir) {
    if (s.env.type == EnvType::Constant) return s.env.color;
    if (s.env.type == EnvType::Map) {
        Vec2 uv = directionToLatLong(dir);
        return envMapTexel(s, uv.x, uv.y) * s.env.color;
    }
    return Vec3(0.0f);
}

// Solid-angle pdf of sampleEnv choosing `dir` (without the light-selection probability).
ATROUS_INLINE float envPdf(const SceneView& s, Vec3 dir) {
    if (s.env.type == EnvType::Constant) return 1.0f / (4.0f * kPi);
    if (s.env.type != EnvType::Map || s.env.margInt <= 0.0f) return 0.0f;
    const Texture& t = s.textures[s.env.texture];
    Vec2 uv = directionToLatLong(dir);
    int x = clampi(int(uv.x * float(t.width)), 0, t.width - 1);
    int y = clampi(int(uv.y * float(t.height)), 0, t.height - 1);
    const float* cond = s.envDist + s.env.condCdf + size_t(y) * size_t(t.width + 1);
    const float* marg = s.envDist + s.env.margCdf;
    float pdfUv = (cond[x + 1] - cond[x]) * float(t.width) * (marg[y + 1] - marg[y]) * float(t.height);
    float sinTheta = sinf(uv.y * kPi);
    return sinTheta > 0.0f ? pdfUv / (2.0f * kPi * kPi * sinTheta) : 0.0f;
}

// Samples a direction toward the environment; returns false when it has nothing to sample.
ATROUS_INLINE bool sampleEnv(const SceneView& s, float u1, float u2, Vec3& dir, float& pdf) {
    if (s.env.type == EnvType::Constant) {
        dir = uniformSphere(u1, u2);
        pdf = 1.0f / (4.0f * kPi);
        return true;
    }
    if (s.env.type != EnvType::Map || s.env.margInt <= 0.0f) return false;
    const Texture& t = s.textures[s.env.texture];
    int row, col;
    float pdfV, pdfU;
    float v = sampleContinuous(s.envDist + s.env.margCdf, t.height, u1, row, pdfV);
    float u = sampleContinuous(s.envDist + s.env.condCdf + size_t(row) * size_t(t.width + 1), t.width, u2, col, pdfU);
    float sinTheta = sinf(v * kPi);
    if (sinTheta <= 0.0f || pdfU * pdfV <= 0.0f) return false;
    dir = latLongToDirection(u, v);
    pdf = pdfU * pdfV / (2.0f * kPi * kPi * sinTheta);
    return true;
}

}  // namespace atrous::pt

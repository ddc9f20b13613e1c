// Small vector math shared by host and device code.
#pragma once
#include <cmath>

#include "atrous/platform.h"

namespace atrous {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr float kInfinity = 3.0e38f;  // finite stand-in used where a format needs a number

struct Vec2 {
    float x = 0, y = 0;
    Vec2() = default;  // defaulted: host and device alike
    ATROUS_INLINE Vec2(float x_, float y_) : x(x_), y(y_) {}
};

struct Vec3 {
    float x = 0, y = 0, z = 0;
    Vec3() = default;  // defaulted: host and device alike
    ATROUS_INLINE Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
    ATROUS_INLINE explicit Vec3(float v) : x(v), y(v), z(v) {}
    ATROUS_INLINE float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    ATROUS_INLINE float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

ATROUS_INLINE Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
ATROUS_INLINE Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
ATROUS_INLINE Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
ATROUS_INLINE Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
ATROUS_INLINE Vec3 operator/(Vec3 a, Vec3 b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }
ATROUS_INLINE Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
ATROUS_INLINE Vec3 operator*(float s, Vec3 a) { return {a.x * s, a.y * s, a.z * s}; }
ATROUS_INLINE Vec3 operator/(Vec3 a, float s) { return a * (1.0f / s); }
ATROUS_INLINE Vec3& operator+=(Vec3& a, Vec3 b) { a = a + b; return a; }
ATROUS_INLINE Vec3& operator-=(Vec3& a, Vec3 b) { a = a - b; return a; }
ATROUS_INLINE Vec3& operator*=(Vec3& a, Vec3 b) { a = a * b; return a; }
ATROUS_INLINE Vec3& operator*=(Vec3& a, float s) { a = a * s; return a; }

ATROUS_INLINE float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
ATROUS_INLINE Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
ATROUS_INLINE float length(Vec3 a) { return sqrtf(dot(a, a)); }
ATROUS_INLINE float lengthSquared(Vec3 a) { return dot(a, a); }
ATROUS_INLINE Vec3 normalize(Vec3 a) {
    float l = length(a);
    return l > 0.0f ? a / l : Vec3(0.0f);
}
ATROUS_INLINE float minf(float a, float b) { return a < b ? a : b; }
ATROUS_INLINE float maxf(float a, float b) { return a > b ? a : b; }
ATROUS_INLINE int mini(int a, int b) { return a < b ? a : b; }
ATROUS_INLINE int maxi(int a, int b) { return a > b ? a : b; }
ATROUS_INLINE float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
ATROUS_INLINE int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }
ATROUS_INLINE float lerpf(float a, float b, float t) { return a + (b - a) * t; }
ATROUS_INLINE Vec3 minv(Vec3 a, Vec3 b) { return {minf(a.x, b.x), minf(a.y, b.y), minf(a.z, b.z)}; }
ATROUS_INLINE Vec3 maxv(Vec3 a, Vec3 b) { return {maxf(a.x, b.x), maxf(a.y, b.y), maxf(a.z, b.z)}; }
ATROUS_INLINE float maxComponent(Vec3 a) { return maxf(a.x, maxf(a.y, a.z)); }
// Rec. 709 luminance of linear RGB.
ATROUS_INLINE float luminance(Vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
ATROUS_INLINE bool isFiniteF(float v) { return v - v == 0.0f; }  // false for NaN and +-Inf
ATROUS_INLINE bool isFinite(Vec3 v) { return isFiniteF(v.x) && isFiniteF(v.y) && isFiniteF(v.z); }

// Orthonormal basis around unit n (Duff et al. 2017, branchless).
ATROUS_INLINE void makeBasis(Vec3 n, Vec3& t, Vec3& b) {
    float s = n.z >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (s + n.z);
    float c = n.x * n.y * a;
    t = Vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    b = Vec3(c, s + n.y * n.y * a, -n.y);
}

}  // namespace atrous

// The ranges a scene value may take: one rule per kind of value, shared by the JSON scene parser and
// the OBJ/MTL loader (docs/reliability.md). Every number a scene carries is finite and inside its
// kind's range, so nothing downstream overflows:
// - coordinates (camera position and target, vertices after their transform, sphere centres and
//   radii, quad corners, light positions, pivots, translations) stay within ±kMaxSceneCoordinate.
//   Embree asserts |ray origin| <= 1.844e18 (FLT_LARGE, `ray.valid()`); hit points lie on the
//   geometry, so every ray origin stays within the scene's bounds plus a small offset, 9 orders of
//   magnitude below that, and differences and cross products of two coordinates stay finite;
// - radiances (emission, point-light intensity, environment colour and map times its scale, the
//   sky's sun) within [0, kMaxRadiance]: the running variance of a pixel (squares of samples)
//   stays finite;
// - reflectances within [0, 1] (a larger one creates energy);
// - texture coordinates within ±kMaxTexcoord, the checker scale within (0, kMaxCheckerScale].
#pragma once
#include <cmath>
#include <cstdio>
#include <string>

namespace atrous::pt {

constexpr float kMaxSceneCoordinate = 1e9f;
constexpr float kMaxRadiance = 1e8f;
constexpr float kMaxTexcoord = 1e6f;
constexpr float kMaxCheckerScale = 1e6f;
constexpr float kMaxTransformScale = 1e6f;
constexpr float kMaxAngleDeg = 1e6f;  // rotations (degrees): any finite angle works, this keeps sin/cos exact enough
constexpr int kMaxFaceVertices = 1024;  // an OBJ face (tinyobjloader's ear clipping is quadratic in it)
// Largest radiance one path sample may carry into a pixel's running mean and variance (a
// grazing-angle pdf can still amplify a bounded emitter): its square stays far from float's limit.
constexpr float kMaxSampleRadiance = 1e12f;

struct ValueRule {
    float lo, hi;
    const char* text;  // how the rule reads in a message: "must be in [0, 1]"
};

constexpr ValueRule kCoordinateRule{-kMaxSceneCoordinate, kMaxSceneCoordinate, "must be finite and within +-1e9"};
constexpr ValueRule kRadianceRule{0.0f, kMaxRadiance, "must be in [0, 1e8]"};
constexpr ValueRule kReflectanceRule{0.0f, 1.0f, "must be in [0, 1]"};
constexpr ValueRule kScaleRule{0.0f, kMaxRadiance, "must be in [0, 1e8]"};  // a light's "scale"
constexpr ValueRule kTransformScaleRule{-kMaxTransformScale, kMaxTransformScale, "must be non-zero and within +-1e6"};
constexpr ValueRule kAngleRule{-kMaxAngleDeg, kMaxAngleDeg, "must be finite and within +-1e6 degrees"};
constexpr ValueRule kTexcoordRule{-kMaxTexcoord, kMaxTexcoord, "must be finite and within +-1e6"};
constexpr ValueRule kCheckerScaleRule{0.0f, kMaxCheckerScale, "must be in (0, 1e6]"};  // and > 0
constexpr ValueRule kRoughnessRule{0.0f, 1.0f, "must be in [0, 1]"};
constexpr ValueRule kIorRule{1.0f, 4.0f, "must be in [1, 4]"};
constexpr ValueRule kAnyFiniteRule{-3.0e38f, 3.0e38f, "must be finite"};

// True when v is finite and within the rule's closed range (false for NaN and ±Inf).
inline bool allowed(const ValueRule& r, double v) { return std::isfinite(v) && v >= r.lo && v <= r.hi; }

// "12", "1e+39", "nan": the value as a message shows it.
inline std::string formatValue(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

}  // namespace atrous::pt

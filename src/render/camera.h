// Pinhole camera (look-at, vertical field of view), shared by host and device.
#pragma once
#include "atrous/math.h"
#include "render/scene_data.h"

namespace atrous::pt {

// Builds a camera at `eye` looking at `target`; fovDeg is the vertical field of view in degrees.
inline Camera makeLookAtCamera(Vec3 eye, Vec3 target, Vec3 up, float fovDeg) {
    Camera c;
    c.position = eye;
    c.forward = normalize(target - eye);
    c.right = normalize(cross(c.forward, up));
    c.up = cross(c.right, c.forward);
    c.tanHalfFov = tanf(0.5f * fovDeg * kPi / 180.0f);
    return c;
}

// Unit direction of the ray through image position (px, py) in pixels (origin top-left,
// (x + 0.5, y + 0.5) is the centre of pixel (x, y)).
ATROUS_INLINE Vec3 cameraRayDirection(const Camera& c, float px, float py, int width, int height) {
    float aspect = float(width) / float(height);
    float sx = (2.0f * px / float(width) - 1.0f) * c.tanHalfFov * aspect;
    float sy = (1.0f - 2.0f * py / float(height)) * c.tanHalfFov;
    return normalize(c.forward + c.right * sx + c.up * sy);
}

// Inverse of cameraRayDirection: the image position (pixels) where the ray along `offset` (a point
// minus the camera position, or a direction for points at infinity) crosses the image. False when
// it is not in front of the camera.
ATROUS_INLINE bool projectToImage(const Camera& c, Vec3 offset, int width, int height, float& px, float& py) {
    float z = dot(offset, c.forward);
    if (!(z > 1e-6f * length(offset))) return false;
    float aspect = float(width) / float(height);
    float sx = dot(offset, c.right) / (z * c.tanHalfFov * aspect);
    float sy = dot(offset, c.up) / (z * c.tanHalfFov);
    px = 0.5f * (sx + 1.0f) * float(width);
    py = 0.5f * (1.0f - sy) * float(height);
    return true;
}

}  // namespace atrous::pt

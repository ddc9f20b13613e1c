// The viewer's orbit camera (view_pipeline.h, OrbitCamera).
#include <algorithm>
#include <cmath>

#include "atrous/view_pipeline.h"
#include "render/camera.h"

namespace atrous::view {

namespace {
constexpr float kPi = 3.14159265358979f;
}

OrbitCamera OrbitCamera::fromCamera(const pt::Camera& c, float pivotDistance) {
    OrbitCamera o;
    o.distance = std::max(pivotDistance, 1e-3f);
    o.target = c.position + c.forward * o.distance;
    const Vec3 off = c.position - o.target;
    o.yaw = std::atan2(off.x, off.z);
    o.pitch = std::asin(std::clamp(off.y / o.distance, -1.0f, 1.0f));
    o.tanHalfFov = c.tanHalfFov;
    return o;
}

pt::Camera OrbitCamera::camera() const {
    const Vec3 off(std::cos(pitch) * std::sin(yaw), std::sin(pitch),
                   std::cos(pitch) * std::cos(yaw));
    pt::Camera c = pt::makeLookAtCamera(target + off * distance, target, Vec3(0, 1, 0), 45.0f);
    c.tanHalfFov = tanHalfFov;
    return c;
}

void OrbitCamera::orbit(float dYaw, float dPitch) {
    yaw += dYaw;
    // Short of the poles, where the look-at basis (world up) degenerates.
    const float limit = 89.0f * kPi / 180.0f;
    pitch = std::clamp(pitch + dPitch, -limit, limit);
}

void OrbitCamera::pan(const pt::Camera& c, float right, float up, float forward) {
    target += c.right * right + c.up * up + c.forward * forward;
}

void OrbitCamera::zoom(float factor) {
    distance = std::clamp(distance * factor, 1e-3f, 1e6f);
}

}  // namespace atrous::view

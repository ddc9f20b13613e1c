// Animation of scenes over time t in [0, 1] (docs/scenes.md, "Animation"): the camera on a path
// (static, orbit, dolly, keyframes) and rigid per-mesh motion, plus what motion vectors need (the
// previous frame's camera and per-mesh current-to-previous maps). Host only.
#pragma once
#include <memory>
#include <vector>

#include "atrous/render.h"
#include "render/scene_data.h"

namespace atrous::pt {

// Orbit paths sweep this many degrees in all (half each side of the rest pose, reached at t = 1/2).
constexpr float kOrbitSweepDeg = 20.0f;
// Dolly paths move towards the target by this fraction of the camera-target distance.
constexpr float kDollyFraction = 0.25f;

// The camera at time t on `path` (Auto resolved as documented). InputError for Keyframes on a
// scene without keyframes.
Camera cameraAtTime(const SceneData& scene, CameraPath path, float t);

// Row-major 3x4 affine maps, 12 floats per mesh id: a point of mesh m at time t maps to where it
// was at time tPrev (identity for static meshes).
std::vector<float> meshToPrevious(const SceneData& scene, float t, float tPrev);

// A copy of `scene` posed at time t: moving meshes and spheres moved, camera on `path`.
std::shared_ptr<SceneData> poseScene(const SceneData& scene, CameraPath path, float t);

// Uniform Catmull-Rom interpolation through p0..p3 at u in [0, 1] between p1 and p2.
inline Vec3 catmullRom(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, float u) {
    float u2 = u * u, u3 = u2 * u;
    return (p1 * 2.0f + (p2 - p0) * u + (p0 * 2.0f - p1 * 5.0f + p2 * 4.0f - p3) * u2 +
            (p1 * 3.0f - p0 - p2 * 3.0f + p3) * u3) *
           0.5f;
}

}  // namespace atrous::pt

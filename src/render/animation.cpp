// Scene animation: camera paths and rigid mesh motion (src/render/animation.h).
#include "render/animation.h"

#include <cmath>

#include "atrous/error.h"
#include "render/camera.h"

namespace atrous {
namespace pt {
namespace {

// Rotation about +y by `a` radians (the same convention as JSON "rotateY").
Vec3 rotateY(Vec3 p, float a) {
    float cs = std::cos(a), sn = std::sin(a);
    return Vec3(cs * p.x + sn * p.z, p.y, -sn * p.x + cs * p.z);
}

CameraPath resolve(const SceneData& s, CameraPath path) {
    if (path == CameraPath::Auto) return s.cameraKeys.empty() ? CameraPath::Static : CameraPath::Keyframes;
    return path;
}

Camera keyframedCamera(const std::vector<CameraKey>& k, float t) {
    const size_t n = k.size();
    if (n == 1 || t <= k.front().t) return makeLookAtCamera(k.front().position, k.front().target, k.front().up, k.front().fovDeg);
    if (t >= k.back().t) return makeLookAtCamera(k.back().position, k.back().target, k.back().up, k.back().fovDeg);
    size_t i = 0;
    while (i + 2 < n && t > k[i + 1].t) ++i;
    float u = (t - k[i].t) / (k[i + 1].t - k[i].t);
    // Missing outer neighbours are mirrored (p[-1] = 2 p0 - p1), which keeps the ends natural.
    auto point = [&](long j, Vec3 CameraKey::*field) -> Vec3 {
        if (j < 0) return k[0].*field * 2.0f - k[1].*field;
        if (j >= long(n)) return k[n - 1].*field * 2.0f - k[n - 2].*field;
        return k[size_t(j)].*field;
    };
    long a = long(i);
    Vec3 pos = catmullRom(point(a - 1, &CameraKey::position), point(a, &CameraKey::position),
                          point(a + 1, &CameraKey::position), point(a + 2, &CameraKey::position), u);
    Vec3 target = catmullRom(point(a - 1, &CameraKey::target), point(a, &CameraKey::target),
                             point(a + 1, &CameraKey::target), point(a + 2, &CameraKey::target), u);
    Vec3 up = normalize(k[i].up * (1.0f - u) + k[i + 1].up * u);
    // Smoothstep on the field of view: no kink at the keys.
    float s = u * u * (3.0f - 2.0f * u);
    float fov = k[i].fovDeg * (1.0f - s) + k[i + 1].fovDeg * s;
    return makeLookAtCamera(pos, target, up, fov);
}

// The map taking a rest-pose point of a mesh with motion `m` to its place at time t.
struct Rigid {
    float angle = 0.0f;  // radians about +y through pivot
    Vec3 pivot, translate;
    Vec3 apply(Vec3 p) const { return rotateY(p - pivot, angle) + pivot + translate; }
    Vec3 applyInverse(Vec3 q) const { return rotateY(q - pivot - translate, -angle) + pivot; }
};

Rigid rigidAt(const MeshMotion& m, float t) {
    Rigid r;
    r.angle = m.rotateYDeg * t * kPi / 180.0f;
    r.pivot = m.pivot;
    r.translate = m.translate * t;
    return r;
}

}  // namespace

Camera cameraAtTime(const SceneData& s, CameraPath path, float t) {
    switch (resolve(s, path)) {
        case CameraPath::Keyframes:
            if (s.cameraKeys.empty())
                throw ParamError("camera_path", "camera_path", "cannot be keyframes: scene \"" + s.name + "\" has no \"camera.keyframes\"");
            return keyframedCamera(s.cameraKeys, t);
        case CameraPath::Orbit: {
            // A rigid turn of the whole camera frame about the vertical axis through the target,
            // so t = 1/2 is exactly the rest camera.
            float a = (t - 0.5f) * kOrbitSweepDeg * kPi / 180.0f;
            Camera c = s.camera;
            Vec3 pivot(s.cameraTarget.x, 0.0f, s.cameraTarget.z);
            c.position = rotateY(s.camera.position - pivot, a) + pivot;
            c.forward = rotateY(s.camera.forward, a);
            c.right = rotateY(s.camera.right, a);
            c.up = rotateY(s.camera.up, a);
            return c;
        }
        case CameraPath::Dolly: {
            Camera c = s.camera;
            float dist = length(s.cameraTarget - s.camera.position);
            c.position = s.camera.position + s.camera.forward * (kDollyFraction * dist * t);
            return c;
        }
        default:
            return s.camera;
    }
}

std::vector<float> meshToPrevious(const SceneData& s, float t, float tPrev) {
    const size_t meshes = s.meshNames.size();
    std::vector<float> m(12 * meshes, 0.0f);
    for (size_t i = 0; i < meshes; ++i) {
        float* r = m.data() + 12 * i;
        if (i >= s.meshMotion.size() || !s.meshMotion[i].moving()) {
            r[0] = r[5] = r[10] = 1.0f;
            continue;
        }
        Rigid now = rigidAt(s.meshMotion[i], t), prev = rigidAt(s.meshMotion[i], tPrev);
        // prev.apply(now.applyInverse(q)) is affine: its columns are the images of the unit
        // vectors minus the image of the origin.
        auto f = [&](Vec3 q) { return prev.apply(now.applyInverse(q)); };
        Vec3 o = f(Vec3(0.0f)), ex = f(Vec3(1, 0, 0)) - o, ey = f(Vec3(0, 1, 0)) - o, ez = f(Vec3(0, 0, 1)) - o;
        const Vec3 col[3] = {ex, ey, ez};
        for (int row = 0; row < 3; ++row) {
            for (int c = 0; c < 3; ++c) r[4 * row + c] = col[c][row];
            r[4 * row + 3] = o[row];
        }
    }
    return m;
}

std::shared_ptr<SceneData> poseScene(const SceneData& s, CameraPath path, float t) {
    if (s.posed) throw InputError("scene \"" + s.name + "\": already posed at a time (pose the scene as loaded)");
    auto d = std::make_shared<SceneData>(s);
    d->camera = cameraAtTime(s, path, t);
    d->posed = true;
    bool anyMoving = false;
    for (const MeshMotion& m : s.meshMotion) anyMoving = anyMoving || m.moving();
    if (anyMoving) {
        std::vector<char> done(d->positions.size(), 0);
        for (size_t tri = 0; tri < d->triMesh.size(); ++tri) {
            int mesh = d->triMesh[tri];
            if (mesh < 0 || size_t(mesh) >= s.meshMotion.size() || !s.meshMotion[mesh].moving()) continue;
            Rigid r = rigidAt(s.meshMotion[mesh], t);
            for (int k = 0; k < 3; ++k) {
                uint32_t v = d->indices[3 * tri + k];
                if (done[v]) continue;
                done[v] = 1;
                d->positions[v] = r.apply(d->positions[v]);
                Vec3 n = d->normals[v];
                if (n.x != 0.0f || n.y != 0.0f || n.z != 0.0f) d->normals[v] = rotateY(n, r.angle);
            }
        }
        for (Sphere& sp : d->spheres)
            if (sp.mesh >= 0 && size_t(sp.mesh) < s.meshMotion.size() && s.meshMotion[sp.mesh].moving())
                sp.center = rigidAt(s.meshMotion[sp.mesh], t).apply(sp.center);
    }
    // Ray offsets scale with the scene radius: grow it to cover the moved geometry and camera.
    Vec3 lo(1e30f), hi(-1e30f);
    for (const Vec3& p : d->positions) { lo = minv(lo, p); hi = maxv(hi, p); }
    for (const Sphere& sp : d->spheres) { lo = minv(lo, sp.center - Vec3(sp.radius)); hi = maxv(hi, sp.center + Vec3(sp.radius)); }
    lo = minv(lo, d->camera.position);
    hi = maxv(hi, d->camera.position);
    d->sceneRadius = maxf(s.sceneRadius, 0.5f * length(hi - lo));
    return d;
}

}  // namespace pt

CameraPath parseCameraPath(const std::string& name) {
    if (name == "auto") return CameraPath::Auto;
    if (name == "static") return CameraPath::Static;
    if (name == "orbit") return CameraPath::Orbit;
    if (name == "dolly") return CameraPath::Dolly;
    if (name == "keyframes") return CameraPath::Keyframes;
    throw ParamError("camera_path", "camera_path", "must be auto, static, orbit, dolly or keyframes", "'" + name + "'");
}

bool Scene::hasCameraKeyframes() const { return !data().cameraKeys.empty(); }

bool Scene::hasMovingObjects() const {
    for (const pt::MeshMotion& m : data().meshMotion)
        if (m.moving()) return true;
    return false;
}

Scene Scene::atTime(float t, CameraPath path) const { return Scene(pt::poseScene(data(), path, t)); }

}  // namespace atrous

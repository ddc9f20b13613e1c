// CPU backend of the path tracer: Embree 3 builds the BVH and answers the ray queries, TBB runs
// the per-pixel kernel (src/render/integrator.h) over 8x8 tiles. Nothing but the intersection
// calls is CPU-specific.
#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>

#include "atrous/error.h"
#include "atrous/render.h"
#include "render/animation.h"
#include "render/bvh_render.h"
#include "render/integrator.h"
#include "render/scene_data.h"

namespace atrous {
namespace {

using pt::Hit;
using pt::HitKind;
using pt::SceneData;
using pt::Sphere;

// Geometry ids inside the Embree scene.
constexpr unsigned kTriangleGeom = 0;
constexpr unsigned kSphereGeom = 1;

RTCDevice sharedDevice() {
    static std::once_flag once;
    static RTCDevice device = nullptr;
    std::call_once(once, [] { device = rtcNewDevice(nullptr); });
    if (!device) throw RuntimeError("Embree: cannot create a device (" + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    return device;
}

// Spheres are Embree user geometry with our own intersection routine (render/lights.h), which
// the GPU traversal can share, rather than RTC_GEOMETRY_TYPE_SPHERE_POINT.
void sphereBounds(const RTCBoundsFunctionArguments* args) {
    const Sphere& s = static_cast<const Sphere*>(args->geometryUserPtr)[args->primID];
    RTCBounds* b = args->bounds_o;
    b->lower_x = s.center.x - s.radius;
    b->lower_y = s.center.y - s.radius;
    b->lower_z = s.center.z - s.radius;
    b->upper_x = s.center.x + s.radius;
    b->upper_y = s.center.y + s.radius;
    b->upper_z = s.center.z + s.radius;
}

void sphereIntersect(const RTCIntersectFunctionNArguments* args) {
    const Sphere& s = static_cast<const Sphere*>(args->geometryUserPtr)[args->primID];
    RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
    RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        Vec3 o(RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i), RTCRayN_org_z(ray, args->N, i));
        Vec3 d(RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i), RTCRayN_dir_z(ray, args->N, i));
        float t = pt::intersectSphere(s.center, s.radius, o, d, RTCRayN_tnear(ray, args->N, i),
                                          RTCRayN_tfar(ray, args->N, i));
        if (t < 0.0f) continue;
        Vec3 n = o + d * t - s.center;
        RTCRayN_tfar(ray, args->N, i) = t;
        RTCHitN_Ng_x(hit, args->N, i) = n.x;
        RTCHitN_Ng_y(hit, args->N, i) = n.y;
        RTCHitN_Ng_z(hit, args->N, i) = n.z;
        RTCHitN_u(hit, args->N, i) = 0.0f;
        RTCHitN_v(hit, args->N, i) = 0.0f;
        RTCHitN_primID(hit, args->N, i) = args->primID;
        RTCHitN_geomID(hit, args->N, i) = args->geomID;
        RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
    }
}

void sphereOccluded(const RTCOccludedFunctionNArguments* args) {
    const Sphere& s = static_cast<const Sphere*>(args->geometryUserPtr)[args->primID];
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        RTCRayN* ray = args->ray;
        Vec3 o(RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i), RTCRayN_org_z(ray, args->N, i));
        Vec3 d(RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i), RTCRayN_dir_z(ray, args->N, i));
        float t = pt::intersectSphere(s.center, s.radius, o, d, RTCRayN_tnear(ray, args->N, i),
                                          RTCRayN_tfar(ray, args->N, i));
        if (t >= 0.0f) RTCRayN_tfar(ray, args->N, i) = -INFINITY;
    }
}

// Owns the Embree scene built over SceneData's arrays (which must outlive it).
class EmbreeScene {
public:
    explicit EmbreeScene(const SceneData& data) {
        RTCDevice device = sharedDevice();
        mScene = rtcNewScene(device);
        rtcSetSceneFlags(mScene, RTC_SCENE_FLAG_NONE);
        rtcSetSceneBuildQuality(mScene, RTC_BUILD_QUALITY_HIGH);
        if (!data.triMaterial.empty()) {
            RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
            rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
            // Copies (rtcSetNewGeometryBuffer pads them as Embree's SIMD loads need).
            auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), data.positions.size()));
            for (size_t i = 0; i < data.positions.size(); ++i) {
                v[3 * i + 0] = data.positions[i].x;
                v[3 * i + 1] = data.positions[i].y;
                v[3 * i + 2] = data.positions[i].z;
            }
            auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                       3 * sizeof(uint32_t), data.triMaterial.size()));
            std::copy(data.indices.begin(), data.indices.end(), idx);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(mScene, g, kTriangleGeom);
            rtcReleaseGeometry(g);
        }
        if (!data.spheres.empty()) {
            RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
            rtcSetGeometryUserPrimitiveCount(g, unsigned(data.spheres.size()));
            rtcSetGeometryUserData(g, const_cast<Sphere*>(data.spheres.data()));
            rtcSetGeometryBoundsFunction(g, sphereBounds, nullptr);
            rtcSetGeometryIntersectFunction(g, sphereIntersect);
            rtcSetGeometryOccludedFunction(g, sphereOccluded);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(mScene, g, kSphereGeom);
            rtcReleaseGeometry(g);
        }
        rtcCommitScene(mScene);
        RTCError err = rtcGetDeviceError(device);
        if (err != RTC_ERROR_NONE) {
            rtcReleaseScene(mScene);
            throw RuntimeError("Embree: scene build failed (error " + std::to_string(int(err)) + ")");
        }
    }
    ~EmbreeScene() { rtcReleaseScene(mScene); }
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;
    RTCScene handle() const { return mScene; }

private:
    RTCScene mScene = nullptr;
};

// The Tracer the integrator calls: rtcIntersect1 / rtcOccluded1 on one ray.
struct EmbreeTracer {
    RTCScene scene = nullptr;

    bool intersect(Vec3 o, Vec3 d, float tmax, Hit& hit) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh;
        rh.ray.org_x = o.x;
        rh.ray.org_y = o.y;
        rh.ray.org_z = o.z;
        rh.ray.tnear = 0.0f;
        rh.ray.dir_x = d.x;
        rh.ray.dir_y = d.y;
        rh.ray.dir_z = d.z;
        rh.ray.time = 0.0f;
        rh.ray.tfar = tmax;
        rh.ray.mask = 0xffffffffu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
        hit.kind = rh.hit.geomID == kTriangleGeom ? HitKind::Triangle : HitKind::Sphere;
        hit.prim = int32_t(rh.hit.primID);
        hit.t = rh.ray.tfar;
        hit.u = rh.hit.u;
        hit.v = rh.hit.v;
        return true;
    }

    bool occluded(Vec3 o, Vec3 d, float tmax) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRay ray;
        ray.org_x = o.x;
        ray.org_y = o.y;
        ray.org_z = o.z;
        ray.tnear = 0.0f;
        ray.dir_x = d.x;
        ray.dir_y = d.y;
        ray.dir_z = d.z;
        ray.time = 0.0f;
        ray.tfar = tmax;
        ray.mask = 0xffffffffu;
        ray.id = 0;
        ray.flags = 0;
        rtcOccluded1(scene, &ctx, &ray);
        return ray.tfar < 0.0f;
    }
};

// `motion` == nullptr: a still image (no motion buffer).
RenderBuffers renderImpl(const Scene& scene, const RenderSettings& settings, const pt::MotionReprojection* motion) {
    validateRenderSettings(settings);
    const SceneData& data = scene.data();
    RenderBuffers b = detail::allocateRenderBuffers(settings.width, settings.height, Device::Cpu);
    if (motion) b.motion = Image(settings.width, settings.height, 3);

    EmbreeScene embree(data);
    EmbreeTracer tracer;
    tracer.scene = embree.handle();
    auto k = detail::makePathTraceKernel(data.view(), tracer, b, settings);
    if (motion) {
        k.out.motion = b.motion.view();
        k.motion = *motion;
    }
    detail::runPathTraceTiles(k, settings);
    return b;
}

}  // namespace

RenderBuffers render(const Scene& scene, const RenderSettings& settings) { return renderImpl(scene, settings, nullptr); }

RenderBuffers renderFrame(const Scene& scene, CameraPath path, float t, float tPrev, const RenderSettings& settings) {
    validateRenderSettings(settings);
    Scene posed = scene.atTime(t, path);
    std::vector<float> toPrev = pt::meshToPrevious(scene.data(), t, tPrev);
    pt::MotionReprojection m;
    m.enabled = true;
    m.previousCamera = pt::cameraAtTime(scene.data(), path, tPrev);
    m.meshToPrevious = toPrev.data();
    m.numMeshes = int32_t(scene.data().meshNames.size());
    return renderImpl(posed, settings, &m);
}

}  // namespace atrous

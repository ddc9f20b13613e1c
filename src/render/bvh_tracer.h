// The path tracer's Tracer (src/render/integrator.h) over the flattened BVH of src/render/bvh.h:
// what the CUDA renderer plugs into pt::PathTraceKernel, and what the CPU tests plug in to
// compare it with the Embree tracer. Host/device code, no STL in the tracer itself.
#pragma once
#include <cstdint>
#include <vector>

#include "render/bvh.h"
#include "render/bvh_build.h"
#include "render/lights.h"
#include "render/scene_data.h"

namespace atrous::pt {

struct BvhTracer {
    BvhView bvh;
    int32_t numTriangles = 0;  // BVH prim ids: triangles first, then spheres

    // Nearest hit in [0, tmax) (the integrator offsets ray origins, so t = 0 never repeats a hit).
    ATROUS_HOST_DEVICE bool intersect(Vec3 o, Vec3 d, float tmax, Hit& hit) const {
        BvhHit h = ::atrous::intersect(bvh, BvhRay{o, d}, 0.0f, tmax);
        if (!h.hit()) return false;
        bool tri = h.primId < numTriangles;
        hit.kind = tri ? HitKind::Triangle : HitKind::Sphere;
        hit.prim = tri ? h.primId : h.primId - numTriangles;
        hit.t = h.t;
        hit.u = h.u;
        hit.v = h.v;
        return true;
    }
    ATROUS_HOST_DEVICE bool occluded(Vec3 o, Vec3 d, float tmax) const {
        return ::atrous::occluded(bvh, BvhRay{o, d}, 0.0f, tmax);
    }
};

static_assert(sizeof(Vec3) == 3 * sizeof(float), "positions are passed to the BVH builder as packed floats");

// Builds the BVH over a scene's triangles and spheres (host only).
inline BvhData buildSceneBvh(const SceneData& data, const BvhBuildOptions& options = {}) {
    std::vector<float> spheres;
    spheres.reserve(data.spheres.size() * 4);
    for (const Sphere& s : data.spheres) spheres.insert(spheres.end(), {s.center.x, s.center.y, s.center.z, s.radius});
    BvhBuildInput in;
    in.positions = reinterpret_cast<const float*>(data.positions.data());
    in.vertexCount = data.positions.size();
    in.indices = data.indices.data();
    in.triangleCount = data.triMaterial.size();
    in.spheres = spheres.data();
    in.sphereCount = data.spheres.size();
    return buildBvh(in, options);
}

inline BvhTracer makeBvhTracer(const BvhView& view, const SceneData& data) {
    BvhTracer t;
    t.bvh = view;
    t.numTriangles = int32_t(data.triMaterial.size());
    return t;
}

}  // namespace atrous::pt

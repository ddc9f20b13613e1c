// Geometry queries and light sampling shared by host and device: analytic sphere intersection,
// surface interactions from a hit record, ray-origin offsets, area / point / environment lights.
#pragma once
#include "atrous/math.h"
#include "render/sampling.h"
#include "render/scene_data.h"

namespace atrous::pt {

constexpr float kRayInfinity = 1e30f;

enum class HitKind : int32_t { None = 0, Triangle = 1, Sphere = 2 };

// What the intersector reports: enough to rebuild the surface (triangle barycentrics u, v for
// p = (1-u-v) v0 + u v1 + v v2, as Embree reports them).
struct Hit {
    HitKind kind = HitKind::None;
    int32_t prim = -1;
    float t = kRayInfinity;
    float u = 0.0f, v = 0.0f;
};

// Nearest ray parameter t in (tmin, tmax) where o + t d (d unit) meets the sphere, or -1.
// Uses the numerically careful form of Haines et al., Ray Tracing Gems ch. 7, so grazing and
// far-away hits keep their precision.
ATROUS_INLINE float intersectSphere(Vec3 center, float radius, Vec3 o, Vec3 d, float tmin, float tmax) {
    Vec3 f = o - center;
    float b = -dot(f, d);
    Vec3 l = f + d * b;
    float disc = radius * radius - dot(l, l);
    if (disc < 0.0f) return -1.0f;
    float c = dot(f, f) - radius * radius;
    float q = b + (b >= 0.0f ? sqrtf(disc) : -sqrtf(disc));
    float t0 = q != 0.0f ? c / q : 0.0f, t1 = q;
    if (t0 > t1) { float tmp = t0; t0 = t1; t1 = tmp; }
    if (t0 > tmin && t0 < tmax) return t0;
    if (t1 > tmin && t1 < tmax) return t1;
    return -1.0f;
}

struct SurfaceInteraction {
    Vec3 p;
    Vec3 ng;  // geometric normal as stored (outward for spheres, winding order for triangles)
    Vec3 ns;  // shading normal, in ng's hemisphere
    Vec2 uv;
    int32_t material = 0;
    int32_t mesh = 0;
    int32_t light = -1;  // light index when this is an emissive triangle
};

ATROUS_INLINE SurfaceInteraction surfaceAt(const SceneView& s, const Hit& hit, Vec3 o, Vec3 d) {
    SurfaceInteraction si;
    if (hit.kind == HitKind::Sphere) {
        const Sphere& sp = s.spheres[hit.prim];
        Vec3 p = o + d * hit.t;
        Vec3 n = normalize(p - sp.center);
        si.p = sp.center + n * sp.radius;  // re-project onto the surface
        si.ng = n;
        si.ns = n;
        si.uv = Vec2(atan2f(n.z, n.x) * (0.5f * kInvPi) + 0.5f, 1.0f - acosf(clampf(n.y, -1.0f, 1.0f)) * kInvPi);
        si.material = sp.material;
        si.mesh = sp.mesh;
        return si;
    }
    const uint32_t* idx = s.indices + 3 * size_t(hit.prim);
    Vec3 p0 = s.positions[idx[0]], p1 = s.positions[idx[1]], p2 = s.positions[idx[2]];
    float b1 = hit.u, b2 = hit.v, b0 = 1.0f - b1 - b2;
    si.p = p0 * b0 + p1 * b1 + p2 * b2;
    si.ng = normalize(cross(p1 - p0, p2 - p0));
    Vec3 ns = s.normals[idx[0]] * b0 + s.normals[idx[1]] * b1 + s.normals[idx[2]] * b2;
    float nl = length(ns);
    si.ns = nl > 1e-6f ? ns / nl : si.ng;
    if (dot(si.ns, si.ng) < 0.0f) si.ns = -si.ns;
    Vec2 t0 = s.uvs[idx[0]], t1 = s.uvs[idx[1]], t2 = s.uvs[idx[2]];
    si.uv = Vec2(t0.x * b0 + t1.x * b1 + t2.x * b2, t0.y * b0 + t1.y * b1 + t2.y * b2);
    si.material = s.triMaterial[hit.prim];
    si.mesh = s.triMesh[hit.prim];
    si.light = s.triLight[hit.prim];
    return si;
}

// Moves a ray origin off the surface to the side `dir` leaves toward, so the new ray does not
// hit the surface it starts on. The offset scales with the coordinates' magnitude (float spacing).
ATROUS_INLINE Vec3 offsetRayOrigin(Vec3 p, Vec3 ng, Vec3 dir) {
    float scale = maxf(1.0f, maxf(fabsf(p.x), maxf(fabsf(p.y), fabsf(p.z))));
    float eps = 1e-4f * scale;
    return dot(ng, dir) >= 0.0f ? p + ng * eps : p - ng * eps;
}

ATROUS_INLINE float lightPmf(const SceneView& s, int i) {
    return (i >= 0 && i < s.numLights) ? s.lightCdf[i + 1] - s.lightCdf[i] : 0.0f;
}

ATROUS_INLINE float triangleArea(const SceneView& s, int tri) {
    const uint32_t* idx = s.indices + 3 * size_t(tri);
    return 0.5f * length(cross(s.positions[idx[1]] - s.positions[idx[0]], s.positions[idx[2]] - s.positions[idx[0]]));
}

// Solid-angle pdf of sampleLight picking the point seen at distance `dist` along a ray that hit
// emissive triangle light `light` (the light-selection probability included).
ATROUS_INLINE float triangleLightPdf(const SceneView& s, int light, const SurfaceInteraction& si, Vec3 dir, float dist) {
    float cosL = fabsf(dot(si.ng, dir));
    if (cosL <= 0.0f) return 0.0f;
    return lightPmf(s, light) * dist * dist / (cosL * triangleArea(s, s.lights[light].triangle));
}

struct LightSample {
    Vec3 wi;        // unit, toward the light
    float dist = 0; // distance to the light point (kRayInfinity for the environment)
    Vec3 li;        // incident radiance (point light: intensity / dist^2)
    float pdf = 0;  // solid angle, selection included (point light: selection probability)
    bool delta = false;
    bool valid = false;
};

// Picks a light proportionally to its power (u0), then a point/direction on it (u1, u2).
ATROUS_INLINE LightSample sampleLight(const SceneView& s, Vec3 p, float u0, float u1, float u2) {
    LightSample ls;
    if (s.numLights <= 0) return ls;
    int i = findSegment(s.lightCdf, s.numLights, u0);
    float pmf = lightPmf(s, i);
    if (pmf <= 0.0f) return ls;
    const Light& l = s.lights[i];
    if (l.type == LightType::Triangle) {
        const uint32_t* idx = s.indices + 3 * size_t(l.triangle);
        Vec3 p0 = s.positions[idx[0]], p1 = s.positions[idx[1]], p2 = s.positions[idx[2]];
        float b1, b2;
        uniformTriangle(u1, u2, b1, b2);
        Vec3 q = p0 * (1.0f - b1 - b2) + p1 * b1 + p2 * b2;
        Vec3 c = cross(p1 - p0, p2 - p0);
        float area2 = length(c);
        if (area2 <= 0.0f) return ls;
        Vec3 n = c / area2;
        Vec3 toL = q - p;
        float d2 = lengthSquared(toL);
        if (d2 <= 0.0f) return ls;
        ls.dist = sqrtf(d2);
        ls.wi = toL / ls.dist;
        float cosL = -dot(n, ls.wi);
        if (cosL <= 0.0f) return ls;  // one-sided emitters: we see the back
        ls.li = s.materials[s.triMaterial[l.triangle]].emission;
        ls.pdf = pmf * d2 / (cosL * 0.5f * area2);
        ls.valid = true;
    } else if (l.type == LightType::Point) {
        Vec3 toL = l.position - p;
        float d2 = lengthSquared(toL);
        if (d2 <= 0.0f) return ls;
        ls.dist = sqrtf(d2);
        ls.wi = toL / ls.dist;
        ls.li = l.intensity / d2;
        ls.pdf = pmf;
        ls.delta = true;
        ls.valid = true;
    } else {
        float pdf;
        if (!sampleEnv(s, u1, u2, ls.wi, pdf)) return ls;
        ls.dist = kRayInfinity;
        ls.li = envRadiance(s, ls.wi);
        ls.pdf = pmf * pdf;
        ls.valid = ls.pdf > 0.0f;
    }
    return ls;
}

}  // namespace atrous::pt

// Test geometry and rays shared by tests/bvh_test.cpp (CPU vs Embree) and tests/cuda/bvh_test.cu
// (GPU vs CPU). Everything is generated from fixed seeds, so every run sees the same rays.
#pragma once
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "render/bvh.h"
#include "render/bvh_build.h"

namespace atrous::test {

struct BvhScene {
    std::vector<float> positions;  // xyz per vertex
    std::vector<uint32_t> indices;  // 3 per triangle
    std::vector<float> spheres;     // cx cy cz r
    size_t triangleCount() const { return indices.size() / 3; }
    size_t sphereCount() const { return spheres.size() / 4; }
    BvhBuildInput input() const {
        BvhBuildInput in;
        in.positions = positions.data();
        in.vertexCount = positions.size() / 3;
        in.indices = indices.data();
        in.triangleCount = triangleCount();
        in.spheres = spheres.data();
        in.sphereCount = sphereCount();
        return in;
    }
    uint32_t addVertex(float x, float y, float z) {
        positions.insert(positions.end(), {x, y, z});
        return uint32_t(positions.size() / 3 - 1);
    }
    void addTriangle(uint32_t a, uint32_t b, uint32_t c) { indices.insert(indices.end(), {a, b, c}); }
    void addSphere(float x, float y, float z, float r) { spheres.insert(spheres.end(), {x, y, z, r}); }
    // Closed box (12 triangles sharing 8 vertices), rotated by `angle` about y around its center.
    void addBox(Vec3 center, Vec3 half, float angle) {
        float c = std::cos(angle), s = std::sin(angle);
        uint32_t v[8];
        for (int i = 0; i < 8; ++i) {
            float x = (i & 1 ? 1.f : -1.f) * half.x, y = (i & 2 ? 1.f : -1.f) * half.y, z = (i & 4 ? 1.f : -1.f) * half.z;
            v[i] = addVertex(center.x + c * x + s * z, center.y + y, center.z - s * x + c * z);
        }
        const int f[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
        for (auto& q : f) {
            addTriangle(v[q[0]], v[q[1]], v[q[2]]);
            addTriangle(v[q[0]], v[q[2]], v[q[3]]);
        }
    }
};

// A few thousand triangles of mixed sizes in [-1, 1]^3: mostly small, some large, some thin
// slivers, some degenerate (repeated vertex, collinear), one with a NaN vertex; plus spheres.
inline BvhScene makeSoupScene(uint32_t seed, int triangles = 3000, int spheres = 150) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f), u11(-1.0f, 1.0f);
    BvhScene s;
    for (int t = 0; t < triangles; ++t) {
        Vec3 c(u11(rng), u11(rng), u11(rng));
        float size = u01(rng) < 0.9f ? 0.02f + 0.1f * u01(rng) : 0.3f + 0.5f * u01(rng);
        Vec3 p[3];
        for (auto& q : p) q = c + Vec3(u11(rng), u11(rng), u11(rng)) * size;
        int kind = t % 50;
        if (kind == 1) p[2] = p[0];                                   // repeated vertex: zero area
        if (kind == 2) p[2] = p[0] + (p[1] - p[0]) * 0.37f;           // (nearly) collinear
        if (kind == 3) p[2] = p[0] + (p[1] - p[0]) * 0.5f + Vec3(1e-4f, -2e-4f, 1e-4f);  // sliver
        uint32_t a = s.addVertex(p[0].x, p[0].y, p[0].z);
        uint32_t b = s.addVertex(p[1].x, p[1].y, p[1].z);
        uint32_t d = s.addVertex(p[2].x, p[2].y, p[2].z);
        s.addTriangle(a, b, d);
    }
    // A small closed mesh with shared vertices, so rays also cross shared edges.
    s.addBox(Vec3(0.2f, -0.1f, 0.3f), Vec3(0.25f, 0.4f, 0.15f), 0.6f);
    // One triangle with a NaN vertex: never hit, left out of the BVH (Embree ignores it too).
    uint32_t n0 = s.addVertex(NAN, 0.0f, 0.0f), n1 = s.addVertex(0.1f, 0.1f, 0.1f), n2 = s.addVertex(0.2f, 0.0f, 0.1f);
    s.addTriangle(n0, n1, n2);
    for (int i = 0; i < spheres; ++i) s.addSphere(u11(rng), u11(rng), u11(rng), 0.01f + 0.1f * u01(rng));
    return s;
}

// A Cornell-box-like closed room [-1, 1]^3 (walls, floor, ceiling as shared-vertex quads), two
// rotated boxes, two spheres.
inline BvhScene makeCornellScene() {
    BvhScene s;
    s.addBox(Vec3(0.0f), Vec3(1.0f), 0.0f);
    s.addBox(Vec3(-0.35f, -0.4f, -0.3f), Vec3(0.3f, 0.6f, 0.3f), 0.3f);
    s.addBox(Vec3(0.4f, -0.7f, 0.35f), Vec3(0.3f, 0.3f, 0.3f), -0.3f);
    s.addSphere(0.45f, -0.15f, 0.35f, 0.25f);
    s.addSphere(-0.5f, 0.6f, 0.5f, 0.2f);
    return s;
}

struct TestRay {
    BvhRay ray;
    float tmax;  // for occlusion queries
};

// Rays from inside and outside the scene bounds [lo, hi]: random directions, one in five along
// an axis, one in five with a non-unit direction (length 0.3 .. 3).
inline std::vector<TestRay> makeRays(uint32_t seed, int count, Vec3 lo, Vec3 hi) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    Vec3 center = (lo + hi) * 0.5f, ext = hi - lo;
    float radius = length(ext);
    std::vector<TestRay> rays(static_cast<size_t>(count));
    for (auto& r : rays) {
        Vec3 inside(lo.x + ext.x * u01(rng), lo.y + ext.y * u01(rng), lo.z + ext.z * u01(rng));
        Vec3 dir = normalize(Vec3(gauss(rng), gauss(rng), gauss(rng)));
        int mode = int(u01(rng) * 10.0f);
        if (mode < 5) {
            r.ray.org = inside;
        } else {
            // Outside: on a sphere around the scene, aimed at a random inside point.
            Vec3 out = center + normalize(Vec3(gauss(rng), gauss(rng), gauss(rng))) * radius;
            r.ray.org = out;
            dir = normalize(inside - out);
        }
        int dirMode = int(u01(rng) * 5.0f);
        if (dirMode == 0) {
            int axis = int(u01(rng) * 3.0f) % 3;
            dir = Vec3(0.0f);
            dir[axis] = u01(rng) < 0.5f ? -1.0f : 1.0f;
        } else if (dirMode == 1) {
            dir = dir * (0.3f + 2.7f * u01(rng));
        }
        r.ray.dir = dir;
        r.tmax = u01(rng) < 0.5f ? INFINITY : 2.0f * radius * u01(rng) / length(dir);
    }
    return rays;
}

inline Vec3 sceneLo(const BvhView& v) { return Vec3(v.sceneLo[0], v.sceneLo[1], v.sceneLo[2]); }
inline Vec3 sceneHi(const BvhView& v) { return Vec3(v.sceneHi[0], v.sceneHi[1], v.sceneHi[2]); }

}  // namespace atrous::test

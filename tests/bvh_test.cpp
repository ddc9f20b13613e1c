// The GPU BVH's traversal (src/render/bvh.h), checked on the CPU against Embree's own
// rtcIntersect1 / rtcOccluded1 on the same geometry, plus the tree's structural invariants.
#include <embree3/rtcore.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "atrous/error.h"
#include "atrous/math.h"

// The traversal is compiled here for FMA hardware (x86-64-v3: what the library, which this test
// links and so needs anyway, and the benchmarks are built for), so that gcc may fuse a*b - c*d
// as it does there. Plain edge functions once broke watertightness exactly that way, and
// ClosedRoomHasNoCracks only sees it in such a build (the test target itself is baseline x86-64).
#pragma GCC push_options
#pragma GCC target("avx2,fma")
#include "render/bvh.h"
#pragma GCC pop_options

#include "bvh_scenes.h"
#include "render/bvh_build.h"

using namespace atrous;
using namespace atrous::test;

namespace {

// Embree's view of the same scene: triangles as geometry 0, spheres as geometry 1
// (RTC_GEOMETRY_TYPE_SPHERE_POINT). Robust mode makes Embree's triangle test watertight too.
class EmbreeScene {
public:
    explicit EmbreeScene(const BvhScene& s) : mTriangles(uint32_t(s.triangleCount())) {
        mDevice = rtcNewDevice(nullptr);
        mScene = rtcNewScene(mDevice);
        rtcSetSceneFlags(mScene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(mScene, RTC_BUILD_QUALITY_HIGH);
        if (s.triangleCount()) {
            RTCGeometry g = rtcNewGeometry(mDevice, RTC_GEOMETRY_TYPE_TRIANGLE);
            copyBuffer(g, RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3, 3 * sizeof(float), s.positions.size() / 3,
                       s.positions.data(), s.positions.size() * sizeof(float));
            copyBuffer(g, RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), s.triangleCount(),
                       s.indices.data(), s.indices.size() * sizeof(uint32_t));
            attach(g, 0);
        }
        if (s.sphereCount()) {
            RTCGeometry g = rtcNewGeometry(mDevice, RTC_GEOMETRY_TYPE_SPHERE_POINT);
            copyBuffer(g, RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT4, 4 * sizeof(float), s.sphereCount(),
                       s.spheres.data(), s.spheres.size() * sizeof(float));
            attach(g, 1);
        }
        rtcCommitScene(mScene);
    }
    ~EmbreeScene() {
        rtcReleaseScene(mScene);
        rtcReleaseDevice(mDevice);
    }
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    static RTCRay toRtc(const BvhRay& r, float tmin, float tmax) {
        RTCRay ray;
        ray.org_x = r.org.x, ray.org_y = r.org.y, ray.org_z = r.org.z;
        ray.dir_x = r.dir.x, ray.dir_y = r.dir.y, ray.dir_z = r.dir.z;
        ray.tnear = tmin;
        ray.tfar = tmax;
        ray.time = 0.0f;
        ray.mask = 0xFFFFFFFFu;
        ray.id = 0;
        ray.flags = 0;
        return ray;
    }
    BvhHit intersect(const BvhRay& r, float tmin, float tmax) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh;
        rh.ray = toRtc(r, tmin, tmax);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(mScene, &ctx, &rh);
        BvhHit h;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
        h.t = rh.ray.tfar;
        h.primId = int32_t(rh.hit.geomID == 0 ? rh.hit.primID : mTriangles + rh.hit.primID);
        h.u = rh.hit.u;
        h.v = rh.hit.v;
        return h;
    }
    bool occluded(const BvhRay& r, float tmin, float tmax) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRay ray = toRtc(r, tmin, tmax);
        rtcOccluded1(mScene, &ctx, &ray);
        return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
    }

private:
    // A new buffer of `count` items of `stride` bytes in slot 0 of g, filled with `bytes` from src.
    static void copyBuffer(RTCGeometry g, RTCBufferType type, RTCFormat format, size_t stride, size_t count,
                           const void* src, size_t bytes) {
        void* dst = rtcSetNewGeometryBuffer(g, type, 0, format, stride, count);
        std::memcpy(dst, src, bytes);
    }
    void attach(RTCGeometry g, unsigned id) {
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(mScene, g, id);
        rtcReleaseGeometry(g);
    }

    uint32_t mTriangles;
    RTCDevice mDevice = nullptr;
    RTCScene mScene = nullptr;
};

struct Agreement {
    int rays = 0, bothMiss = 0, same = 0, ties = 0, mismatches = 0, uvOff = 0, triHits = 0;
    int occlusionMismatches = 0, occlusionAmbiguous = 0;
};

// Compares our traversal with Embree on `rays`. Tolerance on t: relative 1e-4 (the brief's
// figure; both sides compute t to a few float ulps, ~1e-6 relative, except close to the origin,
// hence the absolute floor of 1e-6 of the scene's extent).
Agreement compareWithEmbree(const BvhScene& scene, const BvhData& bvh, const std::vector<TestRay>& rays) {
    EmbreeScene embree(scene);
    BvhView view = bvh.view();
    float extent = length(sceneHi(view) - sceneLo(view));
    auto close = [&](float a, float b) { return std::fabs(a - b) <= 1e-4f * std::max(std::fabs(b), 1e-2f * extent); };
    Agreement a;
    for (const TestRay& tr : rays) {
        ++a.rays;
        BvhHit ours = intersect(view, tr.ray, 0.0f, INFINITY);
        BvhHit ref = embree.intersect(tr.ray, 0.0f, INFINITY);
        if (!ours.hit() && !ref.hit()) {
            ++a.bothMiss;
        } else if (ours.hit() && ref.hit() && close(ours.t, ref.t)) {
            if (ours.primId == ref.primId) {
                ++a.same;
                if (size_t(ours.primId) < scene.triangleCount()) {
                    ++a.triHits;
                    // Barycentrics: both sides are ratios of float edge functions; 1e-3 absolute
                    // allows for the ill-conditioned slivers in the soup.
                    if (std::fabs(ours.u - ref.u) > 1e-3f || std::fabs(ours.v - ref.v) > 1e-3f) ++a.uvOff;
                }
            } else {
                ++a.ties;  // two primitives at the same distance (shared edge, crossing triangles)
            }
        } else {
            ++a.mismatches;
        }
        bool occOurs = occluded(view, tr.ray, 0.0f, tr.tmax);
        bool occRef = embree.occluded(tr.ray, 0.0f, tr.tmax);
        // Our any-hit query must agree with our closest-hit query exactly (same arithmetic).
        EXPECT_EQ(occOurs, intersect(view, tr.ray, 0.0f, tr.tmax).hit());
        if (occOurs != occRef) {
            // Only acceptable when the closest hit lies at tmax within the t tolerance.
            if (ref.hit() && close(ref.t, tr.tmax)) ++a.occlusionAmbiguous;
            else ++a.occlusionMismatches;
        }
    }
    return a;
}

// Walks the tree: every node reached once, every BvhPrim record in exactly one leaf, children's
// boxes inside their parent's box, leaf geometry inside its box, depth within the stack.
void checkInvariants(const BvhScene& scene, const BvhData& bvh) {
    BvhView v = bvh.view();
    ASSERT_NE(v.root, kBvhInvalidRef);
    std::vector<int> nodeSeen(v.nodeCount, 0), primSeen(v.primCount, 0);
    struct Item {
        uint32_t ref;
        float lo[3], hi[3];
        uint32_t depth;
    };
    std::vector<Item> todo{{v.root, {v.sceneLo[0], v.sceneLo[1], v.sceneLo[2]}, {v.sceneHi[0], v.sceneHi[1], v.sceneHi[2]}, 0}};
    uint32_t maxDepth = 0;
    auto inside = [](const float* lo, const float* hi, const float* plo, const float* phi) {
        for (int k = 0; k < 3; ++k)
            if (lo[k] < plo[k] || hi[k] > phi[k]) return false;
        return true;
    };
    while (!todo.empty()) {
        Item it = todo.back();
        todo.pop_back();
        maxDepth = std::max(maxDepth, it.depth);
        if (bvhIsLeaf(it.ref)) {
            uint32_t first = bvhLeafFirst(it.ref), count = bvhLeafCount(it.ref);
            ASSERT_LE(first + count, v.primCount);
            for (uint32_t i = first; i < first + count; ++i) {
                ++primSeen[i];
                const BvhPrim& p = v.prims[i];
                float lo[3], hi[3];
                if (p.kind == kBvhPrimTriangle) {
                    for (int k = 0; k < 3; ++k) {
                        lo[k] = std::min({p.a[k], p.b[k], p.c[k]});
                        hi[k] = std::max({p.a[k], p.b[k], p.c[k]});
                    }
                } else {
                    for (int k = 0; k < 3; ++k) lo[k] = p.a[k] - p.b[0], hi[k] = p.a[k] + p.b[0];
                }
                EXPECT_TRUE(inside(lo, hi, it.lo, it.hi)) << "prim " << p.primId << " outside its leaf box";
            }
            continue;
        }
        ASSERT_LT(it.ref, v.nodeCount);
        ++nodeSeen[it.ref];
        const BvhNode& n = v.nodes[it.ref];
        EXPECT_TRUE(inside(n.lo0, n.hi0, it.lo, it.hi)) << "node " << it.ref << " child 0 box outside parent";
        EXPECT_TRUE(inside(n.lo1, n.hi1, it.lo, it.hi)) << "node " << it.ref << " child 1 box outside parent";
        Item c0{n.child[0], {}, {}, it.depth + 1}, c1{n.child[1], {}, {}, it.depth + 1};
        std::copy(n.lo0, n.lo0 + 3, c0.lo), std::copy(n.hi0, n.hi0 + 3, c0.hi);
        std::copy(n.lo1, n.lo1 + 3, c1.lo), std::copy(n.hi1, n.hi1 + 3, c1.hi);
        todo.push_back(c0);
        todo.push_back(c1);
    }
    EXPECT_EQ(maxDepth, bvh.maxDepth);
    EXPECT_LT(maxDepth, uint32_t(kBvhStackSize));
    for (uint32_t i = 0; i < v.nodeCount; ++i) EXPECT_EQ(nodeSeen[i], 1) << "node " << i;
    for (uint32_t i = 0; i < v.primCount; ++i) EXPECT_EQ(primSeen[i], 1) << "prim record " << i;
    // Every hittable input primitive appears exactly once, with its own geometry.
    size_t total = scene.triangleCount() + scene.sphereCount();
    std::vector<int> idSeen(total, 0);
    for (uint32_t i = 0; i < v.primCount; ++i) {
        const BvhPrim& p = v.prims[i];
        ASSERT_LT(p.primId, total);
        ++idSeen[p.primId];
        if (p.primId < scene.triangleCount()) {
            ASSERT_EQ(p.kind, kBvhPrimTriangle);
            const uint32_t* tri = &scene.indices[3 * size_t(p.primId)];
            for (int k = 0; k < 3; ++k) {
                EXPECT_EQ(p.a[k], scene.positions[3 * tri[0] + k]);
                EXPECT_EQ(p.b[k], scene.positions[3 * tri[1] + k]);
                EXPECT_EQ(p.c[k], scene.positions[3 * tri[2] + k]);
            }
        } else {
            ASSERT_EQ(p.kind, kBvhPrimSphere);
            const float* s = &scene.spheres[4 * (p.primId - scene.triangleCount())];
            EXPECT_EQ(p.a[0], s[0]);
            EXPECT_EQ(p.b[0], s[3]);
        }
    }
    size_t referenced = 0;
    for (int c : idSeen) {
        EXPECT_LE(c, 1);
        referenced += size_t(c);
    }
    EXPECT_EQ(referenced + bvh.skippedPrims, total);
}

void reportAndBound(const Agreement& a, const char* what, int maxTies) {
    std::printf("%s: %d rays, %d both miss, %d same prim, %d ties, %d mismatches, %d/%d uv off, "
                "occlusion %d mismatches, %d at tmax\n",
                what, a.rays, a.bothMiss, a.same, a.ties, a.mismatches, a.uvOff, a.triHits, a.occlusionMismatches,
                a.occlusionAmbiguous);
    // Hit/miss or distance disagreements can only come from rays within float rounding of a
    // silhouette edge or a sphere's tangent: probability ~1e-6 per random ray. Bound: 1e-4.
    EXPECT_LE(a.mismatches, a.rays / 10000) << what;
    EXPECT_LE(a.occlusionMismatches, a.rays / 10000) << what;
    // Ties: a different primitive at the same t (both sides really hit their primitive there,
    // so a tie is never a wrong answer, only an ambiguous one). Bound set by the caller.
    EXPECT_LE(a.ties, maxTies) << what;
    EXPECT_LE(a.uvOff, a.triHits / 1000) << what;
    // The comparison is not vacuous: most rays hit something.
    EXPECT_GT(a.same, a.rays / 3) << what;
}

}  // namespace

TEST(Bvh, SoupMatchesEmbree) {
    BvhScene scene = makeSoupScene(7);
    BvhData bvh = buildBvh(scene.input());
    EXPECT_EQ(bvh.skippedPrims, 1u);  // the NaN triangle
    checkInvariants(scene, bvh);
    auto rays = makeRays(11, 40000, sceneLo(bvh.view()), sceneHi(bvh.view()));
    // Ties need two primitives meeting within 1e-4 of t at the hit point (shared edges, crossing
    // triangles): rare for random rays. Bound: 0.2% of the rays.
    reportAndBound(compareWithEmbree(scene, bvh, rays), "soup", 40000 / 500);
}

TEST(Bvh, SoupWithLargeLeavesMatchesEmbree) {
    BvhScene scene = makeSoupScene(8, 2000, 100);
    BvhBuildOptions opt;
    opt.minLeafSize = 4;
    opt.maxLeafSize = 16;
    BvhData bvh = buildBvh(scene.input(), opt);
    checkInvariants(scene, bvh);
    auto rays = makeRays(12, 20000, sceneLo(bvh.view()), sceneHi(bvh.view()));
    reportAndBound(compareWithEmbree(scene, bvh, rays), "soup, leaves 4..16", 20000 / 500);
}

TEST(Bvh, CornellMatchesEmbree) {
    BvhScene scene = makeCornellScene();
    BvhData bvh = buildBvh(scene.input());
    checkInvariants(scene, bvh);
    auto rays = makeRays(13, 30000, sceneLo(bvh.view()), sceneHi(bvh.view()));
    // The boxes stand on the floor: their bottom faces are coplanar with it, so rays that reach
    // the floor from below meet two triangles at the same t (about 1% of these rays; lifting the
    // boxes by 1e-3 makes the count 0). Bound: 2%.
    reportAndBound(compareWithEmbree(scene, bvh, rays), "cornell", 30000 / 50);
}

namespace {

// Watertightness: rays from inside a closed room aimed exactly at its vertices and at points on
// its edges (the cube's edges and the quads' shared diagonals) must all hit something (Woop et
// al.'s guarantee; a non-watertight test lets some through the cracks). Returns the escapes.
int countEscapes(const BvhScene& room, const BvhView& view) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-0.95f, 0.95f), w(0.0f, 1.0f);
    int escapes = 0;
    for (int i = 0; i < 3000; ++i) {
        Vec3 org(u(rng), u(rng), u(rng));
        for (size_t t = 0; t < 12; ++t) {  // the outer box's triangles
            const uint32_t* tri = &room.indices[3 * t];
            int e = int(w(rng) * 3.0f) % 3;
            const float* a = &room.positions[3 * tri[e]];
            const float* b = &room.positions[3 * tri[(e + 1) % 3]];
            float s = i % 10 == 0 ? 0.0f : w(rng);
            Vec3 target(a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2]));
            BvhRay ray{org, target - org};
            if (!intersect(view, ray, 0.0f, INFINITY).hit()) ++escapes;
            if (!occluded(view, ray, 0.0f, INFINITY)) ++escapes;
        }
    }
    return escapes;
}

BvhScene makeRoom() {
    BvhScene room;
    room.addBox(Vec3(0.0f), Vec3(1.0f), 0.0f);
    room.addBox(Vec3(0.1f, 0.0f, -0.05f), Vec3(0.4f, 0.3f, 0.5f), 0.7f);  // a closed box inside
    return room;
}

}  // namespace

TEST(Bvh, ClosedRoomHasNoCracks) {
    BvhScene room = makeRoom();
    BvhData bvh = buildBvh(room.input());
    EXPECT_EQ(countEscapes(room, bvh.view()), 0) << "of 72000 queries";
}

TEST(Bvh, EmptyAndSinglePrimitive) {
    BvhData empty = buildBvh(BvhBuildInput{});
    BvhRay ray{Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f)};
    EXPECT_FALSE(intersect(empty.view(), ray, 0.0f, INFINITY).hit());
    EXPECT_FALSE(occluded(empty.view(), ray, 0.0f, INFINITY));

    BvhScene one;
    one.addSphere(0.0f, 0.0f, 5.0f, 1.0f);
    BvhData bvh = buildBvh(one.input());
    EXPECT_TRUE(bvhIsLeaf(bvh.root));  // the root itself is a leaf
    BvhHit h = intersect(bvh.view(), ray, 0.0f, INFINITY);
    ASSERT_TRUE(h.hit());
    EXPECT_EQ(h.primId, 0);
    EXPECT_NEAR(h.t, 4.0f, 1e-6f);
    // From inside the sphere the exit point is reported; tmin excludes the entry.
    EXPECT_NEAR(intersect(bvh.view(), ray, 4.5f, INFINITY).t, 6.0f, 1e-6f);
    EXPECT_FALSE(intersect(bvh.view(), ray, 0.0f, 3.9f).hit());
    EXPECT_FALSE(occluded(bvh.view(), ray, 0.0f, 3.9f));
    EXPECT_TRUE(occluded(bvh.view(), ray, 0.0f, 4.1f));
    // Non-unit direction: t in units of the direction.
    BvhRay ray2{Vec3(0.0f), Vec3(0.0f, 0.0f, 2.0f)};
    EXPECT_NEAR(intersect(bvh.view(), ray2, 0.0f, INFINITY).t, 2.0f, 1e-6f);
}

TEST(Bvh, TriangleBarycentricsFollowEmbreeConvention) {
    BvhScene s;
    uint32_t a = s.addVertex(0, 0, 1), b = s.addVertex(1, 0, 1), c = s.addVertex(0, 1, 1);
    s.addTriangle(a, b, c);
    BvhData bvh = buildBvh(s.input());
    BvhHit h = intersect(bvh.view(), BvhRay{Vec3(0.25f, 0.5f, 0.0f), Vec3(0, 0, 1)}, 0.0f, INFINITY);
    ASSERT_TRUE(h.hit());
    EXPECT_NEAR(h.t, 1.0f, 1e-6f);
    EXPECT_NEAR(h.u, 0.25f, 1e-6f);  // weight of vertex 1
    EXPECT_NEAR(h.v, 0.5f, 1e-6f);   // weight of vertex 2
    // Both windings are hit (no culling).
    EXPECT_TRUE(intersect(bvh.view(), BvhRay{Vec3(0.25f, 0.5f, 2.0f), Vec3(0, 0, -1)}, 0.0f, INFINITY).hit());
}

TEST(Bvh, RejectsBadInput) {
    BvhScene s;
    s.addVertex(0, 0, 0);
    s.addVertex(1, 0, 0);
    s.addTriangle(0, 1, 2);  // vertex 2 does not exist
    EXPECT_THROW(buildBvh(s.input()), InputError);
    BvhBuildInput noArray;
    noArray.triangleCount = 3;
    EXPECT_THROW(buildBvh(noArray), InputError);
    BvhScene ok = makeCornellScene();
    BvhBuildOptions opt;
    opt.maxLeafSize = 17;
    EXPECT_THROW(buildBvh(ok.input(), opt), InputError);
}

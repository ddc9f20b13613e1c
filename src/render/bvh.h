// The flattened BVH the GPU traverses (and the CPU tests check against Embree), plus its
// traversal: closest hit (`intersect`) and any hit (`occluded`), written once for host and device.
//
// Layout. A binary BVH laid out by Embree's rtcBuildBVH (src/render/bvh_build.h) and flattened
// into 64-byte nodes that hold the bounds of BOTH children (Aila & Laine 2009): one node fetch
// (four 16-byte loads on the GPU) gives everything needed to test and order the two children.
// A child reference is a uint32: bit 31 clear -> index of an inner node; bit 31 set -> a leaf,
// the range [first, first + count) of `prims`, with first in bits 4..30 and count - 1 in bits
// 0..3 (so leaves hold at most kBvhMaxLeafSize = 16 primitives and a BVH at most 2^27 of them).
//
// Primitives. Leaves point into an array of 48-byte BvhPrim records in leaf order, each holding
// its own geometry (the three triangle vertices, or the sphere's center and radius) and its
// original primitive id. Traversal therefore never gathers through index buffers: one
// contiguous read per primitive, coalesced within a leaf on the GPU.
//
// Primitive id space: triangles first, then spheres. With T triangles and S spheres, id i < T is
// triangle i (indices[3i..3i+2]) and id T + j is sphere j. Primitives that can never be hit
// (a non-finite vertex, a non-finite center, or a radius that is not > 0) are left out of the
// BVH; zero-area triangles are kept (they are never reported as hits).
//
// Precision policy. Triangles use the watertight test of Woop, Benthin & Wald (JCGT 2013): no
// epsilon; a ray through a shared edge or vertex of a closed mesh always hits one of the
// triangles around it. Instead of the paper's double-precision retry, the edge functions are
// computed with Kahan's difference of products (2 ulp, so their sign is always exact), which
// also survives compilers that fuse multiply-adds. Spheres use Embree's geometric form
// (perpendicular distance from the center to the ray), accurate for rays far from the sphere.
// Boxes use the slab test with the exit distance widened by 4e-7 relative (pbrt's 1 + 2 gamma_3)
// so a flat box (an axis-aligned quad) is never missed through rounding; zero direction
// components are replaced by +-1e-30 so 0 * inf never makes a NaN.
//
// Host/device parity. Every product that feeds a sum is written as an explicit fmaf, and nothing
// else in these functions can be contracted, so gcc (which contracts a*b+c freely under
// -std=gnu++17) and nvcc round identically: the CPU and CUDA traversals return bit-identical hits
// (tests/cuda/cuda_bvh_test.cu checks it). Keep that rule when editing.
//
// A hit's t is in units of the ray direction (directions need not be unit length), and
// tmin <= t < tmax. u, v are the barycentrics of vertices 1 and 2 (Embree's convention:
// p = (1 - u - v) v0 + u v1 + v v2); for spheres u = v = 0.
#pragma once
#include <cstdint>

#include "atrous/platform.h"
#include "atrous/math.h"

namespace atrous {

constexpr uint32_t kBvhLeafFlag = 0x80000000u;
constexpr uint32_t kBvhLeafCountBits = 4;
constexpr uint32_t kBvhMaxLeafSize = 1u << kBvhLeafCountBits;          // 16
constexpr uint32_t kBvhMaxPrims = 1u << (31 - kBvhLeafCountBits);      // 2^27
constexpr uint32_t kBvhInvalidRef = 0xFFFFFFFFu;                       // empty BVH
// Fixed traversal stack: one entry per level is enough for a binary BVH, and the builder refuses
// trees deeper than this (bvh_build.cpp asks Embree for at most kBvhMaxDepth levels).
constexpr int kBvhStackSize = 64;
constexpr int kBvhMaxDepth = 48;
constexpr uint32_t kBvhPrimTriangle = 0;
constexpr uint32_t kBvhPrimSphere = 1;

ATROUS_INLINE bool bvhIsLeaf(uint32_t ref) { return (ref & kBvhLeafFlag) != 0; }
ATROUS_INLINE uint32_t bvhLeafFirst(uint32_t ref) { return (ref & ~kBvhLeafFlag) >> kBvhLeafCountBits; }
ATROUS_INLINE uint32_t bvhLeafCount(uint32_t ref) { return (ref & (kBvhMaxLeafSize - 1)) + 1; }
ATROUS_INLINE uint32_t bvhMakeLeaf(uint32_t first, uint32_t count) {
    return kBvhLeafFlag | (first << kBvhLeafCountBits) | (count - 1);
}

// Two children's boxes and references: 64 bytes, 64-byte aligned.
struct alignas(64) BvhNode {
    float lo0[3], hi0[3];  // child 0 bounds
    float lo1[3], hi1[3];  // child 1 bounds
    uint32_t child[2];
    uint32_t pad[2];
};
static_assert(sizeof(BvhNode) == 64, "BvhNode must be 64 bytes");

// One primitive in leaf order. Triangle: a, b, c = vertices 0, 1, 2. Sphere: a = center,
// b[0] = radius.
struct alignas(16) BvhPrim {
    float a[3];
    uint32_t primId;  // original id (triangles first, then spheres)
    float b[3];
    uint32_t kind;  // kBvhPrimTriangle or kBvhPrimSphere
    float c[3];
    uint32_t pad;
};
static_assert(sizeof(BvhPrim) == 48, "BvhPrim must be 48 bytes");

// Non-owning view: what a kernel receives. Pointers are host or device memory alike.
struct BvhView {
    const BvhNode* nodes = nullptr;
    const BvhPrim* prims = nullptr;
    uint32_t nodeCount = 0;
    uint32_t primCount = 0;  // BvhPrim records (primitives that can be hit)
    uint32_t root = kBvhInvalidRef;
    float sceneLo[3] = {0, 0, 0}, sceneHi[3] = {0, 0, 0};
};

struct BvhRay {
    Vec3 org;
    Vec3 dir;  // need not be unit length; t is measured in units of |dir|
};

struct BvhHit {
    float t = 0.0f;
    int32_t primId = -1;  // -1: miss
    float u = 0.0f, v = 0.0f;
    ATROUS_INLINE bool hit() const { return primId >= 0; }
};

namespace bvh_detail {

// Per-ray constants: reciprocal direction for the slab test and Woop's shear (k_z = dominant
// axis, S = shear constants).
struct RayPre {
    float org[3];
    float invDir[3];
    int kx, ky, kz;
    float sx, sy, sz;
};

ATROUS_INLINE float absf(float v) { return v < 0.0f ? -v : v; }
// v[k] through selects, not an indexed load: a dynamically indexed local array would live in
// slow local memory on the GPU.
ATROUS_INLINE float comp(const float v[3], int k) { return k == 0 ? v[0] : (k == 1 ? v[1] : v[2]); }

ATROUS_INLINE RayPre prepare(const BvhRay& ray) {
    RayPre p;
    float d[3] = {ray.dir.x, ray.dir.y, ray.dir.z};
    p.org[0] = ray.org.x;
    p.org[1] = ray.org.y;
    p.org[2] = ray.org.z;
    for (int i = 0; i < 3; ++i) {
        // 1e-30 keeps (lo - o) * inv finite-or-inf but never 0 * inf = NaN.
        float di = absf(d[i]) > 1e-30f ? d[i] : (d[i] < 0.0f ? -1e-30f : 1e-30f);
        p.invDir[i] = 1.0f / di;
    }
    // Woop et al.: kz = dimension where |dir| is largest; swap kx, ky to keep the winding.
    float ax = absf(d[0]), ay = absf(d[1]), az = absf(d[2]);
    int kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    int kx = kz + 1 == 3 ? 0 : kz + 1;
    int ky = kx + 1 == 3 ? 0 : kx + 1;
    if (comp(d, kz) < 0.0f) {
        int tmp = kx;
        kx = ky;
        ky = tmp;
    }
    p.kx = kx;
    p.ky = ky;
    p.kz = kz;
    p.sx = comp(d, kx) / comp(d, kz);
    p.sy = comp(d, ky) / comp(d, kz);
    p.sz = 1.0f / comp(d, kz);
    return p;
}

// Slab test of one box against [tmin, tmax]; writes the entry distance.
ATROUS_INLINE bool hitBox(const float lo[3], const float hi[3], const RayPre& r, float tmin, float tmax,
                          float& tEntry) {
    float tNear = tmin, tFar = tmax;
    for (int i = 0; i < 3; ++i) {
        float t0 = (lo[i] - r.org[i]) * r.invDir[i];
        float t1 = (hi[i] - r.org[i]) * r.invDir[i];
        float a = minf(t0, t1), b = maxf(t0, t1);
        tNear = maxf(tNear, a);
        // Widen the exit by 1 + 2 gamma_3 (pbrt-v4 Bounds3::IntersectP) so rounding in t0/t1
        // never rejects a box the ray touches.
        tFar = minf(tFar, b * 1.0000004f);
    }
    tEntry = tNear;
    return tNear <= tFar;
}

// a*b - c*d to within 2 ulp (Kahan's algorithm; Jeannerod, Louvet & Muller 2013): exact sign,
// and exactly 0 only when the real value is 0.
ATROUS_INLINE float differenceOfProducts(float a, float b, float c, float d) {
    float cd = c * d;
    float err = fmaf(-c, d, cd);  // cd - c*d, exactly
    float dop = fmaf(a, b, -cd);
    return dop + err;
}

// Watertight ray/triangle (Woop, Benthin, Wald 2013). Updates t/u/v when a hit in [tmin, tHit)
// is found.
ATROUS_INLINE bool hitTriangle(const BvhPrim& p, const RayPre& r, float tmin, float tHit, float& t, float& u,
                               float& v) {
    const int kx = r.kx, ky = r.ky, kz = r.kz;
    float a[3] = {p.a[0] - r.org[0], p.a[1] - r.org[1], p.a[2] - r.org[2]};
    float b[3] = {p.b[0] - r.org[0], p.b[1] - r.org[1], p.b[2] - r.org[2]};
    float c[3] = {p.c[0] - r.org[0], p.c[1] - r.org[1], p.c[2] - r.org[2]};
    // Shear and scale the vertices into ray space (the ray becomes the +z axis).
    float ax = fmaf(-r.sx, comp(a, kz), comp(a, kx)), ay = fmaf(-r.sy, comp(a, kz), comp(a, ky));
    float bx = fmaf(-r.sx, comp(b, kz), comp(b, kx)), by = fmaf(-r.sy, comp(b, kz), comp(b, ky));
    float cx = fmaf(-r.sx, comp(c, kz), comp(c, kx)), cy = fmaf(-r.sy, comp(c, kz), comp(c, ky));
    // Scaled barycentrics (edge functions): U weights vertex a, V vertex b, W vertex c. The
    // sign must be exact, or a ray through a shared edge can see "outside" from both triangles
    // (the edge function of one triangle must be the exact negation of its neighbour's). The
    // paper gets that from two rounded products; a compiler that fuses one of them into an FMA
    // (gcc targeting FMA hardware and nvcc both do by default) breaks it. Kahan's difference of
    // products is accurate to 2 ulp, so its sign is exact, and its explicit FMAs cannot re-fuse.
    float uu = differenceOfProducts(cx, by, cy, bx);
    float vv = differenceOfProducts(ax, cy, ay, cx);
    float ww = differenceOfProducts(bx, ay, by, ax);
    if ((uu < 0.0f || vv < 0.0f || ww < 0.0f) && (uu > 0.0f || vv > 0.0f || ww > 0.0f)) return false;
    float det = uu + vv + ww;
    if (det == 0.0f) return false;  // degenerate in ray space (zero area or edge-on)
    float az = r.sz * comp(a, kz), bz = r.sz * comp(b, kz), cz = r.sz * comp(c, kz);
    float tScaled = fmaf(uu, az, fmaf(vv, bz, ww * cz));
    float tt = tScaled / det;
    if (!(tt >= tmin && tt < tHit)) return false;
    t = tt;
    u = vv / det;
    v = ww / det;
    return true;
}

ATROUS_INLINE float dot3(const float a[3], const float b[3]) { return fmaf(a[0], b[0], fmaf(a[1], b[1], a[2] * b[2])); }

// Ray/sphere in Embree's form: project the center onto the ray, compare the perpendicular
// distance l with the radius. Reports the entry point, or the exit point when the entry is
// before tmin (ray starting inside).
ATROUS_INLINE bool hitSphere(const BvhPrim& p, const BvhRay& ray, float tmin, float tHit, float& t) {
    float d[3] = {ray.dir.x, ray.dir.y, ray.dir.z};
    float c0[3] = {p.a[0] - ray.org.x, p.a[1] - ray.org.y, p.a[2] - ray.org.z};
    float radius = p.b[0];
    float rd2 = 1.0f / dot3(d, d);
    float dc = dot3(c0, d);
    float proj = dc * rd2;  // only ever a multiplicand below, so nothing can fuse it
    float perp[3] = {fmaf(-proj, d[0], c0[0]), fmaf(-proj, d[1], c0[1]), fmaf(-proj, d[2], c0[2])};
    float l2 = dot3(perp, perp);
    float rl = fmaf(radius, radius, -l2);  // r^2 - l^2
    if (!(rl >= 0.0f)) return false;
    float td = sqrtf(rl * rd2);
    float tFront = fmaf(dc, rd2, -td), tBack = fmaf(dc, rd2, td);
    if (tFront >= tmin && tFront < tHit) {
        t = tFront;
        return true;
    }
    if (tBack >= tmin && tBack < tHit) {
        t = tBack;
        return true;
    }
    return false;
}

// The one traversal behind intersect() and occluded(): ordered depth-first descent of the binary
// BVH with a short stack. Closest hit shrinks the ray's interval to each hit found; any hit
// (kAnyHit) returns at the first one, since a shadow ray only asks whether something blocks it.
template <bool kAnyHit>
ATROUS_INLINE BvhHit traverse(const BvhView& bvh, const BvhRay& ray, float tmin, float tmax) {
    BvhHit hit;
    hit.t = tmax;
    if (bvh.root == kBvhInvalidRef) return hit;
    const RayPre pre = prepare(ray);
    uint32_t stack[kBvhStackSize];
    int sp = 0;
    uint32_t ref = bvh.root;
    for (;;) {
        if (!bvhIsLeaf(ref)) {
            const BvhNode node = bvh.nodes[ref];
            float t0 = 0.0f, t1 = 0.0f;
            bool h0 = hitBox(node.lo0, node.hi0, pre, tmin, hit.t, t0);
            bool h1 = hitBox(node.lo1, node.hi1, pre, tmin, hit.t, t1);
            if (h0 && h1) {
                // Ordered traversal: nearer child now, the other later.
                bool firstIs0 = t0 <= t1;
                stack[sp++] = firstIs0 ? node.child[1] : node.child[0];
                ref = firstIs0 ? node.child[0] : node.child[1];
                continue;
            }
            if (h0 || h1) {
                ref = h0 ? node.child[0] : node.child[1];
                continue;
            }
        } else {
            uint32_t first = bvhLeafFirst(ref), end = first + bvhLeafCount(ref);
            for (uint32_t i = first; i < end; ++i) {
                const BvhPrim& p = bvh.prims[i];
                float t, u = 0.0f, v = 0.0f;
                const bool h = p.kind == kBvhPrimTriangle ? hitTriangle(p, pre, tmin, hit.t, t, u, v)
                                                          : hitSphere(p, ray, tmin, hit.t, t);
                if (h) {
                    hit.t = t;
                    hit.u = u;
                    hit.v = v;
                    hit.primId = int32_t(p.primId);
                    if (kAnyHit) return hit;
                }
            }
        }
        if (sp == 0) break;
        ref = stack[--sp];
    }
    return hit;
}

}  // namespace bvh_detail

// Closest hit in [tmin, tmax). Returns primId -1 on a miss.
ATROUS_INLINE BvhHit intersect(const BvhView& bvh, const BvhRay& ray, float tmin, float tmax) {
    return bvh_detail::traverse<false>(bvh, ray, tmin, tmax);
}

// Any hit in [tmin, tmax): true when something blocks the segment (shadow rays).
ATROUS_INLINE bool occluded(const BvhView& bvh, const BvhRay& ray, float tmin, float tmax) {
    return bvh_detail::traverse<true>(bvh, ray, tmin, tmax).primId >= 0;
}

}  // namespace atrous

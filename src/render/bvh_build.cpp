// Embree lays out the tree (rtcBuildBVH with binned SAH); this file only hands it primitive
// boxes, records the nodes it creates in Embree's thread-local allocator, and flattens the result
// depth-first into BvhNode/BvhPrim arrays (a node's first child right after it, for locality).
#include "render/bvh_build.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <memory>
#include <new>
#include <string>

#include "atrous/error.h"
#include "atrous/timer.h"

namespace atrous {
namespace {

// Nodes of the temporary tree, allocated by Embree's builder threads.
struct BuildNode {
    bool leaf;
};
struct BuildInner : BuildNode {
    BuildNode* child[2];
    RTCBounds bounds[2];
};
struct BuildLeaf : BuildNode {
    uint32_t count;
    uint32_t ids[kBvhMaxLeafSize];
};

void* createNode(RTCThreadLocalAllocator alloc, unsigned int childCount, void*) {
    if (childCount > 2) return nullptr;  // we ask for a binary tree; anything else is a bug
    void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildInner), 16);
    auto* n = new (mem) BuildInner;
    n->leaf = false;
    n->child[0] = n->child[1] = nullptr;
    return n;
}

void setNodeChildren(void* nodePtr, void** children, unsigned int childCount, void*) {
    auto* n = static_cast<BuildInner*>(nodePtr);
    for (unsigned i = 0; i < childCount && i < 2; ++i) n->child[i] = static_cast<BuildNode*>(children[i]);
}

void setNodeBounds(void* nodePtr, const RTCBounds** bounds, unsigned int childCount, void*) {
    auto* n = static_cast<BuildInner*>(nodePtr);
    for (unsigned i = 0; i < childCount && i < 2; ++i) n->bounds[i] = *bounds[i];
}

void* createLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
    if (count == 0 || count > kBvhMaxLeafSize) return nullptr;
    void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildLeaf), 16);
    auto* l = new (mem) BuildLeaf;
    l->leaf = true;
    l->count = uint32_t(count);
    for (size_t i = 0; i < count; ++i) l->ids[i] = prims[i].primID;
    return l;
}

void onEmbreeError(void* userPtr, RTCError code, const char* str) {
    auto* msg = static_cast<std::string*>(userPtr);
    if (msg->empty()) *msg = "Embree error " + std::to_string(int(code)) + ": " + (str ? str : "");
}

bool finite3(const float* p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

struct Flattener {
    const BvhBuildInput& in;
    BvhData& out;
    std::string error;

    void emitPrim(uint32_t id) {
        BvhPrim p{};
        p.primId = id;
        if (id < in.triangleCount) {
            const uint32_t* tri = in.indices + 3 * size_t(id);
            const float* v[3] = {in.positions + 3 * size_t(tri[0]), in.positions + 3 * size_t(tri[1]),
                                 in.positions + 3 * size_t(tri[2])};
            for (int k = 0; k < 3; ++k) {
                p.a[k] = v[0][k];
                p.b[k] = v[1][k];
                p.c[k] = v[2][k];
            }
            p.kind = kBvhPrimTriangle;
        } else {
            const float* s = in.spheres + 4 * (size_t(id) - in.triangleCount);
            for (int k = 0; k < 3; ++k) p.a[k] = s[k];
            p.b[0] = s[3];
            p.kind = kBvhPrimSphere;
        }
        out.prims.push_back(p);
    }

    uint32_t flatten(const BuildNode* n, uint32_t depth) {
        if (depth > out.maxDepth) out.maxDepth = depth;
        if (!n) {
            error = "Embree returned an incomplete tree";
            return kBvhInvalidRef;
        }
        if (n->leaf) {
            auto* l = static_cast<const BuildLeaf*>(n);
            uint32_t first = uint32_t(out.prims.size());
            for (uint32_t i = 0; i < l->count; ++i) emitPrim(l->ids[i]);
            ++out.leafCount;
            return bvhMakeLeaf(first, l->count);
        }
        auto* b = static_cast<const BuildInner*>(n);
        uint32_t index = uint32_t(out.nodes.size());
        out.nodes.emplace_back();
        uint32_t refs[2];
        for (int i = 0; i < 2; ++i) refs[i] = flatten(b->child[i], depth + 1);
        BvhNode& node = out.nodes[index];  // after the recursion: the vector may have grown
        const RTCBounds& b0 = b->bounds[0];
        const RTCBounds& b1 = b->bounds[1];
        node.lo0[0] = b0.lower_x, node.lo0[1] = b0.lower_y, node.lo0[2] = b0.lower_z;
        node.hi0[0] = b0.upper_x, node.hi0[1] = b0.upper_y, node.hi0[2] = b0.upper_z;
        node.lo1[0] = b1.lower_x, node.lo1[1] = b1.lower_y, node.lo1[2] = b1.lower_z;
        node.hi1[0] = b1.upper_x, node.hi1[1] = b1.upper_y, node.hi1[2] = b1.upper_z;
        node.child[0] = refs[0];
        node.child[1] = refs[1];
        node.pad[0] = node.pad[1] = 0;
        return index;
    }
};

}  // namespace

BvhData buildBvh(const BvhBuildInput& in, const BvhBuildOptions& options) {
    Timer timer;
    if (in.triangleCount > 0 && (!in.indices || !in.positions))
        throw InputError("BVH build: " + std::to_string(in.triangleCount) +
                         " triangles but no index or position array");
    if (in.sphereCount > 0 && !in.spheres)
        throw InputError("BVH build: " + std::to_string(in.sphereCount) + " spheres but no sphere array");
    if (in.triangleCount + in.sphereCount >= kBvhMaxPrims)
        throw InputError("BVH build: " + std::to_string(in.triangleCount + in.sphereCount) +
                         " primitives, more than the BVH's limit of " + std::to_string(kBvhMaxPrims));
    if (options.minLeafSize < 1 || options.maxLeafSize < options.minLeafSize ||
        options.maxLeafSize > int(kBvhMaxLeafSize))
        throw InputError("BVH build: leaf size bounds [" + std::to_string(options.minLeafSize) + ", " +
                         std::to_string(options.maxLeafSize) + "] outside [1, " +
                         std::to_string(kBvhMaxLeafSize) + "]");

    BvhData out;
    std::vector<RTCBuildPrimitive> prims;
    prims.reserve(in.triangleCount + in.sphereCount);
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    auto addPrim = [&](const float* l, const float* h, size_t id) {
        RTCBuildPrimitive p;
        p.lower_x = l[0], p.lower_y = l[1], p.lower_z = l[2];
        p.upper_x = h[0], p.upper_y = h[1], p.upper_z = h[2];
        p.geomID = 0;
        p.primID = unsigned(id);
        prims.push_back(p);
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::fmin(lo[k], l[k]);
            hi[k] = std::fmax(hi[k], h[k]);
        }
    };
    for (size_t t = 0; t < in.triangleCount; ++t) {
        const uint32_t* tri = in.indices + 3 * t;
        float l[3] = {INFINITY, INFINITY, INFINITY}, h[3] = {-INFINITY, -INFINITY, -INFINITY};
        bool ok = true;
        for (int c = 0; c < 3; ++c) {
            if (tri[c] >= in.vertexCount)
                throw InputError("BVH build: triangle " + std::to_string(t) + " references vertex " +
                                 std::to_string(tri[c]) + " but there are only " + std::to_string(in.vertexCount) +
                                 " vertices");
            const float* v = in.positions + 3 * size_t(tri[c]);
            ok = ok && finite3(v);
            for (int k = 0; k < 3; ++k) {
                l[k] = std::fmin(l[k], v[k]);
                h[k] = std::fmax(h[k], v[k]);
            }
        }
        if (ok) addPrim(l, h, t);
        else ++out.skippedPrims;
    }
    for (size_t s = 0; s < in.sphereCount; ++s) {
        const float* sp = in.spheres + 4 * s;
        float r = sp[3];
        if (!finite3(sp) || !std::isfinite(r) || !(r > 0.0f)) {
            ++out.skippedPrims;
            continue;
        }
        float l[3] = {sp[0] - r, sp[1] - r, sp[2] - r}, h[3] = {sp[0] + r, sp[1] + r, sp[2] + r};
        addPrim(l, h, in.triangleCount + s);
    }
    if (prims.empty()) {
        out.buildSeconds = timer.seconds();
        return out;
    }
    for (int k = 0; k < 3; ++k) {
        out.sceneLo[k] = lo[k];
        out.sceneHi[k] = hi[k];
    }

    std::string embreeError;
    RTCDevice device = rtcNewDevice(nullptr);
    if (!device) throw RuntimeError("BVH build: cannot create an Embree device");
    rtcSetDeviceErrorFunction(device, onEmbreeError, &embreeError);
    RTCBVH bvh = rtcNewBVH(device);
    // Release the Embree objects on every path out of here (the tree lives in the RTCBVH).
    std::unique_ptr<RTCBVHTy, void (*)(RTCBVH)> bvhGuard(bvh, rtcReleaseBVH);
    std::unique_ptr<RTCDeviceTy, void (*)(RTCDevice)> deviceGuard(device, rtcReleaseDevice);
    if (!bvh) throw RuntimeError("BVH build: rtcNewBVH failed: " + embreeError);

    RTCBuildArguments args = rtcDefaultBuildArguments();
    // MEDIUM = binned SAH without spatial splits, so every primitive sits in exactly one leaf
    // (HIGH would add splits only with a splitPrimitive callback and spare array capacity).
    args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
    args.maxBranchingFactor = 2;
    args.maxDepth = kBvhMaxDepth;
    args.sahBlockSize = 1;
    args.minLeafSize = unsigned(options.minLeafSize);
    args.maxLeafSize = unsigned(options.maxLeafSize);
    args.traversalCost = options.traversalCost;
    args.intersectionCost = options.intersectionCost;
    args.bvh = bvh;
    args.primitives = prims.data();
    args.primitiveCount = prims.size();
    args.primitiveArrayCapacity = prims.size();
    args.createNode = createNode;
    args.setNodeChildren = setNodeChildren;
    args.setNodeBounds = setNodeBounds;
    args.createLeaf = createLeaf;
    args.splitPrimitive = nullptr;
    args.buildProgress = nullptr;
    args.userPtr = nullptr;
    auto* root = static_cast<BuildNode*>(rtcBuildBVH(&args));
    if (!root) throw RuntimeError("BVH build: rtcBuildBVH failed: " + embreeError);

    out.nodes.reserve(prims.size());
    out.prims.reserve(prims.size());
    Flattener f{in, out, {}};
    out.root = f.flatten(root, 0);
    if (!f.error.empty()) throw RuntimeError("BVH build: " + f.error);
    if (out.maxDepth >= uint32_t(kBvhStackSize))
        throw RuntimeError("BVH build: tree depth " + std::to_string(out.maxDepth) +
                           " exceeds the traversal stack of " + std::to_string(kBvhStackSize));
    out.buildSeconds = timer.seconds();
    return out;
}

}  // namespace atrous

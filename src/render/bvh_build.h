// Builds the flattened BVH of src/render/bvh.h with Embree's generic builder (rtcBuildBVH,
// binned SAH) on the CPU. The result is a host-side owner; its view() is what the CPU traversal
// takes, and what the CUDA backend copies to the device (same layout, plain arrays).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/bvh.h"

namespace atrous {

// Flat input arrays (not owned; only read during the build). Primitive ids: triangles first
// (0 .. triangleCount-1), then spheres (triangleCount .. triangleCount+sphereCount-1).
struct BvhBuildInput {
    const float* positions = nullptr;  // xyz per vertex, world units
    size_t vertexCount = 0;
    const uint32_t* indices = nullptr;  // 3 vertex indices per triangle
    size_t triangleCount = 0;
    const float* spheres = nullptr;  // cx, cy, cz, radius per sphere
    size_t sphereCount = 0;
};

struct BvhBuildOptions {
    // Leaf size bounds handed to Embree; SAH picks the size in between. Small leaves suit the
    // GPU, whose threads diverge inside leaves. At most kBvhMaxLeafSize.
    int minLeafSize = 1;
    int maxLeafSize = 4;
    // SAH costs (Embree's units: relative cost of a node visit vs one primitive test).
    float traversalCost = 1.0f;
    float intersectionCost = 1.0f;
};

// Owner of a built BVH.
struct BvhData {
    std::vector<BvhNode> nodes;
    std::vector<BvhPrim> prims;
    uint32_t root = kBvhInvalidRef;
    float sceneLo[3] = {0, 0, 0}, sceneHi[3] = {0, 0, 0};
    // Statistics of the build.
    uint32_t leafCount = 0;
    uint32_t maxDepth = 0;        // levels below the root (0 when the root is a leaf)
    size_t skippedPrims = 0;      // primitives left out because they can never be hit
    double buildSeconds = 0.0;    // rtcBuildBVH plus flattening

    BvhView view() const {
        BvhView v;
        v.nodes = nodes.data();
        v.prims = prims.data();
        v.nodeCount = uint32_t(nodes.size());
        v.primCount = uint32_t(prims.size());
        v.root = root;
        for (int i = 0; i < 3; ++i) {
            v.sceneLo[i] = sceneLo[i];
            v.sceneHi[i] = sceneHi[i];
        }
        return v;
    }
};

// Builds the BVH. Throws InputError when a triangle references a vertex past vertexCount, when
// an array is null while its count is not zero, or when there are more than kBvhMaxPrims
// primitives; RuntimeError when Embree fails. An empty input gives an empty BVH (every ray
// misses).
BvhData buildBvh(const BvhBuildInput& input, const BvhBuildOptions& options = {});

}  // namespace atrous

// The BVH built on the host (src/render/bvh_build.h) copied to the GPU. Same layout, so the
// device view is the host view with device pointers.
#pragma once
#include "cuda/device_buffer.cuh"
#include "render/bvh.h"
#include "render/bvh_build.h"

namespace atrous::cuda {

class DeviceBvh {
public:
    DeviceBvh() = default;
    explicit DeviceBvh(const BvhData& host) : mNodes(host.nodes), mPrims(host.prims), mView(host.view()) {
        mView.nodes = mNodes.data();
        mView.prims = mPrims.data();
    }
    // Valid while this object lives; pass it to kernels by value.
    const BvhView& view() const { return mView; }

private:
    DeviceBuffer<BvhNode> mNodes;
    DeviceBuffer<BvhPrim> mPrims;
    BvhView mView;
};

}  // namespace atrous::cuda

// The BVH traversal of src/render/bvh.h run in a CUDA kernel, compared with the same traversal on
// the CPU. The traversal is written so that gcc and nvcc round every operation identically
// (explicit FMAs, IEEE division and sqrt, no fast math), so the comparison is exact: same prim
// id, and bit-identical t, u, v. A failure here means a contraction or approximation crept in.
// (Named cuda_bvh_test.cu, not bvh_test.cu: tests/CMakeLists.txt names targets after the file,
// and tests/bvh_test.cpp already owns "bvh_test".)
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "../bvh_scenes.h"
#include "atrous/device.h"
#include "cuda/cuda_bvh.cuh"
#include "atrous/cuda_check.cuh"
#include "cuda/device_buffer.cuh"

using namespace atrous;
using namespace atrous::test;

namespace {

__global__ void traceKernel(BvhView bvh, const TestRay* rays, int count, BvhHit* hits, int* occludedOut) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= count) return;
    hits[i] = intersect(bvh, rays[i].ray, 0.0f, INFINITY);
    occludedOut[i] = occluded(bvh, rays[i].ray, 0.0f, rays[i].tmax) ? 1 : 0;
}

uint32_t bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

void compareOnGpu(const BvhScene& scene, uint32_t raySeed, int rayCount) {
    BvhData bvh = buildBvh(scene.input());
    BvhView hostView = bvh.view();
    std::vector<TestRay> rays = makeRays(raySeed, rayCount, sceneLo(hostView), sceneHi(hostView));

    cuda::DeviceBvh deviceBvh(bvh);
    cuda::DeviceBuffer<TestRay> dRays(rays);
    cuda::DeviceBuffer<BvhHit> dHits(rays.size());
    cuda::DeviceBuffer<int> dOcc(rays.size());
    int block = 128;
    int grid = (rayCount + block - 1) / block;
    traceKernel<<<grid, block>>>(deviceBvh.view(), dRays.data(), rayCount, dHits.data(), dOcc.data());
    ATROUS_CUDA_CHECK(cudaGetLastError());
    ATROUS_CUDA_CHECK(cudaDeviceSynchronize());
    std::vector<BvhHit> gpuHits = dHits.download();
    std::vector<int> gpuOcc = dOcc.download();

    int hitCount = 0, differ = 0;
    for (int i = 0; i < rayCount; ++i) {
        BvhHit cpu = intersect(hostView, rays[i].ray, 0.0f, INFINITY);
        bool cpuOcc = occluded(hostView, rays[i].ray, 0.0f, rays[i].tmax);
        hitCount += cpu.hit();
        bool same = cpu.primId == gpuHits[i].primId && bits(cpu.t) == bits(gpuHits[i].t) &&
                    bits(cpu.u) == bits(gpuHits[i].u) && bits(cpu.v) == bits(gpuHits[i].v) &&
                    int(cpuOcc) == gpuOcc[i];
        if (!same && ++differ <= 5)
            ADD_FAILURE() << "ray " << i << ": cpu prim " << cpu.primId << " t " << cpu.t << " occ " << cpuOcc
                          << ", gpu prim " << gpuHits[i].primId << " t " << gpuHits[i].t << " occ " << gpuOcc[i];
    }
    EXPECT_EQ(differ, 0) << "of " << rayCount << " rays";
    EXPECT_GT(hitCount, rayCount / 3);  // not vacuous
}

}  // namespace

TEST(CudaBvh, SoupMatchesCpuExactly) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    compareOnGpu(makeSoupScene(7), 11, 40000);
}

TEST(CudaBvh, CornellMatchesCpuExactly) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    compareOnGpu(makeCornellScene(), 13, 30000);
}

TEST(CudaBvh, EmptyBvhMissesOnGpu) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    BvhData empty = buildBvh(BvhBuildInput{});
    cuda::DeviceBvh d(empty);
    std::vector<TestRay> rays(1);
    rays[0].ray = BvhRay{Vec3(0.0f), Vec3(0.0f, 0.0f, 1.0f)};
    rays[0].tmax = INFINITY;
    cuda::DeviceBuffer<TestRay> dRays(rays);
    cuda::DeviceBuffer<BvhHit> dHits(1);
    cuda::DeviceBuffer<int> dOcc(1);
    traceKernel<<<1, 32>>>(d.view(), dRays.data(), 1, dHits.data(), dOcc.data());
    ATROUS_CUDA_CHECK(cudaGetLastError());
    ATROUS_CUDA_CHECK(cudaDeviceSynchronize());
    EXPECT_FALSE(dHits.download()[0].hit());
    EXPECT_EQ(dOcc.download()[0], 0);
}

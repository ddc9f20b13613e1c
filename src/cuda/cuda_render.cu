// The CUDA path tracer: uploads the scene's flat arrays and the BVH built by Embree's
// rtcBuildBVH, then runs the renderer's own per-pixel functor (pt::PathTraceKernel,
// src/render/integrator.h) with pt::BvhTracer as the intersector, one thread per pixel. Same
// buffers, RNG streams and sample math as the CPU renderer; only the intersector differs.
#include <cuda_runtime.h>

#include "atrous/device.h"
#include "atrous/error.h"
#include "cuda/cuda_bvh.cuh"
#include "cuda/cuda_check.cuh"
#include "cuda/cuda_exec.cuh"
#include "cuda/device_buffer.cuh"
#include "render/bvh_render.h"

namespace atrous {
namespace {

// Device copies of every array SceneView points to; view() is SceneView with device pointers.
class DeviceScene {
public:
    explicit DeviceScene(const pt::SceneData& d)
        : mPositions(d.positions), mNormals(d.normals), mUvs(d.uvs), mIndices(d.indices), mTriMaterial(d.triMaterial),
          mTriMesh(d.triMesh), mTriLight(d.triLight), mSpheres(d.spheres), mMaterials(d.materials),
          mTextures(d.textures), mTexels(d.texels), mLights(d.lights), mLightCdf(d.lightCdf), mEnvDist(d.envDist),
          mView(d.view()) {
        mView.positions = mPositions.data();
        mView.normals = mNormals.data();
        mView.uvs = mUvs.data();
        mView.indices = mIndices.data();
        mView.triMaterial = mTriMaterial.data();
        mView.triMesh = mTriMesh.data();
        mView.triLight = mTriLight.data();
        mView.spheres = mSpheres.data();
        mView.materials = mMaterials.data();
        mView.textures = mTextures.data();
        mView.texels = mTexels.data();
        mView.lights = mLights.data();
        mView.lightCdf = mLightCdf.data();
        mView.envDist = mEnvDist.data();
    }
    const pt::SceneView& view() const { return mView; }

private:
    cuda::DeviceBuffer<Vec3> mPositions, mNormals;
    cuda::DeviceBuffer<Vec2> mUvs;
    cuda::DeviceBuffer<uint32_t> mIndices;
    cuda::DeviceBuffer<int32_t> mTriMaterial, mTriMesh, mTriLight;
    cuda::DeviceBuffer<pt::Sphere> mSpheres;
    cuda::DeviceBuffer<pt::Material> mMaterials;
    cuda::DeviceBuffer<pt::Texture> mTextures;
    cuda::DeviceBuffer<float> mTexels;
    cuda::DeviceBuffer<pt::Light> mLights;
    cuda::DeviceBuffer<float> mLightCdf, mEnvDist;
    pt::SceneView mView;
};

}  // namespace

RenderBuffers renderBvhCuda(const Scene& scene, const RenderSettings& settings) {
    validateRenderSettings(settings);
    if (!cudaAvailable()) throw InputError("--device cuda: no CUDA device is available");
    const pt::SceneData& data = scene.data();
    BvhData bvh = pt::buildSceneBvh(data);
    cuda::DeviceBvh deviceBvh(bvh);
    DeviceScene deviceScene(data);
    RenderBuffers d = detail::allocateRenderBuffers(settings.width, settings.height, Device::Cuda);
    auto k = detail::makePathTraceKernel(deviceScene.view(), pt::makeBvhTracer(deviceBvh.view(), data), d, settings);
    CudaExec exec;
    exec.forEachPixel(settings.width, settings.height, k);
    exec.synchronize();
    RenderBuffers out;
    out.color = d.color.to(Device::Cpu);
    out.variance = d.variance.to(Device::Cpu);
    out.albedo = d.albedo.to(Device::Cpu);
    out.normal = d.normal.to(Device::Cpu);
    out.position = d.position.to(Device::Cpu);
    out.depth = d.depth.to(Device::Cpu);
    out.ids = d.ids.to(Device::Cpu);
    out.emission = d.emission.to(Device::Cpu);
    return out;
}

}  // namespace atrous

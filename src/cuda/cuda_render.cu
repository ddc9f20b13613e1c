// The CUDA path tracer: uploads the scene's flat arrays and the BVH built by Embree's
// rtcBuildBVH, then runs the renderer's own per-pixel functor (pt::PathTraceKernel,
// src/render/integrator.h) with pt::BvhTracer as the intersector, one thread per pixel. Same
// buffers, RNG streams and sample math as the CPU renderer; only the intersector differs.
#include <cuda_runtime.h>

#include "atrous/device.h"
#include "atrous/error.h"
#include "cuda/cuda_bvh.cuh"
#include "atrous/cuda_check.cuh"
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

struct CudaBvhRenderer::Impl {
    Scene scene;  // keeps the host arrays alive (shared, immutable)
    int32_t numTriangles = 0;
    cuda::DeviceBvh bvh;
    DeviceScene deviceScene;
    RenderBuffers frame;  // device buffers, reused while the size stays the same

    explicit Impl(const Scene& s)
        : scene(s), numTriangles(int32_t(s.data().triMaterial.size())), bvh(pt::buildSceneBvh(s.data())),
          deviceScene(s.data()) {}
};

CudaBvhRenderer::CudaBvhRenderer(const Scene& scene) {
    requireCuda();
    mImpl = std::make_unique<Impl>(scene);
}
CudaBvhRenderer::~CudaBvhRenderer() = default;
CudaBvhRenderer::CudaBvhRenderer(CudaBvhRenderer&&) noexcept = default;
CudaBvhRenderer& CudaBvhRenderer::operator=(CudaBvhRenderer&&) noexcept = default;

const RenderBuffers& CudaBvhRenderer::renderOnDevice(const RenderSettings& settings, const pt::Camera* camera) {
    validateRenderSettings(settings);
    Impl& m = *mImpl;
    if (m.frame.color.empty() || m.frame.color.width() != settings.width || m.frame.color.height() != settings.height)
        m.frame = detail::allocateRenderBuffers(settings.width, settings.height, Device::Cuda);
    pt::SceneView view = m.deviceScene.view();
    if (camera) view.camera = *camera;
    pt::BvhTracer tracer;
    tracer.bvh = m.bvh.view();
    tracer.numTriangles = m.numTriangles;
    auto k = detail::makePathTraceKernel(view, tracer, m.frame, settings);
    CudaExec exec;
    exec.forEachPixel(settings.width, settings.height, k);
    exec.synchronize();
    return m.frame;
}

RenderBuffers CudaBvhRenderer::render(const RenderSettings& settings, const pt::Camera* camera) {
    const RenderBuffers& f = renderOnDevice(settings, camera);
    RenderBuffers out;
    out.color = f.color.to(Device::Cpu);
    out.variance = f.variance.to(Device::Cpu);
    out.albedo = f.albedo.to(Device::Cpu);
    out.normal = f.normal.to(Device::Cpu);
    out.position = f.position.to(Device::Cpu);
    out.depth = f.depth.to(Device::Cpu);
    out.ids = f.ids.to(Device::Cpu);
    out.emission = f.emission.to(Device::Cpu);
    return out;
}

RenderBuffers renderBvhCuda(const Scene& scene, const RenderSettings& settings) {
    validateRenderSettings(settings);  // before any GPU work
    return CudaBvhRenderer(scene).render(settings);
}

}  // namespace atrous

// CPU driver of the BVH path tracer (the GPU's code path on TBB threads) and the CUDA entry
// point's stand-in for builds without CUDA.
#include "render/bvh_render.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "atrous/device.h"
#include "atrous/error.h"

namespace atrous {

RenderBuffers renderBvhCpu(const Scene& scene, const RenderSettings& settings) {
    validateRenderSettings(settings);  // include/atrous/render.h
    const pt::SceneData& data = scene.data();
    BvhData bvh = pt::buildSceneBvh(data);
    RenderBuffers b = detail::allocateRenderBuffers(settings.width, settings.height, Device::Cpu);
    auto k = detail::makePathTraceKernel(data.view(), pt::makeBvhTracer(bvh.view(), data), b, settings);
    detail::runPathTraceTiles(k, settings);
    return b;
}

#if !defined(ATROUS_HAVE_CUDA)
// Builds without the CUDA backend: the CUDA renderer refuses, as --device cuda does elsewhere.
struct CudaBvhRenderer::Impl {};

CudaBvhRenderer::CudaBvhRenderer(const Scene&) {
    noCudaBackend();
}
CudaBvhRenderer::~CudaBvhRenderer() = default;
CudaBvhRenderer::CudaBvhRenderer(CudaBvhRenderer&&) noexcept = default;
CudaBvhRenderer& CudaBvhRenderer::operator=(CudaBvhRenderer&&) noexcept = default;
RenderBuffers CudaBvhRenderer::render(const RenderSettings&, const pt::Camera*) {
    noCudaBackend();
}
const RenderBuffers& CudaBvhRenderer::renderOnDevice(const RenderSettings&, const pt::Camera*) {
    noCudaBackend();
}

RenderBuffers renderBvhCuda(const Scene& scene, const RenderSettings& settings) {
    return CudaBvhRenderer(scene).render(settings);
}
#endif

}  // namespace atrous

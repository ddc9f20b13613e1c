// The public device-choosing renderers (include/atrous/render.h): render(scene, settings, device)
// and SceneRenderer, over the Embree renderer and the CUDA BVH renderer (render/bvh_render.h); and
// the Frame of what they return.
#include <memory>

#include "atrous/render.h"
#include "render/bvh_render.h"

namespace atrous {

Frame RenderBuffers::frame() const {
    Frame f;
    f.set(Buffer::Color, &color).set(Buffer::Variance, &variance).set(Buffer::Albedo, &albedo);
    f.set(Buffer::Normal, &normal).set(Buffer::Position, &position).set(Buffer::Depth, &depth);
    f.set(Buffer::ObjectId, &ids).set(Buffer::Emission, &emission).set(Buffer::Motion, &motion);
    return f;
}

RenderBuffers render(const Scene& scene, const RenderSettings& settings, Device device) {
    return device == Device::Cuda ? renderBvhCuda(scene, settings) : render(scene, settings);
}

struct SceneRenderer::Impl {
    Scene scene;
    std::unique_ptr<CudaBvhRenderer> cuda;
    RenderBuffers host;  // the CPU's renderInPlace
};

SceneRenderer::SceneRenderer(const Scene& scene, Device device) : mImpl(std::make_unique<Impl>()), mDevice(device) {
    mImpl->scene = scene;
    if (device == Device::Cuda) mImpl->cuda = std::make_unique<CudaBvhRenderer>(scene);
}
SceneRenderer::~SceneRenderer() = default;
SceneRenderer::SceneRenderer(SceneRenderer&&) noexcept = default;
SceneRenderer& SceneRenderer::operator=(SceneRenderer&&) noexcept = default;

RenderBuffers SceneRenderer::render(const RenderSettings& settings) {
    return mImpl->cuda ? mImpl->cuda->render(settings) : atrous::render(mImpl->scene, settings);
}

const RenderBuffers& SceneRenderer::renderInPlace(const RenderSettings& settings) {
    if (mImpl->cuda) return mImpl->cuda->renderOnDevice(settings);
    mImpl->host = atrous::render(mImpl->scene, settings);
    return mImpl->host;
}

}  // namespace atrous

// The path tracer over the flattened BVH (src/render/bvh.h) instead of Embree: the same per-pixel
// functor (pt::PathTraceKernel, src/render/integrator.h) with pt::BvhTracer as its intersector.
// renderBvhCuda is the GPU renderer; renderBvhCpu runs the very same code on TBB threads, which
// lets the CPU test suite check the GPU path against the Embree renderer.
#pragma once
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <memory>

#include "atrous/image.h"
#include "atrous/render.h"
#include "render/bvh_tracer.h"
#include "render/integrator.h"

namespace atrous {

// Same buffers, settings and determinism as atrous::render (include/atrous/render.h); the only
// difference is the intersector. Throws InputError for settings out of range.
RenderBuffers renderBvhCpu(const Scene& scene, const RenderSettings& settings);

// The CUDA path tracer (src/cuda/cuda_render.cu): scene and BVH uploaded to the GPU, one thread
// per pixel; buffers come back as host images. Throws InputError when the build has no CUDA
// backend or no GPU is present (a ParamError naming the field `device`).
RenderBuffers renderBvhCuda(const Scene& scene, const RenderSettings& settings);

// The CUDA path tracer for repeated renders of one scene (interactive viewers, sequences): the
// BVH is built and the scene uploaded once, the device buffers are kept between calls, and each
// render may look through another camera. renderBvhCuda(scene, s) equals
// CudaBvhRenderer(scene).render(s). Both throw InputError without CUDA or a GPU.
class CudaBvhRenderer {
public:
    explicit CudaBvhRenderer(const Scene& scene);
    ~CudaBvhRenderer();
    CudaBvhRenderer(CudaBvhRenderer&&) noexcept;
    CudaBvhRenderer& operator=(CudaBvhRenderer&&) noexcept;
    CudaBvhRenderer(const CudaBvhRenderer&) = delete;
    CudaBvhRenderer& operator=(const CudaBvhRenderer&) = delete;

    // Renders with the scene's camera, or with *camera when given. Host buffers as
    // renderBvhCuda's (motion empty): renderOnDevice() and a download of each buffer.
    RenderBuffers render(const RenderSettings& settings, const pt::Camera* camera = nullptr);
    // The same render left on the GPU: the renderer's own device buffers (Device::Cuda images,
    // motion empty), owned by the renderer and valid until the next render call or its
    // destruction (a later call overwrites them; a new size reallocates them). The kernel has
    // finished and been checked when it returns. For GPU pipelines (the viewer) that keep
    // filtering on the device.
    const RenderBuffers& renderOnDevice(const RenderSettings& settings, const pt::Camera* camera = nullptr);

private:
    struct Impl;  // device state (src/cuda/cuda_render.cu)
    std::unique_ptr<Impl> mImpl;
};

namespace detail {

inline RenderBuffers allocateRenderBuffers(int w, int h, Device device) {
    RenderBuffers b;
    for (const RenderBufferField& f : kRenderBufferFields)
        if (f.image != &RenderBuffers::motion) b.*f.image = Image(w, h, 3, device);  // motion: still images have none
    return b;
}

template <class Tracer>
pt::PathTraceKernel<Tracer> makePathTraceKernel(const pt::SceneView& scene, const Tracer& tracer, RenderBuffers& b,
                                                const RenderSettings& s) {
    pt::PathTraceKernel<Tracer> k;
    k.scene = scene;
    k.tracer = tracer;
    k.out = pt::RenderTargets{b.color.view(),    b.variance.view(), b.albedo.view(), b.normal.view(),
                              b.position.view(), b.depth.view(),    b.ids.view(),
                              ImageView{},       b.emission.view()};  // no motion buffer (still images)
    k.width = s.width;
    k.height = s.height;
    k.spp = s.spp;
    k.maxDepth = s.maxDepth;
    k.seed = s.seed;
    k.firstSample = s.firstSample;
    k.lightSampling = s.lightSampling;
    k.backgroundDepth = kBackgroundDepth;
    return k;
}

// Runs a path-tracing kernel over the image on TBB threads in 8x8 tiles (small enough to balance
// the uneven cost of paths, large enough for coherence), in an arena of settings.threads threads
// when that is > 0. The output does not depend on the tiling (RNG streams are per pixel/sample).
template <class Kernel>
void runPathTraceTiles(const Kernel& k, const RenderSettings& settings) {
    const int w = settings.width, h = settings.height;
    auto run = [&] {
        tbb::parallel_for(tbb::blocked_range2d<int>(0, h, 8, 0, w, 8), [&](const tbb::blocked_range2d<int>& r) {
            for (int y = r.rows().begin(); y < r.rows().end(); ++y)
                for (int x = r.cols().begin(); x < r.cols().end(); ++x) k(x, y);
            if (settings.samplesDone)
                settings.samplesDone->fetch_add(uint64_t(r.rows().size()) * uint64_t(r.cols().size()) * uint64_t(settings.spp),
                                                std::memory_order_relaxed);
        });
    };
    if (settings.threads > 0) {
        tbb::task_arena arena(settings.threads);
        arena.execute(run);
    } else {
        run();
    }
}

}  // namespace detail
}  // namespace atrous

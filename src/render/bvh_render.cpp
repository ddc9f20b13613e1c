// CPU driver of the BVH path tracer (the GPU's code path on TBB threads), the settings check
// shared with the CUDA driver, and the CUDA entry point's stand-in for builds without CUDA.
#include "render/bvh_render.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <string>

#include "atrous/error.h"

namespace atrous {
namespace detail {

void validateRenderSettings(const RenderSettings& s) {
    if (s.width <= 0 || s.width > kMaxImageDim)
        throw InputError("--width: " + std::to_string(s.width) + " is out of range (1.." + std::to_string(kMaxImageDim) + ")");
    if (s.height <= 0 || s.height > kMaxImageDim)
        throw InputError("--height: " + std::to_string(s.height) + " is out of range (1.." + std::to_string(kMaxImageDim) + ")");
    if (s.spp <= 0) throw InputError("--spp: must be at least 1 (got " + std::to_string(s.spp) + ")");
    if (s.maxDepth < 0 || s.maxDepth > 1024)
        throw InputError("--max-depth: " + std::to_string(s.maxDepth) + " is out of range (0..1024)");
    if (s.threads < 0) throw InputError("--threads: must be 0 (all cores) or more (got " + std::to_string(s.threads) + ")");
}

}  // namespace detail

RenderBuffers renderBvhCpu(const Scene& scene, const RenderSettings& settings) {
    detail::validateRenderSettings(settings);
    const pt::SceneData& data = scene.data();
    BvhData bvh = pt::buildSceneBvh(data);
    RenderBuffers b = detail::allocateRenderBuffers(settings.width, settings.height, Device::Cpu);
    auto k = detail::makePathTraceKernel(data.view(), pt::makeBvhTracer(bvh.view(), data), b, settings);
    const int w = settings.width, h = settings.height;
    // 8x8 tiles, as the Embree renderer: paths have uneven cost.
    auto run = [&] {
        tbb::parallel_for(tbb::blocked_range2d<int>(0, h, 8, 0, w, 8), [&](const tbb::blocked_range2d<int>& r) {
            for (int y = r.rows().begin(); y < r.rows().end(); ++y)
                for (int x = r.cols().begin(); x < r.cols().end(); ++x) k(x, y);
        });
    };
    if (settings.threads > 0) {
        tbb::task_arena arena(settings.threads);
        arena.execute(run);
    } else {
        run();
    }
    return b;
}

#if !defined(ATROUS_HAVE_CUDA)
RenderBuffers renderBvhCuda(const Scene&, const RenderSettings&) {
    throw InputError("--device cuda: this build of atrous has no CUDA backend");
}
#endif

}  // namespace atrous

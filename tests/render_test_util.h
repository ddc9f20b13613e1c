// Render settings of the small renders the render tests run (tests/render_test.cpp, bvh_render_test.cpp,
// tests/cuda/cuda_render_test.cu): size and sample count, one fixed seed, the rest the defaults.
#pragma once
#include <cstdint>

#include "atrous/denoise.h"
#include "atrous/render.h"

namespace atrous::test {

inline RenderSettings smallRender(int w, int h, int spp, uint32_t seed) {
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.spp = spp;
    s.seed = seed;
    return s;
}

// A small render of a built-in scene with the buffers the still filters read (colour, variance,
// albedo, normal, depth, emission), as Frame.
struct RenderedInputs {
    RenderBuffers b;
    RenderedInputs(const char* scene, int w, int h, int spp, uint32_t seed)
        : b(render(Scene::builtin(scene), smallRender(w, h, spp, seed))) {}
    Frame inputs() const {
        Frame in;
        in.color = &b.color, in.variance = &b.variance, in.albedo = &b.albedo, in.normal = &b.normal;
        in.depth = &b.depth, in.emission = &b.emission;
        return in;
    }
};

}  // namespace atrous::test

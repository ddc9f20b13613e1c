// Render settings of the small renders the render tests run (tests/render_test.cpp, bvh_render_test.cpp,
// tests/cuda/cuda_render_test.cu): size and sample count, one fixed seed, the rest the defaults.
#pragma once
#include <cstdint>

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

}  // namespace atrous::test

// Per-pixel functors behind include/atrous/interop.h, shared by the CPU and CUDA backends.
#pragma once
#include <cstdint>

#include "atrous/image.h"

namespace atrous::detail {

struct GatherStrided {
    const float* src;
    int64_t sy, sx, sc;
    int srcChannels;
    ImageView dst;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float* p = src + y * sy + x * sx;
        for (int c = 0; c < dst.channels; ++c) dst(x, y, c) = p[(srcChannels == 1 ? 0 : c) * sc];
    }
};

struct ScatterInterleaved {
    ImageView src;
    float* dst;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float* p = dst + (size_t(y) * src.width + x) * size_t(src.channels);
        for (int c = 0; c < src.channels; ++c) p[c] = src(x, y, c);
    }
};

// CUDA halves (src/cuda/cuda_strided.cu; the no-CUDA build throws).
void cudaGatherStrided(const GatherStrided& f, int width, int height);
void cudaScatterInterleaved(const ScatterInterleaved& f, int width, int height);

}  // namespace atrous::detail

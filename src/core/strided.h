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

// The common host layout, C-contiguous H x W x 3 (numpy's default): a row at a time with the
// channel stride a constant, so the compiler vectorises the de-interleave. The same values as
// GatherStrided.
struct GatherInterleaved3 {
    const float* src;
    int64_t sy;
    ImageView dst;
    void operator()(int y) const {
        const float* ATROUS_RESTRICT p = src + y * sy;
        float* ATROUS_RESTRICT r = dst.channel(0) + size_t(y) * size_t(dst.width);
        float* ATROUS_RESTRICT g = dst.channel(1) + size_t(y) * size_t(dst.width);
        float* ATROUS_RESTRICT b = dst.channel(2) + size_t(y) * size_t(dst.width);
        for (int x = 0; x < dst.width; ++x) {
            r[x] = p[3 * x];
            g[x] = p[3 * x + 1];
            b[x] = p[3 * x + 2];
        }
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

// The inverse for 3 channels, a row at a time (imageToInterleaved's host path).
struct ScatterInterleaved3 {
    ImageView src;
    float* dst;
    void operator()(int y) const {
        const size_t w = size_t(src.width);
        const float* ATROUS_RESTRICT r = src.channel(0) + size_t(y) * w;
        const float* ATROUS_RESTRICT g = src.channel(1) + size_t(y) * w;
        const float* ATROUS_RESTRICT b = src.channel(2) + size_t(y) * w;
        float* ATROUS_RESTRICT p = dst + size_t(y) * w * 3;
        for (size_t x = 0; x < w; ++x) {
            p[3 * x] = r[x];
            p[3 * x + 1] = g[x];
            p[3 * x + 2] = b[x];
        }
    }
};

// CUDA halves (src/cuda/cuda_strided.cu; the no-CUDA build throws).
void cudaGatherStrided(const GatherStrided& f, int width, int height);
void cudaScatterInterleaved(const ScatterInterleaved& f, int width, int height);

}  // namespace atrous::detail

// The synthetic box-like scene the filter benchmarks time on (bench_denoise, bench_learned): a few
// planar regions with smooth shading, Monte Carlo-like noise and every buffer. Its two variants
// are the inputs each benchmark's published figures were measured on.
#pragma once
#include <algorithm>
#include <cmath>
#include <random>

#include "atrous/denoise.h"

namespace atrous::bench {

struct BoxScene {
    // learnedVariant: bench_learned's inputs (a sky band of depth 1e30 in the top tenth, colour
    // clamped at 0); else bench_denoise's.
    Image color, variance, albedo, normal, position, depth, ids;
    BoxScene(int w, int h, bool learnedVariant)
        : color(w, h, 3), variance(w, h, 3), albedo(w, h, 3), normal(w, h, 3), position(w, h, 3), depth(w, h, 3),
          ids(w, h, 3) {
        std::mt19937 rng(1);
        std::normal_distribution<float> g(0.0f, 1.0f);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const float u = float(x) / w, v = float(y) / h;
                const int region = (u > 0.3f && u < 0.7f && v > 0.4f) ? 1 : (u < 0.15f ? 2 : 0);
                const float z = region == 1 ? 3.0f : (learnedVariant && v < 0.1f ? 1e30f : 5.0f);
                for (int c = 0; c < 3; ++c) {
                    const float a = region == 2 ? (c == 0 ? 0.8f : 0.2f) : 0.7f;
                    const float t = (0.3f + 0.5f * v) * a, var = 0.05f * (0.02f + t);
                    const float noisy = t + std::sqrt(var) * g(rng);
                    color(x, y, c) = learnedVariant ? std::max(noisy, 0.0f) : noisy;
                    variance(x, y, c) = var;
                    albedo(x, y, c) = a;
                    normal(x, y, c) = region == 2 ? (c == 0 ? 1.0f : 0.0f) : (c == 2 ? 1.0f : 0.0f);
                    depth(x, y, c) = z;
                    ids(x, y, c) = c < 2 ? float(region) : 0.0f;
                }
                const float zp = region == 1 ? 3.0f : 5.0f;
                position(x, y, 0) = (u - 0.5f) * zp;
                position(x, y, 1) = (v - 0.5f) * zp;
                position(x, y, 2) = zp;
            }
    }
    // Every buffer (bench_denoise); colour, variance, albedo, normal and depth (bench_learned).
    Frame allInputs() const {
        Frame in = learnedInputs();
        in.position = &position, in.ids = &ids;
        return in;
    }
    Frame learnedInputs() const {
        Frame in;
        in.color = &color, in.variance = &variance, in.albedo = &albedo, in.normal = &normal, in.depth = &depth;
        return in;
    }
};

}  // namespace atrous::bench

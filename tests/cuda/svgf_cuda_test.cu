// SVGF CPU-vs-CUDA parity: the same stage functors run by CpuExec and CudaExec on the same
// synthetic sequence must agree to float tolerance. Skipped where no GPU is available.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "atrous/device.h"
#include "atrous/svgf.h"
#include "../learned_fixture.h"

using namespace atrous;

namespace {

struct CudaTestFrame {
    Image color, albedo, normal, depth, ids, motion, emission;
};

// A textured, tilted ground plane, a sky strip and a box sliding right by 3 px per frame, with
// Gaussian noise (and a few NaN samples) on the colour, and a light (emission 17) in the box's top
// rows whose bottom edge row is covered at random (1-spp coverage noise on a moving emitter).
CudaTestFrame makeFrame(int w, int h, int t) {
    CudaTestFrame f{Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image(w, h, 3),
            Image(w, h, 3)};
    std::bernoulli_distribution cover(0.5);
    std::mt19937 rng(99u + unsigned(t));
    std::normal_distribution<float> gauss(0.0f, 0.2f);
    const int bx = w / 4 + 3 * t, by = h / 3, bs = w / 4;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool sky = y < 4, box = x >= bx && x < bx + bs && y >= by && y < by + bs;
            float a = box ? 0.5f : (((x / 8 + y / 8) % 2) ? 0.8f : 0.2f);
            float e = sky ? 0.5f : (box ? 2.0f : 1.0f + 0.5f * std::sin(float(x) / 10.0f));
            float n = gauss(rng);
            bool light = box && (y < by + 4 || (y == by + 4 && cover(rng)));
            for (int c = 0; c < 3; ++c) {
                f.albedo(x, y, c) = sky ? 1.0f : a;
                f.emission(x, y, c) = light ? 17.0f : 0.0f;
                f.color(x, y, c) = (sky ? 1.0f : a) * e + n + f.emission(x, y, c);
                f.depth(x, y, c) = sky ? 1e30f : (box ? 3.0f : 4.0f + 0.05f * float(y));
                f.ids(x, y, c) = sky ? -1.0f : (box ? 1.0f : 0.0f);
            }
            f.normal(x, y, 1) = sky ? 0.0f : (box ? 0.0f : 0.6f);
            f.normal(x, y, 2) = sky ? 0.0f : (box ? 1.0f : 0.8f);
            f.motion(x, y, 0) = box ? -3.0f : 0.0f;
        }
    f.color(7, 20, 1) = std::nanf("");
    return f;
}

// The SVGF inputs of a test frame.
Frame inputsOf(const CudaTestFrame& f) {
    Frame in;
    in.color = &f.color, in.albedo = &f.albedo, in.normal = &f.normal;
    in.depth = &f.depth, in.ids = &f.ids, in.motion = &f.motion, in.emission = &f.emission;
    return in;
}

// max |a - b| / (1 + |a|) over the values (+inf on a size mismatch or a non-finite value of b).
float maxRelDiff(const Image& a, const Image& b) {
    if (a.size() != b.size()) return INFINITY;
    float maxDiff = 0.0f;
    for (size_t i = 0; i < a.size(); ++i) {
        if (!std::isfinite(b.data()[i])) return INFINITY;
        maxDiff = std::fmax(maxDiff, std::fabs(a.data()[i] - b.data()[i]) / (1.0f + std::fabs(a.data()[i])));
    }
    return maxDiff;
}

}  // namespace

TEST(SvgfCuda, MatchesTheCpuBackend) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    for (bool taa : {false, true}) {
        SvgfParams p;
        p.taa = taa;
        p.emissionMotionAlpha = taa ? 0.1f : 0.0f;  // both α rules of the emission accumulation
        SvgfDenoiser cpu(p, Device::Cpu), gpu(p, Device::Cuda);
        for (int t = 0; t < 5; ++t) {
            CudaTestFrame f = makeFrame(96, 64, t);
            const Frame in = inputsOf(f);
            Image a = cpu.denoiseFrame(in);
            Image b = gpu.denoiseFrame(in);  // host inputs are uploaded by the driver
            const float maxDiff = maxRelDiff(a, b);
            // Same functors and fastExp on both sides; only FMA contraction and summation order
            // differ (~1e-6 relative per operation), amplified a little through the edge stops.
            EXPECT_LT(maxDiff, 2e-3f) << "frame " << t << (taa ? " with TAA" : "");
        }
    }
}

// The learned spatial filter (SvgfParams::learnedSpatial): the same SVGF stages and the learned
// cascade's functors on both sides (filters/learned.h; the CPU runs its row engine, held to the
// functors by tests/svgf_learned_test.cpp). The same bound as above: the cascade alone is held to
// 1e-5 (tests/cuda/learned_cuda_test.cu), SVGF's own stages dominate.
TEST(SvgfCuda, LearnedSpatialMatchesTheCpuBackend) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    for (int tap : {0, -1}) {
        SvgfParams p;
        p.learnedSpatial = true;
        p.feedbackTap = tap;
        SvgfDenoiser cpu(p, Device::Cpu), gpu(p, Device::Cuda);
        for (int t = 0; t < 5; ++t) {
            CudaTestFrame f = makeFrame(96, 64, t);
            const Frame in = inputsOf(f);
            Image a = cpu.denoiseFrame(in);
            Image b = gpu.denoiseFrame(in);
            const float maxDiff = maxRelDiff(a, b);
            EXPECT_LT(maxDiff, 2e-3f) << "frame " << t << ", feedback tap " << tap;
        }
    }
}

// Given weights (the parity fixture's) on both backends, across a change of size: CUDA keeps the
// network's device copy and the cascade's temporaries between frames (filters::LearnedCache), so a
// stale copy or stale planes would show here; same bound as above. The weights reach the GPU's
// cascade: the built-in ones give another output.
TEST(SvgfCuda, LearnedSpatialRunsTheGivenWeightsAcrossSizes) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    const LearnedWeights w = LearnedWeights::parse(test::fixture().weights.data(), test::fixture().weights.size(), "fixture");
    SvgfParams p;
    p.learnedSpatial = true;
    SvgfDenoiser cpu(p, Device::Cpu, w), gpu(p, Device::Cuda, w), gpuBuiltin(p, Device::Cuda);
    const int sizes[][2] = {{96, 64}, {64, 40}};
    for (const auto& sz : sizes) {
        for (int t = 0; t < 3; ++t) {
            CudaTestFrame f = makeFrame(sz[0], sz[1], t);
            const Frame in = inputsOf(f);
            Image a = cpu.denoiseFrame(in), b = gpu.denoiseFrame(in), c = gpuBuiltin.denoiseFrame(in);
            const float maxDiff = maxRelDiff(a, b);
            float other = 0.0f;
            for (size_t i = 0; i < b.size() && i < c.size(); ++i) other = std::fmax(other, std::fabs(b.data()[i] - c.data()[i]));
            EXPECT_LT(maxDiff, 2e-3f) << sz[0] << "x" << sz[1] << " frame " << t;
            EXPECT_GT(other, 1e-2f) << sz[0] << "x" << sz[1] << " frame " << t;
        }
    }
}

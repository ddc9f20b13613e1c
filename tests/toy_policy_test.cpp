// A new edge stop is a new policy of the shared à-trous level (filters/atrous_level.h), not a new
// filter stack: ToyStop below, a cross-bilateral stop on a 1-channel guide image, is the whole of
// one. It runs through the functor (what CudaExec launches; tests/cuda/toy_policy_cuda_test.cu
// compiles it for the GPU) and through the CPU row engine (src/cpu/atrous_rows.h), and the two
// agree; with the stop off it is the plain B3 à-trous; and it keeps an edge of its guide.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/parallel.h"
#include "cpu/atrous_rows.h"
#include "toy_policy.h"

using namespace atrous;

namespace {

Image noisy(int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> g(0.0f, 0.1f);
    Image img(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) img(x, y, c) = (x < w / 2 ? 0.2f : 0.8f) + g(rng);
    return img;
}

// The guide: 0 left of the middle, 1 right of it.
Image stepGuide(int w, int h) {
    Image img(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) img(x, y, 0) = x < w / 2 ? 0.0f : 1.0f;
    return img;
}

// Plain B3 à-trous of one level, taps outside the image dropped and the rest renormalised.
Image plainLevel(const Image& in, int step) {
    Image out(in.width(), in.height(), 3);
    for (int y = 0; y < in.height(); ++y)
        for (int x = 0; x < in.width(); ++x) {
            double s[3] = {0, 0, 0}, ws = 0;
            for (int qy = -2; qy <= 2; ++qy)
                for (int qx = -2; qx <= 2; ++qx) {
                    const int xx = x + qx * step, yy = y + qy * step;
                    if (xx < 0 || yy < 0 || xx >= in.width() || yy >= in.height()) continue;
                    const double h = double(filters::b3(qx)) * filters::b3(qy);
                    ws += h;
                    for (int c = 0; c < 3; ++c) s[c] += h * in(xx, yy, c);
                }
            for (int c = 0; c < 3; ++c) out(x, y, c) = float(s[c] / ws);
        }
    return out;
}

float maxAbsDiff(const Image& a, const Image& b) {
    float d = 0.0f;
    for (size_t i = 0; i < a.size(); ++i) d = std::fmax(d, std::fabs(a.data()[i] - b.data()[i]));
    return d;
}

toy::ToyStop makeStop(const Image& in, const Image& guide, Image& out, int step, float invSigma2) {
    toy::ToyStop t;
    t.step_ = step;
    t.invSigma2 = invSigma2;
    t.in = in.view(), t.guide = guide.view(), t.out = out.view();
    return t;
}

}  // namespace

TEST(ToyPolicy, RowEngineEqualsTheFunctor) {
    // Sizes that are not a multiple of the vector width, and images smaller than the reach.
    const int sizes[][2] = {{67, 45}, {9, 7}, {3, 2}, {1, 1}, {40, 40}};
    std::vector<bool> isas = {false};
    if (cpuHasAvx512()) isas.push_back(true);
    for (const auto& sz : sizes) {
        const Image in = noisy(sz[0], sz[1], 3), guide = stepGuide(sz[0], sz[1]);
        for (int step : {1, 2, 4, 8})
            for (bool avx512 : isas) {
                Image ref(sz[0], sz[1], 3), got(sz[0], sz[1], 3);
                filters::runAtrousLevelFunctor(CpuExec{}, makeStop(in, guide, ref, step, 50.0f));
                cpu::runAtrousRows(makeStop(in, guide, got, step, 50.0f), avx512);
                // Same taps in the same order per pixel; only FMA contraction may differ.
                EXPECT_LT(maxAbsDiff(got, ref), 1e-6f) << sz[0] << "x" << sz[1] << " step " << step;
            }
    }
}

TEST(ToyPolicy, WithoutTheStopItIsThePlainB3Atrous) {
    const Image in = noisy(33, 21, 4), guide = stepGuide(33, 21);
    for (int step : {1, 4}) {
        Image got(33, 21, 3);
        cpu::runAtrousRows(makeStop(in, guide, got, step, 0.0f), cpuHasAvx512());
        EXPECT_LT(maxAbsDiff(got, plainLevel(in, step)), 1e-6f) << "step " << step;
    }
}

TEST(ToyPolicy, KeepsTheGuidesEdge) {
    const int w = 32, h = 64;
    const Image in = noisy(w, h, 5), guide = stepGuide(w, h);
    Image got(w, h, 3);
    cpu::runAtrousRows(makeStop(in, guide, got, 2, 1e4f), cpuHasAvx512());
    // Next to the edge each side keeps its own mean (0.2 | 0.8); the plain filter mixes them.
    const Image plain = plainLevel(in, 2);
    double left = 0, right = 0, plainLeft = 0;
    for (int y = 0; y < h; ++y) {
        left += got(w / 2 - 1, y, 0) / h;
        right += got(w / 2, y, 0) / h;
        plainLeft += plain(w / 2 - 1, y, 0) / h;
    }
    EXPECT_NEAR(left, 0.2, 0.06);
    EXPECT_NEAR(right, 0.8, 0.06);
    EXPECT_GT(plainLeft, 0.3);
}

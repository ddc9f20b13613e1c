// Metrics (docs/eval.md, "What is measured") against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "atrous/error.h"
#include "atrous/metrics.h"

using namespace atrous;

TEST(Metrics, IdenticalImages) {
    Image a(20, 20, 3);
    a.fill(0.3f);
    ImageMetrics m = computeMetrics(a, a);
    EXPECT_EQ(m.mse, 0.0);
    EXPECT_EQ(m.relMse, 0.0);
    EXPECT_EQ(m.psnr, 100.0);  // capped
    EXPECT_NEAR(m.ssim, 1.0, 1e-12);
}

TEST(Metrics, KnownValues) {
    Image r(16, 8, 3), x(16, 8, 3);
    r.fill(1.0f);
    x.fill(1.5f);
    ImageMetrics m = computeMetrics(x, r);
    EXPECT_NEAR(m.mse, 0.25, 1e-9);
    EXPECT_NEAR(m.relMse, 0.25 / 1.01, 1e-9);
    // Tonemap: (1/2)^(1/2.2) and (0.6)^(1/2.2).
    const double t0 = std::pow(0.5, 1 / 2.2), t1 = std::pow(0.6, 1 / 2.2);
    EXPECT_NEAR(m.psnr, 10 * std::log10(1.0 / ((t1 - t0) * (t1 - t0))), 1e-4);
    EXPECT_NEAR(tonemapForMetrics(1.0f), t0, 1e-6);
    EXPECT_EQ(tonemapForMetrics(-1.0f), 0.0f);
    EXPECT_EQ(tonemapForMetrics(NAN), 0.0f);
}

TEST(Metrics, SsimDropsWithNoiseAndNanCountsAsError) {
    Image r(64, 64, 3), a(64, 64, 3), b(64, 64, 3);
    std::mt19937 rng(1);
    std::normal_distribution<float> g(0.0f, 1.0f);
    for (size_t i = 0; i < r.size(); ++i) {
        r.data()[i] = 0.5f + 0.3f * std::sin(0.2f * float(i % 64));
        const float n = g(rng);
        a.data()[i] = r.data()[i] + 0.02f * n;
        b.data()[i] = r.data()[i] + 0.2f * n;
    }
    ImageMetrics ma = computeMetrics(a, r), mb = computeMetrics(b, r);
    EXPECT_GT(ma.ssim, mb.ssim);
    EXPECT_GT(ma.psnr, mb.psnr);
    EXPECT_LT(ma.mse, mb.mse);
    EXPECT_LE(ma.ssim, 1.0);
    EXPECT_EQ(ma.nonFinitePixels, 0);
    a.data()[5] = NAN;
    a.data()[r.plane() + 5] = INFINITY;  // same pixel, another channel: still one pixel
    a.data()[7] = -INFINITY;
    r.data()[2 * r.plane() + 9] = NAN;
    ImageMetrics mn = computeMetrics(a, r);
    EXPECT_TRUE(std::isfinite(mn.mse));
    EXPECT_GT(mn.mse, ma.mse);
    EXPECT_EQ(mn.nonFinitePixels, 2);
    EXPECT_EQ(mn.referenceNonFinitePixels, 1);
}

TEST(Metrics, ErrorMapsAndSizeMismatch) {
    Image r(4, 4, 3), x(4, 4, 3);
    r.fill(0.0f);
    x.fill(0.0f);
    x(1, 2, 0) = 3.0f;
    Image se = squaredErrorMap(x, r), rel = relativeErrorMap(x, r);
    EXPECT_NEAR(se(1, 2, 1), 3.0f, 1e-6f);  // 9 / 3 channels
    EXPECT_NEAR(rel(1, 2, 2), 300.0f, 1e-3f);
    EXPECT_EQ(se(0, 0, 0), 0.0f);
    Image small(3, 4, 3);
    EXPECT_THROW(computeMetrics(small, r), InputError);
}

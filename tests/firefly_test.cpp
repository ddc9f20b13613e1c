// Firefly suppression (docs/denoising.md, "Fireflies") and non-finite samples: fireflies are brought down to
// the local bound, ordinary noise and dense bright samples (light, not outliers) are left alone, NaN/Inf
// never reach the output.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "atrous/denoise.h"
#include "core/parallel.h"
#include "denoise_test_util.h"
#include "filters/prepass.h"

using namespace atrous;
using namespace atrous::test;

namespace {

// Flat grey 0.5 with Gaussian noise σ = 0.05 and a matching variance buffer (σ² per channel).
struct Flat {
    Image color, var;
    Flat(int w, int h, unsigned seed) : color(w, h, 3), var(w, h, 3) {
        std::mt19937 rng(seed);
        std::normal_distribution<float> g(0.0f, 0.05f);
        for (size_t i = 0; i < color.size(); ++i) color.data()[i] = 0.5f + g(rng);
        var.fill(0.05f * 0.05f);
    }
    Frame inputs() const { return inputsOf(color, var); }
    // A bright pixel: `value` in R, G, B with a variance of the mean of sd² per channel.
    void spike(int x, int y, float value, float sd) {
        for (int c = 0; c < 3; ++c) {
            color(x, y, c) = value;
            var(x, y, c) = sd * sd;
        }
    }
    // The report of a denoise with the default options.
    DenoiseReport defaultReport() const {
        DenoiseReport rep;
        DenoiseOptions o;
        test::denoiseReporting(inputs(), o, rep);
        return rep;
    }
};

}  // namespace

TEST(Firefly, ClampsAnOutlierAndLeavesNoiseAlone) {
    Flat f(64, 64, 1);
    // One firefly: one huge sample among n raises the mean by E and reports a variance of the
    // mean of about E² (what the renderer's variance buffer holds for it).
    f.spike(30, 20, 500.0f, 500.0f);
    DenoiseReport rep;
    DenoiseOptions o;
    o.method = DenoiseMethod::Eaw;
    Image out = test::denoiseReporting(f.inputs(), o, rep);
    // Gaussian noise exceeds 4 local σ with probability ~3e-5 per pixel: of 4096 pixels, the
    // firefly plus at most a handful.
    EXPECT_GE(rep.firefliesClamped, 1);
    EXPECT_LE(rep.firefliesClamped, 5);
    // The firefly's energy is removed: without suppression it would add 500·1/4096 = 0.12 to the
    // mean luminance; with it the mean stays within 0.005 of 0.5.
    EXPECT_NEAR(rep.meanLuminanceAfterFirefly, 0.5, 0.005);
    EXPECT_GT(rep.meanLuminanceIn, 0.6);
    // And the output around it is not a blotch: every pixel within 0.2 of the flat level.
    for (size_t i = 0; i < out.size(); ++i) ASSERT_NEAR(out.data()[i], 0.5f, 0.2f);
    // Without suppression the blotch is there.
    o.firefly.enabled = false;
    Image raw = test::denoiseReporting(f.inputs(), o, rep);
    EXPECT_GT(raw(30, 20, 0), 2.0f);
}

TEST(Firefly, ParametersChangeTheOutput) {
    Flat f(48, 48, 2);
    f.spike(10, 10, 50.0f, 50.0f);
    DenoiseOptions base;
    const Image ref = denoise(f.inputs(), base);
    DenoiseOptions off = base;
    off.firefly.enabled = false;
    EXPECT_GT(maxAbsDiff(denoise(f.inputs(), off), ref), 1e-3);
    DenoiseOptions k = base;
    k.firefly.k = 1.0f;  // clamps ordinary noise too
    EXPECT_GT(maxAbsDiff(denoise(f.inputs(), k), ref), 1e-4);
}

TEST(Firefly, TwoPixelClusterIsClamped) {
    // The brightest neighbour is left out of the local statistics, so a firefly next to another
    // one does not vouch for it.
    Flat f(32, 32, 3);
    f.spike(10, 10, 200.0f, 200.0f);
    f.spike(11, 10, 150.0f, 150.0f);
    const DenoiseReport rep = f.defaultReport();
    EXPECT_NEAR(rep.meanLuminanceAfterFirefly, 0.5, 0.01);
}

TEST(Firefly, BrightPixelWithLowOwnVarianceIsSignal) {
    // The sun seen directly: very bright, but its own standard deviation (here 10% of its excess)
    // says most samples agree, so it is kept (docs/denoising.md, "Fireflies": only implausible pixels).
    Flat f(32, 32, 5);
    f.spike(16, 16, 1000.0f, 100.0f);
    const DenoiseReport rep = f.defaultReport();
    EXPECT_EQ(rep.firefliesClamped, 0);
    EXPECT_NEAR(rep.meanLuminanceAfterFirefly, rep.meanLuminanceIn, 1e-6);
}

TEST(Firefly, DenseBrightSamplesAreLightNotFireflies) {
    // A flat 0.5 (variance 0.0025 per channel, Σ w_c² v_c = 0.0014 in luminance: the bound is
    // 0.5 + k 0.0375) with bright 0.75 pixels whose own
    // variance says one outlier made each: on a 3-pixel lattice over the left half (1 pixel in 9,
    // as a sun patch reached by one bounce at a few spp) and once, alone, on the right.
    const int w = 64, h = 64;
    Image c(w, h, 3), v(w, h, 3);
    c.fill(0.5f);
    v.fill(0.0025f);
    auto bright = [&](int x, int y) {
        for (int ch = 0; ch < 3; ++ch) c(x, y, ch) = 0.75f, v(x, y, ch) = 0.5625f;
    };
    for (int y = 1; y < h; y += 3)
        for (int x = 1; x < w / 2; x += 3) bright(x, y);
    bright(50, 30);
    Image co(w, h, 3), vo(w, h, 3), flag(w, h, 1), tmp(w, h, 1), sums(w, h, 1);
    const filters::FireflyClamp pass{4.0f, 1, c.view(), v.view(), co.view(), vo.view(), flag.view()};
    filters::runFireflyClamp(CpuExec{}, pass);
    // The pass alone clamps every bright pixel to 0.65 (what the dense step must undo)...
    for (int y = 1; y < h; y += 3)
        for (int x = 1; x < w / 2; x += 3) ASSERT_NEAR(co(x, y, 0), 0.65f, 1e-4f) << x << "," << y;
    filters::runFireflyDense(CpuExec{}, pass, tmp.view(), sums.view());
    // ...the dense step gives the lattice its light back where its window is dense (1/9 > 0.06:
    // k ≈ 7.4, bound 0.78), away from the half's edge where the window also sees the right half...
    for (int y = 7; y < h - 7; y += 3)
        for (int x = 7; x < w / 2 - 8; x += 3) {
            ASSERT_EQ(co(x, y, 1), 0.75f) << x << "," << y;
            ASSERT_EQ(flag(x, y, 0), 0.0f) << x << "," << y;
        }
    // ...and the lone one stays clamped, the flat pixels untouched.
    EXPECT_NEAR(co(50, 30, 0), 0.65f, 1e-4f);
    EXPECT_EQ(flag(50, 30, 0), 1.0f);
    EXPECT_EQ(co(40, 10, 2), 0.5f);
    // Through the library (measured: 52 of the 232 bright pixels clamped, on the lattice's right
    // edge, whose windows reach past it, and the lone one; all of them without the dense step) the
    // light stays: the pass alone took 40% of the bright pixels' excess over 0.5 (0.75 -> 0.65).
    DenoiseReport rep;
    DenoiseOptions o;
    o.method = DenoiseMethod::Eaw;
    test::denoiseReporting(test::inputsOf(c, v), o, rep);
    EXPECT_LE(rep.firefliesClamped, 64);
    EXPECT_GT(rep.firefliesClamped, 0);
    EXPECT_NEAR(rep.meanLuminanceAfterFirefly, rep.meanLuminanceIn, 0.1 * (rep.meanLuminanceIn - 0.5));
}

TEST(NonFinite, NanAndInfNeverSpread) {
    SyntheticScene s = makeScene(40, 40, 0.3f, 4);
    s.noisy(5, 5, 0) = NAN;
    s.noisy(20, 20, 1) = INFINITY;
    s.noisy(21, 20, 2) = -INFINITY;
    for (int x = 30; x < 40; ++x)
        for (int c = 0; c < 3; ++c) s.noisy(x, 39, c) = NAN;  // a run of missing pixels at the edge
    s.variance(7, 7, 0) = NAN;
    s.normal(8, 8, 0) = NAN;
    s.position(9, 9, 2) = INFINITY;
    s.depth(3, 3, 0) = INFINITY;
    for (auto m : {DenoiseMethod::Eaw, DenoiseMethod::Sure}) {
        for (bool estimate : {false, true}) {
            Frame in = s.inputs();
            if (estimate) in.variance = nullptr;
            DenoiseReport rep;
            DenoiseOptions o;
            o.method = m;
            Image out = test::denoiseReporting(in, o, rep);
            EXPECT_TRUE(allFinite(out)) << denoiseMethodName(m);
            EXPECT_EQ(rep.nonFinitePixels, 13);
            // Missing pixels are filled from their neighbourhood: close to the truth there.
            EXPECT_NEAR(out(5, 5, 0), s.truth(5, 5, 0), 0.3f);
            EXPECT_NEAR(out(20, 20, 1), s.truth(20, 20, 1), 0.3f);
        }
    }
}

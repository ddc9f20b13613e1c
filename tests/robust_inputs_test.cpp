// Robustness rules for other renderers' buffers (docs/algorithms.md): black albedo where the
// colour is not (glass, mirrors, lights in Mitsuba's and Cycles' albedo passes), and a firefly's
// luminance variance with correlated channels. Each test fails without its rule.
#include <gtest/gtest.h>

#include <cmath>

#include "atrous/denoise.h"
#include "denoise_test_util.h"

using namespace atrous;
using namespace atrous::test;

namespace {

// makeScene with region 2 (the disk) turned into "glass": the albedo pass is 0 there and on its
// rim falls with the disk's coverage of the pixel (rim pixels of tiny albedo), while the colour
// (what is seen through it) keeps its value and noise.
SyntheticScene glassScene(unsigned seed) {
    SyntheticScene s = makeScene(64, 64, 0.3f, seed);
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const float u = (x + 0.5f) / 64, v = (y + 0.5f) / 64;
            const float r = std::sqrt((u - 0.7f) * (u - 0.7f) + (v - 0.55f) * (v - 0.55f));
            // Coverage of the disk (radius 0.2) over about one pixel.
            const float cover = std::fmin(std::fmax((0.2f - r) * 64.0f + 0.5f, 0.0f), 1.0f);
            if (cover <= 0.0f) continue;
            for (int c = 0; c < 3; ++c) s.albedo(x, y, c) = (1.0f - cover) * 0.02f * s.albedo(x, y, c);
        }
    return s;
}

}  // namespace

TEST(RobustInputs, BlackAlbedoDoesNotBlowUp) {
    const SyntheticScene s = glassScene(41);
    const double noisy = mse(s.noisy, s.truth);
    for (DenoiseMethod m : {DenoiseMethod::Eaw, DenoiseMethod::Sure}) {
        DenoiseOptions o;
        o.method = m;
        const double fixed = mse(denoise(s.inputs(), o), s.truth);
        o.albedoFloor = 0.0f;  // the plain max(albedo, 1e-3): what the filters did before the rule
        const double plain = mse(denoise(s.inputs(), o), s.truth);
        // Measured (both methods): plain 0.379 = 9.8x the noisy MSE 0.0386 (the rim's demodulated
        // values are 50-1000x the colour and spread), with the floor 0.00135 = 1/28 of it. The
        // bounds leave a 9x margin each way.
        EXPECT_GT(plain, noisy) << denoiseMethodName(m);
        EXPECT_LT(fixed, noisy / 3) << denoiseMethodName(m);
    }
}

TEST(RobustInputs, AlbedoFloorLeavesOrdinaryAlbedoAlone) {
    // Every albedo channel maximum of makeScene is >= 0.7 > the floor: output bit-equal to floor 0.
    const SyntheticScene s = makeScene(32, 32, 0.3f, 42);
    DenoiseOptions a, b;
    b.albedoFloor = 0.0f;
    EXPECT_EQ(maxAbsDiff(denoise(s.inputs(), a), denoise(s.inputs(), b)), 0.0);
}

TEST(RobustInputs, WhiteFireflyWithTheVarianceOfOneOutlierIsClamped) {
    // One pixel at 6.0 on 0.1. One outlier among n samples raises the mean by E with a standard
    // deviation of ~E (docs/algorithms.md), here E = 5.9, var ~35; the rule clamps when the
    // pixel's luminance std exceeds E/2 = 2.95, i.e. var > 8.7 with correlated channels. The
    // independent-channel form (std = 0.75 sqrt(var)) kept it up to var 15.5.
    Image c(32, 32, 3), v(32, 32, 3);
    for (size_t i = 0; i < c.size(); ++i) c.data()[i] = 0.1f, v.data()[i] = 1e-4f;
    for (float var : {9.0f, 13.0f, 35.0f}) {
        for (int ch = 0; ch < 3; ++ch) c(16, 16, ch) = 6.0f, v(16, 16, ch) = var;
        DenoiseInputs in;
        in.color = &c;
        in.variance = &v;
        for (DenoiseMethod m : {DenoiseMethod::Eaw, DenoiseMethod::Sure}) {
            DenoiseOptions o;
            o.method = m;
            EXPECT_LT(denoise(in, o)(16, 16, 0), 0.5f) << var << " " << denoiseMethodName(m);
        }
    }
    // A highlight most samples see (std 1, well below E/2) is kept.
    for (int ch = 0; ch < 3; ++ch) v(16, 16, ch) = 1.0f;
    DenoiseInputs in;
    in.color = &c;
    in.variance = &v;
    EXPECT_GT(denoise(in, DenoiseOptions{})(16, 16, 0), 5.0f);
}

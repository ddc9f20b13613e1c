// DetailEnergy's albedo fit (src/filters/noise_estimate.h): detail of the demodulated colour that
// the albedo's own detail explains is not counted as noise, pure noise is (nearly) all kept, and
// with a flat or absent albedo nothing changes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "atrous/image.h"
#include "filters/noise_estimate.h"

using namespace atrous;
using namespace atrous::filters;

namespace {

// Mean energy of channel 0..2 over the image, DetailEnergy run on the host, with or without the fit.
double meanEnergy(const Image& color, const Image& albedo, bool fit, Image* energyOut = nullptr) {
    const int w = color.width(), h = color.height();
    Image normal(w, h, 3), depth(w, h, 3), energy(w, h, 3);
    for (size_t i = 0; i < depth.size(); ++i) depth.data()[i] = 1.0f;  // one surface: no geometric edge
    DetailEnergy de{color.view(), energy.view(), normal.view(), depth.view()};
    if (fit) de.albedo = albedo.view();
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) de(x, y);
    double s = 0;
    for (size_t i = 0; i < energy.size(); ++i) s += energy.data()[i];
    if (energyOut) *energyOut = std::move(energy);
    return s / double(energy.size() ? energy.size() : 1);
}

// A fine texture: albedo 0.2 / 0.8 in a 2-pixel checker.
Image checkerAlbedo(int w, int h) {
    Image a(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) a(x, y, c) = ((x + y) % 2) ? 0.8f : 0.2f;
    return a;
}

}  // namespace

TEST(NoiseFit, TextureLeakingThroughDemodulationIsNotNoise) {
    // c / a' = D + S / a: a specular layer S that the albedo does not multiply, divided by it.
    const int w = 32, h = 32;
    const Image a = checkerAlbedo(w, h);
    Image d(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) d(x, y, c) = 0.5f + 0.3f / a(x, y, c);
    const double without = meanEnergy(d, a, false), with = meanEnergy(d, a, true);
    ASSERT_GT(without, 0.1);  // the checker reads as heavy noise without the fit (detail ~1.1)
    // Two albedo values: any pattern of them is linear in a, so the fit explains it exactly; what
    // is left is float rounding of values ~1 (below 1e-5 per pixel).
    EXPECT_LT(with, 1e-4 * without) << without << " -> " << with;
}

TEST(NoiseFit, PureNoiseOverATexturedAlbedoIsKept) {
    const int w = 96, h = 96;
    const Image a = checkerAlbedo(w, h);
    Image d(w, h, 3);
    std::mt19937 rng(5);
    std::normal_distribution<float> n(0.0f, 0.1f);
    for (size_t i = 0; i < d.size(); ++i) d.data()[i] = 1.0f + n(rng);
    const double without = meanEnergy(d, a, false), with = meanEnergy(d, a, true);
    // DetailEnergy is unbiased on white noise: sigma^2 = 0.01. 27648 values: the mean of a
    // chi-square(1)-like energy has a relative standard error of ~1% (the 5x5 details overlap:
    // allow 6%).
    EXPECT_NEAR(without, 0.01, 0.0006);
    // The fit of noise on an albedo that varies takes some of its energy: its share is p's
    // leverage, w_p (a_p - mean)^2 / sum w (a - mean)^2, largest where p is at an extreme of its
    // window's albedo, as every pixel of a 1-pixel checker is (the worst case; measured 73% kept,
    // the expected ~1/13 of a smooth albedo is far less). Never most of it: 60% to 90% kept.
    EXPECT_GT(with, 0.6 * without);
    EXPECT_LT(with, 0.9 * without);
}

TEST(NoiseFit, FlatAlbedoChangesNothing) {
    const int w = 24, h = 20;
    Image a(w, h, 3), d(w, h, 3);
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0.0f, 2.0f);
    for (size_t i = 0; i < a.size(); ++i) a.data()[i] = 0.6f, d.data()[i] = u(rng);
    Image e0, e1;
    meanEnergy(d, a, false, &e0);
    meanEnergy(d, a, true, &e1);
    for (size_t i = 0; i < e0.size(); ++i) ASSERT_EQ(e0.data()[i], e1.data()[i]) << i;  // bit-identical
}

// The one demodulate/remodulate pair (src/filters/modulation.h) that the still filters, their
// noise estimate and SVGF run: the round trip, the "is a sample" mask, the clamp and the guard.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/parallel.h"
#include "filters/still_state.h"
#include "filters/modulation.h"
#include "filters/svgf_common.h"

using namespace atrous;
using filters::Demodulate;
using filters::DemodulateSample;
using filters::Remodulate;
using filters::RemodulateGuarded;

namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Colour, albedo (black, dark, near the floors, bright, above 1, NaN) and emission, 16x16.
struct Bufs {
    Image color{16, 16, 3}, albedo{16, 16, 3}, emission{16, 16, 3};
    Bufs() {
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        const float alb[] = {0.0f, 1e-4f, 0.02f, 0.05f, 0.1f, 0.3f, 0.9f, 1.5f, kNan};
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x)
                for (int c = 0; c < 3; ++c) {
                    color(x, y, c) = 4.0f * u(rng);
                    albedo(x, y, c) = alb[(x + 3 * y + c) % 9];
                    emission(x, y, c) = (x % 5 == 0) ? 2.0f * u(rng) : 0.0f;
                }
    }
};

// remodulate(demodulate(c)) = c: (c - e) · (1/a') · a' + e rounds three times, so within a few
// float ulps of the larger of c and e (4 ulp = 4.8e-7 relative allowed).
void expectRoundTrip(const filters::AlbedoRule& rule, bool withEmission) {
    Bufs b;
    Image demod(16, 16, 3), back(16, 16, 3);
    Demodulate d;
    d.rule = rule, d.albedo = b.albedo.view(), d.in = b.color.view(), d.out = demod.view();
    if (withEmission) d.emission = b.emission.view();
    parallelFor2dCpu(16, 16, d);
    Remodulate r;
    r.rule = rule, r.base = demod.view(), r.albedo = b.albedo.view(), r.out = back.view();
    if (withEmission) r.emission = b.emission.view();
    parallelFor2dCpu(16, 16, r);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
            for (int c = 0; c < 3; ++c) {
                const float want = b.color(x, y, c), e = withEmission ? b.emission(x, y, c) : 0.0f;
                ASSERT_TRUE(std::isfinite(demod(x, y, c))) << x << "," << y;
                EXPECT_NEAR(back(x, y, c), want, 4.8e-7f * std::fmax(std::fabs(want), e) + 1e-30f) << x << "," << y << " " << c;
            }
}

}  // namespace

TEST(Modulation, RoundTripIsTheIdentityForTheStillAndSvgfRules) {
    DenoiseOptions o;
    expectRoundTrip(filters::stillAlbedoRule(o), false);
    expectRoundTrip(filters::stillAlbedoRule(o), true);
    expectRoundTrip(svgf::albedoRule(), true);
}

TEST(Modulation, DemodulateDividesAndScalesTheVariance) {
    Image color(1, 1, 3), albedo(1, 1, 3), var(1, 1, 3);
    for (int c = 0; c < 3; ++c) color(0, 0, c) = 1.0f, albedo(0, 0, c) = 0.5f, var(0, 0, c) = 1.0f;
    Demodulate d;
    d.albedo = albedo.view(), d.in = d.out = color.view(), d.var = var.view();
    d(0, 0);
    EXPECT_EQ(color(0, 0, 0), 2.0f);  // 1 / 0.5
    EXPECT_EQ(var(0, 0, 0), 4.0f);    // 1 / 0.5²
}

TEST(Modulation, NonFiniteColourIsNoSampleAndTheClampHolds) {
    Image color(3, 1, 3), out(3, 1, 3), valid(3, 1, 1);
    color.fill(1.0f);
    color(0, 0, 1) = kNan;
    color(1, 0, 2) = kInf;
    color(2, 0, 0) = 1e30f;  // finite, beyond the clamp
    DemodulateSample d;  // SVGF's
    d.in = color.view(), d.out = out.view(), d.valid = valid.view(), d.maxAbs = svgf::kMaxIllum;
    for (int x = 0; x < 3; ++x) d(x, 0);
    EXPECT_EQ(valid(0, 0, 0), 0.0f);
    EXPECT_EQ(valid(1, 0, 0), 0.0f);
    EXPECT_EQ(valid(2, 0, 0), 1.0f);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(out(0, 0, c), 0.0f);
    EXPECT_EQ(out(2, 0, 0), svgf::kMaxIllum);
}

TEST(Modulation, RemodulateNeverLetsANonFiniteValueOut) {
    Image base(2, 1, 3), emission(2, 1, 3), out(2, 1, 3);
    base.fill(1.0f);
    emission.fill(0.5f);
    base(0, 0, 0) = kNan;
    emission(1, 0, 1) = kInf;  // a non-finite emission reads as 0
    RemodulateGuarded r;  // SVGF's
    r.base = base.view(), r.emission = emission.view(), r.out = out.view();
    for (int x = 0; x < 2; ++x) r(x, 0);
    EXPECT_EQ(out(0, 0, 0), 0.0f);
    EXPECT_EQ(out(0, 0, 1), 1.5f);
    EXPECT_EQ(out(1, 0, 1), 1.0f);
}

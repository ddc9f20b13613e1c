// EAW (docs/denoising.md): unit weights = plain B3 à-trous, constants stay constant, no
// energy gain, CPU fast path = generic functor, every parameter matters, the fast exp is accurate.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "denoise_test_util.h"
#include "param_effect_util.h"
#include "filters/eaw.h"
#include "filters/filter_math.h"

using namespace atrous;
using namespace atrous::test;

namespace {

// Direct reference: the unweighted B3 à-trous cascade in double; taps outside the image are
// dropped and the kernel renormalised (the filters' border rule).
Image plainAtrous(const Image& in, int levels) {
    const int w = in.width(), h = in.height();
    std::vector<double> cur(in.size()), nxt(in.size());
    for (size_t i = 0; i < in.size(); ++i) cur[i] = in.data()[i];
    const double b[5] = {1 / 16.0, 4 / 16.0, 6 / 16.0, 4 / 16.0, 1 / 16.0};
    for (int l = 0; l < levels; ++l) {
        const int s = 1 << l;
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    double a = 0, k = 0;
                    for (int qy = -2; qy <= 2; ++qy)
                        for (int qx = -2; qx <= 2; ++qx) {
                            const int xx = x + qx * s, yy = y + qy * s;
                            if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                            a += b[qx + 2] * b[qy + 2] * cur[size_t(c) * w * h + size_t(yy) * w + xx];
                            k += b[qx + 2] * b[qy + 2];
                        }
                    nxt[size_t(c) * w * h + size_t(y) * w + x] = a / k;
                }
        cur.swap(nxt);
    }
    Image out(w, h, 3);
    for (size_t i = 0; i < out.size(); ++i) out.data()[i] = float(cur[i]);
    return out;
}

DenoiseOptions unitWeightOptions(int levels) {
    DenoiseOptions o = plainOptions(DenoiseMethod::Eaw);
    o.eaw.levels = levels;
    o.eaw.sigmaColor = 1e18f;  // Δc²/σ_c² underflows to 0: w_c = 1
    o.eaw.sigmaNormal = 0;     // no normal stop
    return o;
}

}  // namespace

TEST(FastExp, MatchesStdExp) {
    // The one exponential of the filters (filters/atrous_math.h). Relative error bound 1e-6: the
    // Taylor remainder is 1.2e-7, plus float rounding of t = x·log2e (|t| up to 125, ulp 7.6e-6 in
    // t -> 5e-6 relative at the far end); so test 1e-6 on [-10, 0] and 1e-5 on [-80, -10]; below
    // -80 the result is exactly 0.
    for (float x = -80.0f; x <= 0.0f; x += 0.01f) {
        const double ref = std::exp(double(x));
        const double got = filters::fastExp(x);
        EXPECT_NEAR(got / ref, 1.0, x > -10 ? 1e-6 : 1e-5) << "x = " << x;
    }
    EXPECT_EQ(filters::fastExp(0.0f), 1.0f);
    EXPECT_EQ(filters::fastExp(-INFINITY), 0.0f);
    EXPECT_EQ(filters::fastExp(-81.0f), 0.0f);
    EXPECT_EQ(filters::fastExp(NAN), 0.0f);
}

TEST(Eaw, UnitWeightsEqualPlainB3Atrous) {
    SyntheticScene s = makeScene(48, 40, 0.3f, 1);
    for (int levels : {1, 3, 5}) {
        for (bool fast : {true, false}) {
            filters::eawCpuFastPath() = fast;
            Frame in;
            in.color = &s.noisy;
            Image got = denoise(in, unitWeightOptions(levels));
            Image ref = plainAtrous(s.noisy, levels);
            // Float accumulation of 25 taps per level over values of order 1: 1e-5 absolute.
            EXPECT_LT(maxAbsDiff(got, ref), 1e-5) << "levels " << levels << " fast " << fast;
        }
    }
    filters::eawCpuFastPath() = true;
}

TEST(Eaw, ConstantImageStaysConstant) {
    SyntheticScene s = makeScene(40, 40, 0.3f, 2);
    Image flat(40, 40, 3);
    flat.fill(0.37f);
    Image var(40, 40, 3);
    var.fill(0.01f);
    Frame in = s.inputs();
    in.color = &flat;
    in.variance = &var;
    for (auto m : {DenoiseMethod::Eaw, DenoiseMethod::Sure}) {
        DenoiseOptions o;  // all defaults, features on (demodulation divides and multiplies back)
        o.method = m;
        Image out = denoise(in, o);
        for (size_t i = 0; i < out.size(); ++i) ASSERT_NEAR(out.data()[i], 0.37f, 2e-6f) << denoiseMethodName(m);
    }
}

TEST(Eaw, NoEnergyGain) {
    // Symmetric weights (S(p)+S(q), |n_p - n_q|, ...) make the filter nearly mean-preserving; only
    // the clamped border and the asymmetric automatic σ_x break exact symmetry, so 1% of the mean.
    SyntheticScene s = makeScene(64, 64, 0.3f, 3);
    DenoiseOptions o = plainOptions(DenoiseMethod::Eaw);
    Image out = denoise(s.inputs(), o);
    double a = 0, b = 0;
    for (size_t i = 0; i < out.size(); ++i) {
        a += s.noisy.data()[i];
        b += out.data()[i];
    }
    EXPECT_NEAR(b / a, 1.0, 0.01);
}

TEST(Eaw, CpuFastPathEqualsGenericFunctor) {
    SyntheticScene s = makeScene(70, 45, 0.4f, 4);
    // Material ids that change where no other feature does (stripes across the regions), so the
    // id stop changes the output and both of its specialisations are tested for something.
    for (int y = 0; y < s.ids.height(); ++y)
        for (int x = 0; x < s.ids.width(); ++x) s.ids(x, y, 1) = float((x / 9 + y / 7) % 3);
    // The fast path is compiled for AVX2 and for AVX-512 (picked at run time): test every one this
    // CPU can run.
    const bool hasAvx512 = filters::eawCpuAvx512();
    std::vector<bool> isas = {false};
    if (hasAvx512) isas.push_back(true);
    for (bool avx512 : isas)
        for (auto m : {DenoiseMethod::Eaw, DenoiseMethod::Sure})
            for (float sigmaDepth : {0.0f, 0.1f})  // the fast path specialises on the depth stop...
                for (bool ids : {true, false}) {   // ...and on the id stop
                    DenoiseOptions o;
                    o.method = m;
                    o.eaw.sigmaDepth = sigmaDepth;  // 0.1: every term on
                    o.eaw.useIds = ids;
                    filters::eawCpuFastPath() = true;
                    filters::eawCpuAvx512() = avx512;
                    Image fast = denoise(s.inputs(), o);
                    filters::eawCpuFastPath() = false;
                    Image generic = denoise(s.inputs(), o);
                    filters::eawCpuFastPath() = true;
                    filters::eawCpuAvx512() = hasAvx512;
                    // Same math, different summation association and FMA contraction: 1e-5 on
                    // values ~1.
                    EXPECT_LT(maxAbsDiff(fast, generic), 1e-5)
                        << denoiseMethodName(m) << " avx512 " << avx512 << " depth " << sigmaDepth << " ids " << ids;
                    // The id stop must matter on this scene, or the ids = false case tests nothing new.
                    if (!ids) {
                        o.eaw.useIds = true;
                        EXPECT_GT(maxAbsDiff(denoise(s.inputs(), o), fast), 1e-4) << "ids changed nothing";
                    }
                }
}

TEST(Eaw, EveryParameterChangesTheOutput) {
    SyntheticScene s = makeScene(48, 48, 0.4f, 5);
    DenoiseOptions base;
    base.method = DenoiseMethod::Eaw;
    // Ids off in the base: in this scene they change exactly where normals and depth do, and a
    // weight of 0 from the ids would hide those terms.
    base.eaw.useIds = false;
    const auto changed = outputChangeCheck(s, base);
    changed("levels", [](DenoiseOptions& o) { o.eaw.levels = 3; });
    changed("sigmaColor", [](DenoiseOptions& o) { o.eaw.sigmaColor = 0.05f; });
    changed("colorScale", [](DenoiseOptions& o) { o.eaw.colorScale = 3.0f; });
    changed("colorLevelFactor", [](DenoiseOptions& o) { o.eaw.colorLevelFactor = 1.0f; });
    changed("sigmaNormal", [](DenoiseOptions& o) { o.eaw.sigmaNormal = 2.0f; });
    changed("normalStepScale", [](DenoiseOptions& o) { o.eaw.normalStepScale = true; });
    changed("sigmaPosition", [](DenoiseOptions& o) { o.eaw.sigmaPosition = 0.5f; });
    changed("positionScale", [](DenoiseOptions& o) { o.eaw.positionScale = 0.3f; });
    changed("sigmaDepth", [](DenoiseOptions& o) { o.eaw.sigmaDepth = 0.05f; });
    changed("useIds", [](DenoiseOptions& o) {
        o.eaw.useIds = true;
        o.eaw.sigmaNormal = 0;  // otherwise normals already separate the regions
        o.eaw.sigmaPosition = 100;
    });
    changed("demodulate", [](DenoiseOptions& o) { o.demodulate = false; });
    changed("albedoEpsilon", [](DenoiseOptions& o) { o.albedoEpsilon = 0.5f; });
}

TEST(Eaw, RejectsOutOfRangeParameters) {
    SyntheticScene s = makeScene(16, 16, 0.3f, 6);
    auto bad = [&](auto mutate) {
        DenoiseOptions o;
        mutate(o);
        EXPECT_THROW(denoise(s.inputs(), o), InputError);
    };
    bad([](DenoiseOptions& o) { o.eaw.levels = 0; });
    bad([](DenoiseOptions& o) { o.eaw.levels = 11; });
    bad([](DenoiseOptions& o) { o.eaw.sigmaColor = -1; });
    bad([](DenoiseOptions& o) { o.eaw.colorLevelFactor = 0; });
    bad([](DenoiseOptions& o) { o.eaw.sigmaNormal = NAN; });
    bad([](DenoiseOptions& o) { o.eaw.positionScale = 0; });
    bad([](DenoiseOptions& o) { o.sure.windowRadius = 0; });
    bad([](DenoiseOptions& o) { o.sure.candidates = {}; });
    bad([](DenoiseOptions& o) { o.sure.candidates = {1.5f}; });
    bad([](DenoiseOptions& o) { o.firefly.k = 0; });
    bad([](DenoiseOptions& o) { o.albedoEpsilon = 0; });
}

TEST(Eaw, RejectsBadBuffers) {
    SyntheticScene s = makeScene(16, 16, 0.3f, 7);
    Image small(8, 16, 3);
    Frame in = s.inputs();
    in.normal = &small;
    EXPECT_THROW(denoise(in, DenoiseOptions{}), InputError);
    in = s.inputs();
    s.variance(3, 4, 1) = -0.5f;
    EXPECT_THROW(denoise(in, DenoiseOptions{}), InputError);
    Frame none;
    EXPECT_THROW(denoise(none, DenoiseOptions{}), InputError);
}

TEST(Eaw, EmissionIsFilteredAroundAndAddedBack) {
    // A visible emitter: colour = emission there (nothing reflected). With the emission buffer the
    // emitter's pixels come back as their emission plus a filtered reflected part, which here is
    // what the surrounding surface reflects (its truth is at most 1.2 · 0.8 < 1.5): the emitter's
    // coverage-like pattern is kept exactly, and the output differs from the run without it.
    SyntheticScene s = makeScene(40, 40, 0.3f, 8);
    Image emission(40, 40, 3);
    for (int y = 10; y < 14; ++y)
        for (int x = 5; x < 30; ++x)
            for (int c = 0; c < 3; ++c) {
                emission(x, y, c) = 20.0f + 7.0f * float((x * 7 + y * 3) % 5);  // coverage-like noise
                s.noisy(x, y, c) = emission(x, y, c);
            }
    for (auto m : {DenoiseMethod::Eaw, DenoiseMethod::Sure}) {
        DenoiseOptions o;
        o.method = m;
        Frame in = s.inputs();
        const Image without = denoise(in, o);
        in.emission = &emission;
        const Image with = denoise(in, o);
        for (int x = 5; x < 30; ++x) {
            ASSERT_GE(with(x, 12, 1), emission(x, 12, 1) - 0.5f) << denoiseMethodName(m);
            ASSERT_LE(with(x, 12, 1), emission(x, 12, 1) + 1.5f) << denoiseMethodName(m);
        }
        EXPECT_GT(maxAbsDiff(with, without), 1e-3) << denoiseMethodName(m);
    }
}

// The CPU row loops of the still driver's passes against the shared per-pixel functors they stand
// for (the CUDA backend's code, and what the CPU ran before them): bit for bit. Demodulate,
// Remodulate and the global variance (src/cpu/modulation_cpu.cpp: a' of a row at once, the rim
// rule's 3x3 scan as row minima), the noise estimate without a variance buffer
// (src/cpu/noise_cpu.cpp: the global MAD σ, its median, the local per-pixel estimate), the
// in-place form of the sanitise pass, the firefly pass's count and its dense-firefly step
// (src/cpu/prepass_cpu.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "filters/still_cascades.h"
#include "filters/emission_filter.h"
#include "filters/modulation.h"
#include "filters/noise_estimate.h"
#include "filters/prepass.h"
#include "filters/sure.h"
#include "test_util.h"

using namespace atrous;
using namespace atrous::filters;

namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Sizes with an interior for every row loop, and degenerate ones (the border paths alone).
const int kSizes[][2] = {{37, 23}, {64, 19}, {5, 7}, {3, 5}, {2, 4}, {1, 1}, {1, 9}, {40, 1}};

// The index of the first float that differs bit for bit (-1: none). NaNs compare by their bits.
long firstBitDifference(const Image& a, const Image& b) {
    if (a.size() != b.size()) return 0;
    for (size_t i = 0; i < a.size(); ++i)
        if (std::memcmp(a.data() + i, b.data() + i, sizeof(float)) != 0) return long(i);
    return -1;
}

using test::randomImage;

// An albedo with every case of the modulation rule: black, below a tenth of the floor, between
// the floor and twice it (the rim test), ordinary, above 1, NaN and Inf, in patches so that rims
// form.
Image ruleAlbedo(int w, int h, unsigned seed) {
    const float vals[] = {0.0f, 0.004f, 0.03f, 0.06f, 0.09f, 0.3f, 0.8f, 1.4f, kNan, kInf, 1e-4f};
    Image a(w, h, 3);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> pick(0, 10);
    std::uniform_real_distribution<float> jitter(0.9f, 1.1f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int base = pick(rng);
            for (int c = 0; c < 3; ++c) {
                const float v = vals[(base + (c == 2 && x % 3 == 0 ? 1 : 0)) % 11];
                a(x, y, c) = std::isfinite(v) ? v * jitter(rng) : v;
            }
        }
    return a;
}

AlbedoRule rules(int k) {
    AlbedoRule r;
    if (k == 0) r.eps = 1e-3f, r.floor = 0.05f;                   // the still filters'
    if (k == 1) r.eps = 1e-3f, r.floor = 0.0f;                    // floor off
    if (k == 2) r.eps = 1e-2f, r.floor = 0.2f, r.rim = false;     // no rim rule
    if (k == 3) r.eps = 1e-3f, r.floor = 0.1f, r.nonFinite = 1.0f;
    return r;
}

}  // namespace

TEST(FilterRows, DemodulateRemodulateAndGlobalVarianceEqualTheFunctors) {
    for (auto& sz : kSizes) {
        const int w = sz[0], h = sz[1];
        const Image albedo = ruleAlbedo(w, h, unsigned(w * 31 + h));
        const Image color = randomImage(w, h, 3, 2, -0.5f, 4.0f), var = randomImage(w, h, 3, 3, 0.0f, 0.2f);
        const Image emission = randomImage(w, h, 3, 4, 0.0f, 1.0f), detail = randomImage(w, h, 3, 5, -0.3f, 0.3f);
        for (int k = 0; k < 4; ++k)
            for (int withE = 0; withE < 2; ++withE)
                for (int withAlbedo = 0; withAlbedo < 2; ++withAlbedo) {
                    const std::string what = std::to_string(w) + "x" + std::to_string(h) + " rule " + std::to_string(k) +
                                             " emission " + std::to_string(withE) + " albedo " + std::to_string(withAlbedo);
                    Demodulate d;
                    d.rule = rules(k);
                    d.albedo = withAlbedo ? albedo.view() : ImageView{};
                    if (withE) d.emission = emission.view();
                    // Into other planes (and the variance in place), and in place.
                    Image o1(w, h, 3), o2(w, h, 3), v1 = var.clone(), v2 = var.clone();
                    d.in = color.view(), d.out = o1.view(), d.var = v1.view();
                    runDemodulate(CpuExec{}, d);
                    d.out = o2.view(), d.var = v2.view();
                    CpuExec{}.forEachPixel(w, h, d);
                    EXPECT_EQ(firstBitDifference(o1, o2), -1) << what;
                    EXPECT_EQ(firstBitDifference(v1, v2), -1) << what;
                    Image inPlace = color.clone();
                    d.in = d.out = inPlace.view(), d.var = ImageView{};
                    runDemodulate(CpuExec{}, d);
                    EXPECT_EQ(firstBitDifference(inPlace, o2), -1) << what << " in place";

                    Remodulate r;
                    r.rule = rules(k);
                    r.albedo = d.albedo;
                    if (withE) r.emission = emission.view();
                    for (int withDetail = 0; withDetail < 2; ++withDetail) {
                        r.detail = withDetail ? detail.view() : ImageView{};
                        Image p1(w, h, 3), p2(w, h, 3);
                        r.base = o2.view(), r.out = p1.view();
                        runRemodulate(CpuExec{}, r);
                        r.out = p2.view();
                        CpuExec{}.forEachPixel(w, h, r);
                        EXPECT_EQ(firstBitDifference(p1, p2), -1) << what << " detail " << withDetail;
                        Image p3 = o2.clone();
                        r.base = r.out = p3.view();
                        runRemodulate(CpuExec{}, r);
                        EXPECT_EQ(firstBitDifference(p3, p2), -1) << what << " in place";
                    }
                }
        for (int withAlbedo = 0; withAlbedo < 2; ++withAlbedo) {
            GlobalVariance g;
            g.floorVar[0] = 0.01f, g.floorVar[1] = 0.3f, g.floorVar[2] = 2e-5f;
            g.eps = 1e-3f, g.floor = 0.05f;
            g.albedo = withAlbedo ? albedo.view() : ImageView{};
            Image a(w, h, 3), b(w, h, 3);
            g.var = a.view();
            runGlobalVariance(CpuExec{}, g);
            g.var = b.view();
            CpuExec{}.forEachPixel(w, h, g);
            EXPECT_EQ(firstBitDifference(a, b), -1) << w << "x" << h << " albedo " << withAlbedo;
        }
    }
}

namespace {

// A noisy scene for the noise estimate: planes of different normals and depths, a bright square
// (a colour edge), a dense-noise patch, background (normal 0) in one corner, a few non-finite values.
struct NoiseScene {
    Image color, normal, depth, albedo;
    NoiseScene(int w, int h, unsigned seed)
        : color(w, h, 3), normal(w, h, 3), depth(w, h, 1), albedo(ruleAlbedo(w, h, seed + 1)) {
        std::mt19937 rng(seed);
        std::normal_distribution<float> g(0.0f, 1.0f);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool left = x < w / 2, bg = x > 3 * w / 4 && y < h / 4;
                const bool bright = x > w / 4 && x < w / 3 && y > h / 3 && y < h / 2;
                const float sigma = (x > w / 2 && y > h / 2) ? 0.4f : 0.05f;
                for (int c = 0; c < 3; ++c) {
                    color(x, y, c) = (bright ? 20.0f : 0.5f + 0.1f * c) + sigma * g(rng);
                    normal(x, y, c) = bg ? 0.0f : (left ? (c == 2 ? 1.0f : 0.0f) : (c == 0 ? 1.0f : 0.0f));
                }
                depth(x, y, 0) = bg ? 1e18f : (left ? 2.0f : 3.0f + 0.01f * float(y));
            }
        if (w > 4 && h > 4) {
            color(w / 2, h / 2, 1) = kNan;
            color(1, h - 2, 0) = kInf;
        }
    }
};

}  // namespace

TEST(FilterRows, NoiseEstimateEqualsTheFunctors) {
    for (auto& sz : kSizes) {
        const int w = sz[0], h = sz[1];
        const NoiseScene s(w, h, unsigned(7 * w + h));
        // The global σ: row loops and the radix median against the functor path.
        for (int withAlbedo = 0; withAlbedo < 2; ++withAlbedo) {
            const ImageView a = withAlbedo ? s.albedo.view() : ImageView{};
            float s1[3], s2[3];
            globalNoiseSigma(CpuExec{}, s.color.view(), a, 1e-3f, 0.05f, s1);
            globalNoiseSigma<CpuExec>(CpuExec{}, s.color.view(), a, 1e-3f, 0.05f, s2);
            for (int c = 0; c < 3; ++c) EXPECT_EQ(s1[c], s2[c]) << w << "x" << h << " channel " << c;
        }
        // The local estimate, with and without each feature, on the colour without non-finite
        // values (the driver's input is sanitised).
        Image clean = s.color.clone();
        for (size_t i = 0; i < clean.size(); ++i)
            if (!std::isfinite(clean.data()[i])) clean.data()[i] = 0.5f;
        for (int mask = 0; mask < 8; ++mask) {
            LocalNoise f;
            for (int c = 0; c < 3; ++c) {
                f.floorVar[c] = 0.0025f * float(c + 1);
                f.maxDiff2[c] = kNoiseEdgeSigmas2 * kNoiseCapMul * f.floorVar[c];
            }
            f.eps = 1e-3f, f.floor = 0.05f;
            f.color = clean.view();
            if (mask & 1) f.normal = s.normal.view();
            if (mask & 2) f.depth = s.depth.view();
            if (mask & 4) f.albedo = s.albedo.view();
            Image v1(w, h, 3), v2(w, h, 3);
            f.var = v1.view();
            runLocalNoise(CpuExec{}, f);
            f.var = v2.view();
            runLocalNoise<CpuExec>(CpuExec{}, f);
            EXPECT_EQ(firstBitDifference(v1, v2), -1) << w << "x" << h << " features " << mask;
        }
    }
}

TEST(FilterRows, MedianIsTheElementNthElementFinds) {
    std::mt19937 rng(3);
    std::normal_distribution<float> g(0.0f, 1.0f);
    for (size_t n : {size_t(1), size_t(2), size_t(7), size_t(1000), size_t(300001)}) {
        std::vector<float> v(n);
        for (float& x : v) x = std::fabs(g(rng)) * (rng() % 3 == 0 ? 1e-20f : 1.0f);
        if (n > 10) v[3] = kNan, v[5] = kInf, v[7] = -kInf, v[9] = -0.0f, v[8] = -2.5f;
        std::vector<float> ref(v);
        auto end = std::partition(ref.begin(), ref.end(), [](float a) { return a < INFINITY && a == a; });
        const size_t m = size_t(end - ref.begin());
        std::nth_element(ref.begin(), ref.begin() + long(m / 2), end);
        const float got = medianFinite(CpuExec{}, ImageView{v.data(), int(n), 1, 1}, 42.0f);
        EXPECT_EQ(got, ref[m / 2]) << n;
    }
    std::vector<float> none = {kNan, kInf};
    EXPECT_EQ(medianFinite(CpuExec{}, ImageView{none.data(), 2, 1, 1}, 42.0f), 42.0f);
}

TEST(FilterRows, InPlaceSanitiseAndTheFireflyCountEqualTheFunctors) {
    for (auto& sz : kSizes) {
        const int w = sz[0], h = sz[1];
        Image c = randomImage(w, h, 3, 11, 0.0f, 1.0f), v = randomImage(w, h, 3, 12, 0.0f, 0.05f);
        // Fireflies (clamped and kept), and non-finite values next to each other.
        std::mt19937 rng(5);
        for (int k = 0; k < (w * h) / 20 + 1; ++k) {
            const int x = int(rng() % unsigned(w)), y = int(rng() % unsigned(h));
            for (int ch = 0; ch < 3; ++ch) c(x, y, ch) = 40.0f;
            if (k % 2) v(x, y, 0) = 400.0f;
        }
        c(0, 0, 1) = kNan;
        c(w - 1, h - 1, 0) = kInf;
        if (w > 1) c(1, 0, 1) = kNan;
        v(w / 2, h / 2, 2) = -kInf;
        // Sanitise into other planes (the functor) and in place.
        Image c1(w, h, 3), v1(w, h, 3);
        CpuExec{}.forEachPixel(w, h, SanitizeColor{c.view(), v.view(), c1.view(), v1.view()});
        Image c2 = c.clone(), v2 = v.clone();
        runSanitizeColor(CpuExec{}, SanitizeColor{c2.view(), v2.view(), c2.view(), v2.view()});
        EXPECT_EQ(firstBitDifference(c1, c2), -1) << w << "x" << h;
        EXPECT_EQ(firstBitDifference(v1, v2), -1) << w << "x" << h;
        // Without a variance: the colour alone.
        Image c3 = c.clone();
        runSanitizeColor(CpuExec{}, SanitizeColor{c3.view(), ImageView{}, c3.view(), ImageView{}});
        EXPECT_EQ(firstBitDifference(c1, c3), -1) << w << "x" << h;
        // The firefly pass, given and estimated variance: the CPU row loop into other planes with a
        // flag plane (what the driver ran before), against the same loop in place with its count.
        // (The row loop and the functor agree to a few ulps, not bit for bit, since the CPU loop
        // came in: GCC contracts the bound's multiply-adds differently in the two; same decisions.)
        for (int own = 0; own < 2; ++own) {
            Image fc1(w, h, 3), fv1(w, h, 3), flag1(w, h, 1);
            runFireflyClamp(CpuExec{}, FireflyClamp{4.0f, own, c1.view(), v1.view(), fc1.view(), fv1.view(), flag1.view()});
            int want = 0;
            for (size_t i = 0; i < flag1.size(); ++i) want += flag1.data()[i] > 0.5f;
            Image fr(w, h, 3), fvr(w, h, 3), flagr(w, h, 1);
            CpuExec{}.forEachPixel(w, h, FireflyClamp{4.0f, own, c1.view(), v1.view(), fr.view(), fvr.view(), flagr.view()});
            EXPECT_EQ(firstBitDifference(flag1, flagr), -1) << w << "x" << h << " own " << own;
            for (size_t i = 0; i < fr.size(); ++i)
                ASSERT_NEAR(fc1.data()[i], fr.data()[i], 1e-6f * std::fabs(fr.data()[i])) << w << "x" << h << " " << i;
            if (w * h > 100 && own == 0) EXPECT_GT(want, 0) << w << "x" << h;
            // Without a flag plane: the count alone.
            Image fc4(w, h, 3), fv4(w, h, 3);
            int count = -1;
            runFireflyClamp(CpuExec{}, FireflyClamp{4.0f, own, c1.view(), v1.view(), fc4.view(), fv4.view(), ImageView{}}, &count);
            EXPECT_EQ(firstBitDifference(fc1, fc4), -1) << w << "x" << h << " own " << own;
            EXPECT_EQ(firstBitDifference(fv1, fv4), -1) << w << "x" << h << " own " << own;
            EXPECT_EQ(count, want) << w << "x" << h << " own " << own;
        }
    }
}

TEST(FilterRows, DenseFireflyStepEqualsTheFunctors) {
    // Bright pixels dense in one half (about one in five) and sparse in the other, so that windows
    // cross the thresholds both ways: the CPU overload (sliding sums, dense windows only) against
    // BoxSum + FireflyDense over every pixel: the same decisions (flags bit for bit) and values to
    // a few ulps (as the pass itself: GCC contracts the bound's multiply-add differently in the
    // two instantiations of the functor).
    // kSizes, and sizes whose bands of 32 rows start below row 0 (y0 > 0) and whose rows have no
    // middle stretch in the sliding sum (w < 2r + 2 = 16).
    std::vector<std::pair<int, int>> sizes;
    for (auto& sz : kSizes) sizes.emplace_back(sz[0], sz[1]);
    for (auto sz : {std::pair{9, 33}, std::pair{12, 70}, std::pair{15, 40}, std::pair{16, 65}, std::pair{200, 100}})
        sizes.push_back(sz);
    for (auto [w, h] : sizes) {
        Image c = randomImage(w, h, 3, 21, 0.0f, 1.0f), v = randomImage(w, h, 3, 22, 0.0f, 0.05f);
        std::mt19937 rng(7);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (rng() % (x < w / 2 ? 5u : 60u) == 0)
                    for (int ch = 0; ch < 3; ++ch) c(x, y, ch) = 3.0f + float(rng() % 8), v(x, y, ch) = 100.0f;
        for (int own = 0; own < 2; ++own) {
            Image co1(w, h, 3), vo1(w, h, 3), flag1(w, h, 1), tmp(w, h, 1), sums(w, h, 1);
            const FireflyClamp p1{4.0f, own, c.view(), v.view(), co1.view(), vo1.view(), flag1.view()};
            runFireflyClamp(CpuExec{}, p1);
            Image co2 = co1.clone(), vo2 = vo1.clone(), flag2 = flag1.clone(), before = co1.clone();
            Image flagAfterPass = flag1.clone();
            runFireflyDense(CpuExec{}, p1, tmp.view(), sums.view());
            const FireflyClamp p2{4.0f, own, c.view(), v.view(), co2.view(), vo2.view(), flag2.view()};
            Image tmp2(w, h, 1), sums2(w, h, 1);
            CpuExec{}.forEachPixel(w, h, BoxSum<false>{kFireflyDenseRadius, flag2.view(), tmp2.view()});
            CpuExec{}.forEachPixel(w, h, BoxSum<true>{kFireflyDenseRadius, tmp2.view(), sums2.view()});
            CpuExec{}.forEachPixel(w, h, FireflyDense{p2, sums2.view()});
            for (size_t i = 0; i < co1.size(); ++i) {
                ASSERT_NEAR(co1.data()[i], co2.data()[i], 1e-6f * std::fabs(co2.data()[i])) << w << "x" << h << " " << i;
                // The variance takes the factor squared: twice its relative difference, and a rounding.
                ASSERT_NEAR(vo1.data()[i], vo2.data()[i], 3e-6f * std::fabs(vo2.data()[i])) << w << "x" << h << " " << i;
            }
            EXPECT_EQ(firstBitDifference(flag1, flag2), -1) << w << "x" << h << " own " << own;
            // The CPU's row sums are BoxSum's (taken from the flags as the pass left them).
            Image tmp3(w, h, 1);
            CpuExec{}.forEachPixel(w, h, BoxSum<false>{kFireflyDenseRadius, flagAfterPass.view(), tmp3.view()});
            EXPECT_EQ(firstBitDifference(tmp, tmp3), -1) << w << "x" << h << " own " << own;
            // The step did something on the larger sizes (not a test of nothing against nothing).
            if (w * h > 400) EXPECT_NE(firstBitDifference(co1, before), -1) << w << "x" << h << " own " << own;
        }
    }
}

TEST(FilterRows, EmissionLevelEqualsTheFunctor) {
    // Emission: zeros, quiet lights (tiny variance), partly covered pixels (variance near and above
    // the copy threshold), tiny values; every level's step.
    for (auto& sz : kSizes) {
        const int w = sz[0], h = sz[1];
        Image e(w, h, 3), v(w, h, 3);
        std::mt19937 rng(unsigned(w * 7 + h));
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const int kind = int(rng() % 5);
                for (int c = 0; c < 3; ++c) {
                    const float val = kind == 0 ? 0.0f : (kind == 4 ? 1e-20f * u(rng) : 5.0f * u(rng));
                    e(x, y, c) = val;
                    // variance relative to the energy: below, at and above 1e-4 of it
                    const float rel = kind == 1 ? 1e-6f : (kind == 2 ? 1.0e-4f / 3.0f : 0.5f);
                    v(x, y, c) = rel * val * val * (0.9f + 0.2f * u(rng));
                }
            }
        for (int step : {1, 2, 4, 8}) {
            EmissionLevel f;
            f.step = step;
            f.sigmaMul = 2.0f / float(step * step);
            f.eIn = e.view(), f.variance = v.view();
            Image a(w, h, 3), b(w, h, 3);
            f.eOut = a.view();
            runEmissionLevel(CpuExec{}, f);
            // The functor pixel by pixel in the dispatched row loop (what the CPU level was).
            f.eOut = b.view();
            parallelForRowsCpu(h, [&](int y) {
                for (int x = 0; x < w; ++x) f(x, y);
            });
            EXPECT_EQ(firstBitDifference(a, b), -1) << w << "x" << h << " step " << step;
        }
    }
}

TEST(FilterRows, EmissionFilterEqualsTheFunctorLevels) {
    // The whole filter (1 to 5 levels): the CPU's listed pixels against every pixel through the
    // functor level by level; with the second buffer separate and being the input itself (as the
    // driver passes the emission's own copy).
    for (auto& sz : kSizes) {
        const int w = sz[0], h = sz[1];
        Image e(w, h, 3), v(w, h, 3);
        std::mt19937 rng(unsigned(w * 5 + h));
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (size_t i = 0; i < e.plane(); ++i) {
            const int kind = int(rng() % 4);
            for (int c = 0; c < 3; ++c) {
                const float val = kind == 0 ? 0.0f : 3.0f * u(rng);
                e.data()[i + c * e.plane()] = val;
                v.data()[i + c * e.plane()] = (kind == 1 ? 1e-6f : 0.3f) * val * val;
            }
        }
        for (int levels = 1; levels <= 5; ++levels)
            for (int alias = 0; alias < 2; ++alias) {
                Image in1 = e.clone(), a1(w, h, 3), b1(w, h, 3), in2 = e.clone(), a2(w, h, 3), b2(w, h, 3);
                const ImageView r1 = runEmissionFilter(CpuExec{}, levels, 1.0f, v.view(), in1.view(), a1.view(),
                                                       alias ? in1.view() : b1.view());
                const ImageView r2 = runEmissionFilter<CpuExec>(CpuExec{}, levels, 1.0f, v.view(), in2.view(), a2.view(),
                                                                alias ? in2.view() : b2.view());
                Image x1(w, h, 3), x2(w, h, 3);
                std::memcpy(x1.data(), r1.data, x1.size() * sizeof(float));
                std::memcpy(x2.data(), r2.data, x2.size() * sizeof(float));
                EXPECT_EQ(firstBitDifference(x1, x2), -1) << w << "x" << h << " levels " << levels << " alias " << alias;
            }
    }
}

TEST(FilterRows, SureWindowEqualsItsTwoPasses) {
    // The fused window passes (a ring of horizontal sums) against SureBoxH into a plane, then
    // SureChoose from it: discrete and James-Stein, radii 1 to 5, s_i map or not.
    for (auto& sz : kSizes) {
        const int w = sz[0], h = sz[1];
        const Image detail = randomImage(w, h, 2, 21, 0.0f, 1.0f);
        const Image ci = randomImage(w, h, 3, 22, 0.0f, 2.0f), cn = randomImage(w, h, 3, 23, 0.0f, 2.0f);
        const Image acc0 = randomImage(w, h, 3, 24, -0.1f, 0.1f);
        for (int js = 0; js < 2; ++js)
            for (int r = 1; r <= 5; r += 2)
                for (int withS = 0; withS < 2; ++withS) {
                    SureChoiceParams p;
                    p.radius = r;
                    p.jamesStein = js;
                    Image boxH(w, h, 2), acc1 = acc0.clone(), acc2 = acc0.clone(), s1(w, h, 1), s2(w, h, 1);
                    runSureBoxH(CpuExec{}, SureBoxH{r, detail.view(), boxH.view()});
                    runSureChoose(CpuExec{}, SureChoose{p, boxH.view(), ci.view(), cn.view(), acc1.view(),
                                                      withS ? s1.view() : ImageView{}});
                    runSureWindow(CpuExec{}, SureBoxH{r, detail.view(), ImageView{}},
                                  SureChoose{p, ImageView{}, ci.view(), cn.view(), acc2.view(), withS ? s2.view() : ImageView{}});
                    const std::string what = std::to_string(w) + "x" + std::to_string(h) + " r " + std::to_string(r) +
                                             " js " + std::to_string(js);
                    EXPECT_EQ(firstBitDifference(acc1, acc2), -1) << what;
                    if (withS) EXPECT_EQ(firstBitDifference(s1, s2), -1) << what;
                }
    }
}

TEST(FilterRows, RimAlbedoEqualsTheFunctor) {
    // The rim albedo (prepass.h) row by row against its functor, bit for bit, on the rule albedo
    // sanitised (what the driver hands it); and an albedo with no black pixel comes back as itself.
    for (const auto& s : kSizes) {
        const int w = s[0], h = s[1];
        Image a = ruleAlbedo(w, h, 11u + unsigned(w * 31 + h));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 3; ++c) a(x, y, c) = sanitizeFeature(a(x, y, c));
        const float black = kBlackAlbedoFraction * 0.05f;
        // Colour and emission from which the black pixels' reflected colour is read: dark, bright,
        // and (emission above the colour) negative before the clamp.
        const Image color = randomImage(w, h, 3, 5u + unsigned(w), 0.0f, 4.0f);
        const Image emission = randomImage(w, h, 3, 9u + unsigned(h), 0.0f, 2.0f);
        for (const bool withEmission : {false, true}) {
            const ImageView e = withEmission ? emission.view() : ImageView{};
            Image rows, ref(w, h, 3);
            const ImageView got = rimAlbedo(CpuExec{}, RimAlbedo{a.view(), {}, color.view(), e, black}, rows);
            CpuExec{}.forEachPixel(w, h, RimAlbedo{a.view(), ref.view(), color.view(), e, black});
            Image gotCopy(w, h, 3);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    for (int c = 0; c < 3; ++c) gotCopy(x, y, c) = got(x, y, c);
            EXPECT_EQ(firstBitDifference(gotCopy, ref), -1) << w << "x" << h << " emission " << withEmission;
        }
    }
    Image grey(9, 7, 3), colour(9, 7, 3);
    grey.fill(0.5f);
    colour.fill(1.0f);
    grey(4, 3, 1) = 0.0f;  // one channel black, the pixel is not: its largest channel is 0.5
    Image store;
    const ImageView same =
        rimAlbedo(CpuExec{}, RimAlbedo{grey.view(), {}, colour.view(), {}, kBlackAlbedoFraction * 0.05f}, store);
    EXPECT_EQ(same.data, grey.view().data);
    EXPECT_TRUE(store.empty());
}

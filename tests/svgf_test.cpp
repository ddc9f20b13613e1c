// SVGF: the stage functors (reprojection) and the per-frame driver (history, convergence,
// variance, bad input, parameters) on the synthetic sequences of svgf_test_util.h. Emission
// accumulation: svgf_emission_test.cpp; sequence I/O and the sequence command:
// svgf_sequence_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/svgf.h"
#include "core/parallel.h"
#include "filters/svgf_pipeline.h"
#include "atrous/io/image_io.h"
#include "atrous/io/sequence.h"
#include "svgf_test_util.h"
#include "test_util.h"

using namespace atrous;
using namespace atrous::svgf_test;

// ---- reprojection -------------------------------------------------------------------------------

struct ReprojectFixture {
    int w = 32, h = 16;
    Image motion{w, h, 2}, depth{w, h, 1}, normal{w, h, 3}, ids{w, h, 1}, grad{w, h, 2};
    Image prevIllum{w, h, 3}, prevMoments{w, h, 2}, prevLength{w, h, 1}, prevDepth{w, h, 1}, prevNormal{w, h, 3},
        prevIds{w, h, 1};
    Image outIllum{w, h, 3}, outMoments{w, h, 2}, outLength{w, h, 1};

    static float texture(int x, int y, int c) { return std::sin(0.7f * x + 0.3f * c) + 0.25f * float(y) + float(c); }

    ReprojectFixture() {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                depth(x, y, 0) = prevDepth(x, y, 0) = 5.0f;
                normal(x, y, 2) = prevNormal(x, y, 2) = 1.0f;
                for (int c = 0; c < 3; ++c) prevIllum(x, y, c) = texture(x, y, c);
                prevMoments(x, y, 0) = texture(x, y, 0);
                prevMoments(x, y, 1) = 2.0f * texture(x, y, 1);
                prevLength(x, y, 0) = 3.0f;
            }
    }

    void run(float mx, float my) {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) motion(x, y, 0) = mx, motion(x, y, 1) = my;
        svgf::Reproject r;
        r.havePrevious = true;
        r.motion = motion.view(), r.depth = depth.view(), r.normal = normal.view(), r.ids = ids.view();
        r.depthGrad = grad.view();
        r.prevIllum = prevIllum.view(), r.prevMoments = prevMoments.view(), r.prevLength = prevLength.view();
        r.prevDepth = prevDepth.view(), r.prevNormal = prevNormal.view(), r.prevIds = prevIds.view();
        r.outIllum = outIllum.view(), r.outMoments = outMoments.view(), r.outLength = outLength.view();
        CpuExec().forEachPixel(w, h, r);
    }
};

TEST(SvgfReproject, IntegerMotionCopiesTheShiftedPreviousFrameExactly) {
    ReprojectFixture f;
    f.run(-2.0f, 1.0f);  // previous - current: the content moved 2 px right and 1 px up
    for (int y = 0; y < f.h - 1; ++y)
        for (int x = 2; x < f.w; ++x) {
            for (int c = 0; c < 3; ++c) ASSERT_EQ(f.outIllum(x, y, c), ReprojectFixture::texture(x - 2, y + 1, c));
            ASSERT_EQ(f.outMoments(x, y, 0), f.prevMoments(x - 2, y + 1, 0));
            ASSERT_EQ(f.outMoments(x, y, 1), f.prevMoments(x - 2, y + 1, 1));
            ASSERT_EQ(f.outLength(x, y, 0), 3.0f);
        }
}

TEST(SvgfReproject, HalfPixelMotionGivesTheBilinearValue) {
    ReprojectFixture f;
    f.run(-1.5f, 0.5f);
    for (int y = 0; y < f.h - 1; ++y)
        for (int x = 2; x < f.w; ++x)
            for (int c = 0; c < 3; ++c) {
                float expect = 0.25f * (ReprojectFixture::texture(x - 2, y, c) + ReprojectFixture::texture(x - 1, y, c) +
                                        ReprojectFixture::texture(x - 2, y + 1, c) + ReprojectFixture::texture(x - 1, y + 1, c));
                // Four float products and a normalisation: a few ulps of values up to ~7.
                ASSERT_NEAR(f.outIllum(x, y, c), expect, 1e-5f) << x << "," << y;
            }
}

TEST(SvgfReproject, InconsistentTapsAreDroppedAndTheFallbackSearchRecovers) {
    ReprojectFixture f;
    // Column 10 of the previous frame belongs to another mesh: a half-pixel footprint over columns
    // 9 and 10 keeps only column 9 (renormalised bilinear weight).
    for (int y = 0; y < f.h; ++y) f.prevIds(10, y, 0) = 7.0f;
    f.run(-0.5f, 0.0f);
    EXPECT_EQ(f.outIllum(9 + 1, 5, 0), ReprojectFixture::texture(9, 5, 0));  // x = 10 reads 9.5
    // Everything in the footprint is another mesh -> 3x3 search finds the neighbours.
    for (int y = 0; y < f.h; ++y) f.prevIds(9, y, 0) = 7.0f;
    f.run(0.0f, 0.0f);
    EXPECT_EQ(f.outLength(9, 5, 0), 3.0f);  // found a consistent neighbour (column 8)
    EXPECT_NEAR(f.outIllum(9, 5, 0),
                (ReprojectFixture::texture(8, 4, 0) + ReprojectFixture::texture(8, 5, 0) + ReprojectFixture::texture(8, 6, 0)) / 3.0f,
                1e-5f);
}

TEST(SvgfReproject, MotionOutsideTheImageOrNonFiniteResetsTheHistory) {
    ReprojectFixture f;
    for (float m : {-1e4f, 40.0f, 1e20f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        f.run(m, 0.0f);
        for (int y = 0; y < f.h; ++y)
            for (int x = 0; x < f.w; ++x) ASSERT_EQ(f.outLength(x, y, 0), 0.0f) << "motion " << m;
    }
}

// ---- history length through the whole driver ----------------------------------------------------

TEST(SvgfHistory, DisoccludedPixelsResetAndConsistentPixelsIncrement) {
    SceneOptions o;  // noiseless, box slides 4 px per frame
    svgf::SvgfPipeline<CpuExec> pipe(SvgfParams{});
    for (int t = 0; t < 3; ++t) {
        pipe.run(makeFrame(o, t).frame());
        const Image& len = pipe.state().histLength;  // this frame's accumulated history length
        // Ground far from the box: t + 1 frames, exactly (bilinear weight 1 on a static pixel).
        EXPECT_EQ(len(2, o.height - 2, 0), float(t + 1));
        // Inside the moving box (consistent reprojection along its motion): t + 1.
        EXPECT_EQ(len(boxX0(o, t) + 5, boxY0(o) + 5, 0), float(t + 1));
        // Sky: background matches background.
        EXPECT_EQ(len(5, 1, 0), float(t + 1));
    }
    // Ground the box uncovered in the last frame: columns x0(1) .. x0(2)-1. The first column can
    // borrow history from its left neighbour (itself uncovered one frame earlier, so length 1 or
    // 2) through the 3x3 search; the others are reset.
    const Image& len = pipe.state().histLength;
    for (int x = boxX0(o, 1) + 1; x < boxX0(o, 2); ++x)
        for (int y = boxY0(o) + 1; y < boxY0(o) + boxSize(o) - 1; ++y) EXPECT_EQ(len(x, y, 0), 1.0f) << x << "," << y;
    EXPECT_GT(len(boxX0(o, 1), boxY0(o) + 5, 0), 1.0f);
}

// ---- convergence --------------------------------------------------------------------------------

TEST(SvgfConvergence, StaticNoisySceneApproachesTheTruth) {
    SceneOptions o;
    o.withBox = false;
    o.noiseSigma = 0.3f;
    SvgfParams p;
    p.safetyNet = 0.0f;  // SVGF's own accumulation (the net would hand edges to the per-frame filter)
    SvgfDenoiser d(p);
    std::vector<double> err;
    double inputMse = 0;
    for (int t = 0; t < 10; ++t) {
        SynthFrame f = makeFrame(o, t);
        Image out = d.denoiseFrame(f.frame());
        err.push_back(mse(out, f.truth));
        inputMse = mse(f.color, f.truth);
    }
    for (size_t i = 0; i < err.size(); ++i) std::printf("frame %zu: MSE %.5f\n", i, err[i]);
    // Measured (64x48, σ = 0.3, input MSE ~0.09): 0.0034 after one frame, 0.0012 after three,
    // ~0.0010 from then on (α = 0.2 caps the temporal gain). The bounds leave ~1.6x headroom.
    EXPECT_LT(err[2], 0.6 * err[0]);
    EXPECT_LT(err.back(), 0.5 * err.front());
    EXPECT_LT(err.back(), 0.02 * inputMse);
}

// ---- variance -----------------------------------------------------------------------------------

TEST(SvgfVariance, TemporalEstimateMatchesTheNoiseVariance) {
    SceneOptions o;
    o.flat = true;
    o.withBox = false;
    o.noiseSigma = 0.1f;
    const float sigma2 = o.noiseSigma * o.noiseSigma;  // grey noise: luminance variance = σ²
    SvgfParams p;
    svgf::SvgfPipeline<CpuExec> pipe(p);
    for (int t = 0; t < 40; ++t) pipe.run(makeFrame(o, t).frame());
    const Image& v = pipe.state().variance;
    double mean = 0;
    for (size_t i = 0; i < v.size(); ++i) mean += v.data()[i];
    mean /= double(v.size());
    // An exponential moving average with weight a has E[μ2 - μ1²] = σ² (1 - a / (2 - a)).
    const double a = p.momentsAlpha, expected = sigma2 * (1.0 - a / (2.0 - a));
    // 3072 pixels, each estimate averaging ~9 effective frames: the mean's relative standard error
    // is about 1%; 4% is four of those.
    EXPECT_NEAR(mean / expected, 1.0, 0.04) << "mean variance " << mean << " expected " << expected;
}

TEST(SvgfVariance, SpatialEstimateIsUsedWhileTheHistoryIsShort) {
    SceneOptions o;
    o.flat = true;
    o.withBox = false;
    o.noiseSigma = 0.1f;
    const double sigma2 = double(o.noiseSigma) * o.noiseSigma;
    auto meanVariance = [&](const SvgfParams& p) {
        svgf::SvgfPipeline<CpuExec> pipe(p);
        pipe.run(makeFrame(o, 0).frame());
        const Image& v = pipe.state().variance;
        double m = 0;
        for (size_t i = 0; i < v.size(); ++i) m += v.data()[i];
        return m / double(v.size());
    };
    // History 1 < 4: the 7x7 spatial estimate, (49 - 1)/49 σ² in expectation on this flat plane
    // (fewer taps at the border); ±6% covers the sampling error of 3072 correlated estimates.
    EXPECT_NEAR(meanVariance(SvgfParams{}) / sigma2, 48.0 / 49.0, 0.06);
    // Forcing the temporal estimate at history 1 gives μ2 - μ1² = l² - l² = 0, up to the rounding
    // of l²: on the FMA targets (AVX2, AVX-512: src/core/isa_dispatch.h) μ2 - μ1·μ1 is contracted
    // into one fused multiply-add, which leaves l²'s rounding error, at most half an ulp of l²
    // (l ≈ 1 here: 6e-8; measured mean 1.2e-8). The bound, 1e-5 σ² = 1e-7, is 1e5 times below
    // the spatial estimate this test tells it from (σ² = 1e-2).
    SvgfParams temporal;
    temporal.spatialVarianceFrames = 1;
    EXPECT_LT(meanVariance(temporal), 1e-5 * sigma2);
}

// ---- bad input ----------------------------------------------------------------------------------

TEST(SvgfRobustness, NanInputsAndWildMotionGiveFiniteOutput) {
    SceneOptions o;
    o.noiseSigma = 0.1f;
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    svgf::SvgfPipeline<CpuExec> pipe(SvgfParams{});
    Image emission(o.width, o.height, 3);
    for (int t = 0; t < 4; ++t) {
        SynthFrame f = makeFrame(o, t);
        for (int i = 0; i < 40; ++i) {
            int x = (i * 37 + t * 11) % o.width, y = (i * 17 + t * 5) % o.height;
            Image* bufs[] = {&f.color, &f.albedo, &f.normal, &f.depth, &f.ids, &f.motion, &emission};
            Image& b = *bufs[i % 7];
            b(x, y, i % 2) = (i % 3) ? nan : -inf;
        }
        f.color(3, 20, 0) = inf;
        f.motion(10, 30, 0) = 1e20f;   // far outside
        f.motion(11, 30, 1) = -3e4f;   // outside
        f.motion(12, 30, 0) = 200.0f;  // outside
        Frame in = f.frame();
        in.emission = &emission;
        pipe.run(in);
        ASSERT_TRUE(allFinite(*pipe.state().result)) << "frame " << t;
        for (const Image* img : {&pipe.state().histIllum, &pipe.state().histMoments, &pipe.state().variance})
            ASSERT_TRUE(allFinite(*img));
        if (t > 0) {
            // Documented rule: motion that leaves the image is a disocclusion (history reset).
            EXPECT_EQ(pipe.state().histLength(10, 30, 0), 1.0f);
            EXPECT_EQ(pipe.state().histLength(11, 30, 0), 1.0f);
            EXPECT_EQ(pipe.state().histLength(12, 30, 0), 1.0f);
        }
    }
    // A pixel whose first colour sample is NaN is filled in by the spatial filter, not left black.
    SceneOptions clean;
    SynthFrame f = makeFrame(clean, 0);
    f.color(2, 40, 0) = f.color(2, 40, 1) = f.color(2, 40, 2) = nan;
    SvgfDenoiser d;
    Image out = d.denoiseFrame(f.frame());
    EXPECT_TRUE(allFinite(out));
    EXPECT_NEAR(out(2, 40, 1), f.truth(2, 40, 1), 0.1f * f.truth(2, 40, 1));
}

TEST(SvgfRobustness, BadFramesAndParamsAreInputErrors) {
    Image c(8, 8, 3), small(4, 8, 3), grey(8, 8, 1);
    SvgfDenoiser d;
    EXPECT_THROW(d.denoiseFrame(Frame{}), InputError);
    Frame f;
    f.color = &c;
    f.albedo = &small;
    try {
        d.denoiseFrame(f);
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("albedo"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("4x8"), std::string::npos) << e.what();
    }
    f.albedo = nullptr;
    f.motion = &grey;  // needs 2 channels
    EXPECT_THROW(d.denoiseFrame(f), InputError);
    f.motion = nullptr;
    EXPECT_NO_THROW(d.denoiseFrame(f));  // colour alone is enough

    auto bad = [](const std::function<void(SvgfParams&)>& change) {
        SvgfParams p;
        change(p);
        EXPECT_THROW(SvgfDenoiser{p}, InputError);
    };
    bad([](SvgfParams& p) { p.sigmaL = 0; });
    bad([](SvgfParams& p) { p.sigmaN = -1; });
    bad([](SvgfParams& p) { p.sigmaZ = std::nanf(""); });
    bad([](SvgfParams& p) { p.alpha = 0; });
    bad([](SvgfParams& p) { p.momentsAlpha = 1.5f; });
    bad([](SvgfParams& p) { p.historyCap = 0; });
    bad([](SvgfParams& p) { p.levels = 11; });
    bad([](SvgfParams& p) { p.feedbackTap = 5; });
    bad([](SvgfParams& p) { p.spatialVarianceFrames = 0; });
    bad([](SvgfParams& p) { p.depthTolerance = -1; });
    bad([](SvgfParams& p) { p.normalCos = 2; });
    bad([](SvgfParams& p) { p.taaAlpha = 0; });
    bad([](SvgfParams& p) { p.emissionAlpha = 0; });
    bad([](SvgfParams& p) { p.emissionAlpha = std::numeric_limits<float>::quiet_NaN(); });
    bad([](SvgfParams& p) { p.emissionMotionAlpha = -1.0f; });
    bad([](SvgfParams& p) { p.emissionMotionAlpha = std::numeric_limits<float>::infinity(); });
    if (!cudaAvailable()) EXPECT_THROW(SvgfDenoiser(SvgfParams{}, Device::Cuda), InputError);
}

TEST(SvgfRobustness, ResetAndSizeChangeStartANewHistory) {
    SceneOptions o;
    o.noiseSigma = 0.2f;
    SvgfDenoiser d;
    Image first = d.denoiseFrame(makeFrame(o, 0).frame());
    d.denoiseFrame(makeFrame(o, 1).frame());
    d.reset();
    Image again = d.denoiseFrame(makeFrame(o, 0).frame());
    EXPECT_EQ(maxAbsDiff(first, again), 0.0f);  // deterministic, and no history leaked
    SceneOptions big = o;
    big.width = 80;
    Image other = d.denoiseFrame(makeFrame(big, 0).frame());
    EXPECT_EQ(other.width(), 80);
    SvgfDenoiser fresh;
    EXPECT_EQ(maxAbsDiff(other, fresh.denoiseFrame(makeFrame(big, 0).frame())), 0.0f);
}

TEST(SvgfParamsTest, ZeroLevelsIsTemporalAccumulationWithTheDefaultTap) {
    // levels 0 ("temporal accumulation only") must work without also setting feedbackTap: the
    // default tap 0 then means the accumulation, exactly as -1 does.
    SceneOptions o;
    o.noiseSigma = 0.2f;
    SvgfParams p0;
    p0.levels = 0;
    SvgfParams pm = p0;
    pm.feedbackTap = -1;
    EXPECT_NO_THROW(validateSvgfParams(p0));
    SvgfDenoiser a(p0), b(pm);
    for (int t = 0; t < 4; ++t) {
        Image x = a.denoiseFrame(makeFrame(o, t).frame()), y = b.denoiseFrame(makeFrame(o, t).frame());
        EXPECT_EQ(maxAbsDiff(x, y), 0.0f) << "frame " << t;
    }
    SvgfParams bad = p0;
    bad.feedbackTap = 1;  // no level 1 to feed back
    try {
        validateSvgfParams(bad);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("got 1 with levels 0"), std::string::npos) << e.what();
    }
}

// ---- every parameter matters ------------------------------------------------------------------

TEST(SvgfParamsTest, EveryFieldChangesTheOutput) {
    SceneOptions o;
    o.noiseSigma = 0.2f;
    o.emitter = true;  // for the emission fields
    const int frames = 6;
    const Image base = runSequence(SvgfParams{}, o, frames);
    SvgfParams taaBase;
    taaBase.taa = true;
    const Image taaOut = runSequence(taaBase, o, frames);
    struct Case {
        const char* name;
        std::function<void(SvgfParams&)> change;
        const Image* reference;
    };
    std::vector<Case> cases = {
        {"sigmaL", [](SvgfParams& p) { p.sigmaL = 1.0f; }, &base},
        {"sigmaN", [](SvgfParams& p) { p.sigmaN = 4.0f; }, &base},
        {"sigmaZ", [](SvgfParams& p) { p.sigmaZ = 8.0f; }, &base},
        {"alpha", [](SvgfParams& p) { p.alpha = 0.5f; }, &base},
        {"momentsAlpha", [](SvgfParams& p) { p.momentsAlpha = 0.6f; }, &base},
        {"historyCap", [](SvgfParams& p) { p.historyCap = 2; }, &base},
        {"levels", [](SvgfParams& p) { p.levels = 3; }, &base},
        {"feedbackTap", [](SvgfParams& p) { p.feedbackTap = 2; }, &base},
        {"spatialVarianceFrames", [](SvgfParams& p) { p.spatialVarianceFrames = 1; }, &base},
        {"depthTolerance", [](SvgfParams& p) { p.depthTolerance = 0.4f; }, &base},
        {"normalCos", [](SvgfParams& p) { p.normalCos = 0.9999f; }, &base},
        {"taa", [](SvgfParams& p) { p.taa = true; }, &base},
        {"taaAlpha", [](SvgfParams& p) { p.taa = true, p.taaAlpha = 0.5f; }, &taaOut},
        {"emissionAlpha", [](SvgfParams& p) { p.emissionAlpha = 0.5f; }, &base},
        {"emissionMotionAlpha", [](SvgfParams& p) { p.emissionMotionAlpha = 0.0f; }, &base},
        {"historyClip", [](SvgfParams& p) { p.historyClip = 0.0f; }, &base},
        {"learnedSpatial", [](SvgfParams& p) { p.learnedSpatial = true; }, &base},
    };
    for (const auto& c : cases) {
        SvgfParams p;
        c.change(p);
        Image out = runSequence(p, o, frames);
        // Outputs are O(1); 1e-3 is far above float noise (the runs are deterministic anyway).
        EXPECT_GT(maxAbsDiff(out, *c.reference), 1e-3f) << c.name << " did not change the output";
    }
}

TEST(SvgfModulation, IsTheStillFiltersAlbedoWithSvgfsFloorAndNoRimRule) {
    // SVGF's divisor is filters::pixelModulationAlbedo without the rim rule (svgf::albedoRule();
    // one function for both): per pixel
    // it must equal SVGF's own rule as it was written before the merge, exactly (same operations):
    // non-finite channel -> 1, t = min(m / 0.1, 1)^2, a' = 1 + t (max(a, 1e-3) - 1), a' = max(a,
    // 1e-3) where t = 1. And no rim rule: a black neighbour changes nothing (the still filters'
    // rule raises their floor there).
    const float vals[] = {0.0f, 1e-4f, 1e-3f, 0.02f, 0.05f, 0.0999f, 0.1f, 0.15f, 0.5f, 1.0f, 3.0f, NAN, INFINITY};
    Image img(3, 3, 3);
    for (float r : vals)
        for (float g : vals)
            for (float b : {0.0f, 0.07f, 0.9f, NAN}) {
                img.fill(0.0f);  // black neighbours
                img(1, 1, 0) = r, img(1, 1, 1) = g, img(1, 1, 2) = b;
                float a3[3];
                svgf::albedoRule().at(img.view(), 1, 1, a3);
                const Vec3 got(a3[0], a3[1], a3[2]);
                const float a[3] = {std::isfinite(r) ? r : 1.0f, std::isfinite(g) ? g : 1.0f, std::isfinite(b) ? b : 1.0f};
                const float m = std::max(std::max(a[0], a[1]), a[2]);
                const float t = std::min(m / 0.1f, 1.0f) * std::min(m / 0.1f, 1.0f);
                float want[3];
                for (int c = 0; c < 3; ++c) {
                    const float ac = std::max(a[c], 1e-3f);
                    want[c] = t >= 1.0f ? ac : 1.0f + t * (ac - 1.0f);
                }
                EXPECT_EQ(got.x, want[0]) << r << " " << g << " " << b;
                EXPECT_EQ(got.y, want[1]) << r << " " << g << " " << b;
                EXPECT_EQ(got.z, want[2]) << r << " " << g << " " << b;
            }
    // The still filters' rule does act on this pixel (so the test above would see it).
    img.fill(0.0f);
    for (int c = 0; c < 3; ++c) img(1, 1, c) = 0.15f;
    float still[3];
    filters::pixelModulationAlbedo(img.view(), 1, 1, 1e-3f, 0.1f, still);
    float svgfA[3];
    svgf::albedoRule().at(img.view(), 1, 1, svgfA);
    EXPECT_NE(still[0], svgfA[0]);
}

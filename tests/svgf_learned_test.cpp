// SVGF with the learned cascade as its spatial filter (SvgfParams::learnedSpatial, svgf_learned.h):
// the temporal half and the history are SVGF's own, the cascade's variance is that of the
// accumulation, the output is finite and denoised, the row engine gives the functors' values, and
// the cascade runs the denoiser's weights (built-in or given) with temporaries kept between frames.
#include "filters/svgf_learned.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "atrous/params.h"
#include "atrous/svgf.h"
#include "core/parallel.h"
#include "filters/atrous_level.h"
#include "filters/svgf_pipeline.h"
#include "learned_fixture.h"
#include "svgf_test_util.h"

using namespace atrous;
using namespace atrous::svgf_test;

namespace {

SvgfParams learnedParams(int feedbackTap = 0) {
    SvgfParams p;
    p.learnedSpatial = true;
    p.feedbackTap = feedbackTap;
    return p;
}

bool bitEqual(const Image& a, const Image& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Runs `frames` frames through a pipeline on the CPU, the fast paths on or off.
void runFrames(svgf::SvgfPipeline<CpuExec>& pipe, const SceneOptions& o, int frames,
               bool fast = true) {
    const bool saved = filters::atrousCpuFastPath();
    filters::atrousCpuFastPath() = fast;
    for (int t = 0; t < frames; ++t) pipe.run(makeFrame(o, t).frame());
    filters::atrousCpuFastPath() = saved;
}

}  // namespace

TEST(SvgfLearned, VarianceFactorIsTheAccumulationsAverage) {
    // A running mean of n frames for n <= 1/alpha, then the exponential average's alpha / (2 -
    // alpha).
    EXPECT_FLOAT_EQ(svgf::accumulatedVarianceFactor(0.2f, 1.0f), 1.0f);
    EXPECT_FLOAT_EQ(svgf::accumulatedVarianceFactor(0.2f, 4.0f), 0.25f);
    EXPECT_FLOAT_EQ(svgf::accumulatedVarianceFactor(0.2f, 32.0f), 0.2f / 1.8f);
    EXPECT_FLOAT_EQ(svgf::accumulatedVarianceFactor(0.2f, 0.0f), 1.0f);  // an empty pixel
    EXPECT_FLOAT_EQ(svgf::accumulatedVarianceFactor(1.0f, 9.0f), 1.0f);  // no accumulation
}

// On a flat, static, noisy scene with the plain exponential average (no clip, the accumulation as
// history) the cascade's var matches the variance of the accumulated colour itself.
TEST(SvgfLearned, CascadeVarianceIsTheAccumulatedColoursVariance) {
    SceneOptions o;
    o.flat = true;
    o.withBox = false;
    o.noiseSigma = 0.1f;
    SvgfParams p = learnedParams(-1);
    p.historyClip = 0.0f;
    svgf::SvgfPipeline<CpuExec> pipe(p);
    runFrames(pipe, o, 40);
    const Image& acc = pipe.state().histIllum;  // tap -1: this frame's accumulation
    const Image& var = pipe.state().learnedVar;
    double mean = 0, mean2 = 0, est = 0;
    const size_t n = size_t(acc.width()) * size_t(acc.height());
    for (size_t i = 0; i < n; ++i) {
        const double v = acc.data()[i];  // channel 0
        mean += v, mean2 += v * v, est += var.data()[i];
    }
    mean /= double(n), mean2 /= double(n), est /= double(n);
    const double actual = mean2 - mean * mean;
    // SVGF's moment estimate is biased low by 1 - a / (2 - a) (tests/svgf_test.cpp,
    // TemporalEstimateMatchesTheNoiseVariance); the sample variance over 3072 independent pixels
    // has a relative standard error of sqrt(2 / 3072) = 2.6%: 0.08 is three of those.
    const double a = p.momentsAlpha;
    std::printf("cascade var %.4g, variance of the accumulation %.4g, ratio %.4f\n", est, actual,
                est / actual);
    EXPECT_NEAR(est / actual, 1.0 - a / (2.0 - a), 0.08);
    // Unscaled (SVGF's per-sample variance) it would be 9x this: the factor is what matters.
    EXPECT_LT(est, 0.2 * double(o.noiseSigma) * double(o.noiseSigma));
}

// The temporal half is SVGF's: the history after any number of frames is bit-identical to the
// à-trous SVGF's, with the first level fed back (tap 0, SVGF's level 0 still runs) or the
// accumulation.
TEST(SvgfLearned, HistoryIsSvgfsOwn) {
    SceneOptions o;
    o.noiseSigma = 0.2f;
    o.emitter = true;
    for (int tap : {0, -1}) {
        SvgfParams svgfP;
        svgfP.feedbackTap = tap;
        svgf::SvgfPipeline<CpuExec> atrous(svgfP), learned(learnedParams(tap));
        runFrames(atrous, o, 6);
        runFrames(learned, o, 6);
        const svgf::SvgfState &a = atrous.state(), &l = learned.state();
        EXPECT_TRUE(bitEqual(a.histIllum, l.histIllum)) << "tap " << tap;
        EXPECT_TRUE(bitEqual(a.histMoments, l.histMoments)) << "tap " << tap;
        EXPECT_TRUE(bitEqual(a.histLength, l.histLength)) << "tap " << tap;
        EXPECT_TRUE(bitEqual(a.histEmission, l.histEmission)) << "tap " << tap;
        // ... while the output is the cascade's (outputs are O(1); 1e-3 is far above rounding).
        EXPECT_GT(maxAbsDiff(a.output, l.output), 1e-3f) << "tap " << tap;
    }
}

// A static noisy scene: the learned path stays finite, converges like SVGF's, and beats the input.
TEST(SvgfLearned, StaticNoisySceneIsFiniteAndDenoised) {
    SceneOptions o;
    o.boxSpeed = 0.0f, o.boxApproach = 0.0f, o.boxTurn = 0.0f;
    o.noiseSigma = 0.3f;
    SvgfDenoiser d(learnedParams());
    double first = 0, last = 0, input = 0;
    for (int t = 0; t < 10; ++t) {
        SynthFrame f = makeFrame(o, t);
        const Image out = d.denoiseFrame(f.frame());
        ASSERT_TRUE(allFinite(out)) << "frame " << t;
        const double e = mse(out, f.truth);
        if (t == 0) first = e;
        last = e;
        input = mse(f.color, f.truth);
        std::printf("frame %d: MSE %.5f (input %.4f)\n", t, e, input);
    }
    // Measured (64x48, sigma 0.3, input MSE ~0.09) with the built-in weights retrained on data
    // version 2: frame 0 0.00332, frame 9 0.00118 (0.36x; ee1ce7d's: 0.00261, 0.00137). The input bound is SVGF's own (tests/svgf_test.cpp,
    // StaticNoisySceneApproachesTheTruth); SVGF's 0.5x from frame 0 to 9 is not: the cascade
    // alone removes more of frame 0's noise than SVGF's à-trous, leaving the history less to do.
    // 0.7x still fails without the accumulation (every frame would stay at frame 0's level).
    EXPECT_LT(last, 0.7 * first);
    EXPECT_LT(last, 0.05 * input);
}

// Non-finite buffers (NaN colour, albedo, normal, depth) give finite output on the learned path.
TEST(SvgfLearned, NanInputsGiveFiniteOutput) {
    SceneOptions o;
    o.noiseSigma = 0.2f;
    SvgfDenoiser d(learnedParams());
    for (int t = 0; t < 4; ++t) {
        SynthFrame f = makeFrame(o, t);
        for (int x = 0; x < 8; ++x) {
            f.color(x, 10, 1) = NAN, f.albedo(x, 11, 0) = NAN, f.normal(x, 12, 2) = INFINITY;
            f.depth(x, 13, 0) = NAN, f.color(x, 14, 0) = INFINITY;
        }
        EXPECT_TRUE(allFinite(d.denoiseFrame(f.frame()))) << "frame " << t;
    }
}

// The CPU row engine and the functors (the GPU's code) give the same frames. With the accumulation
// as history (tap -1) no SVGF level runs, so what differs is the learned cascade alone, held to the
// bound of tests/learned_test.cpp (RowEngineEqualsFunctors: 2e-6 relative, measured bit-identical
// there); the frames' history carries any difference forward, so this checks all of them.
TEST(SvgfLearned, RowEngineEqualsFunctors) {
    SceneOptions o;
    o.noiseSigma = 0.2f;
    o.emitter = true;
    svgf::SvgfPipeline<CpuExec> fast(learnedParams(-1)), ref(learnedParams(-1));
    double worst = 0;
    for (int t = 0; t < 5; ++t) {
        const SynthFrame f = makeFrame(o, t);
        filters::atrousCpuFastPath() = true;
        fast.run(f.frame());
        filters::atrousCpuFastPath() = false;
        ref.run(f.frame());
        filters::atrousCpuFastPath() = true;
        const Image &a = *fast.state().result, &b = *ref.state().result;
        for (size_t i = 0; i < a.size(); ++i)
            worst = std::max(worst, double(std::fabs(a.data()[i] - b.data()[i])) /
                                        std::max(1.0f, std::fabs(b.data()[i])));
    }
    std::printf("row engine vs functors over 5 frames: %.3g\n", worst);
    EXPECT_LE(worst, 2e-6);
}

// The learned spatial filter runs the denoiser's weights: another valid set (the parity fixture's
// random weights) changes the output; LearnedWeights::builtin() passed explicitly is the default.
TEST(SvgfLearned, DenoiserTakesOtherWeights) {
    SceneOptions o;
    o.noiseSigma = 0.2f;
    const LearnedWeights fixture = LearnedWeights::parse(test::fixture().weights.data(), test::fixture().weights.size(),
                                                         "fixture");
    SvgfDenoiser builtin(learnedParams()), explicitBuiltin(learnedParams(), Device::Cpu, LearnedWeights::builtin()),
        other(learnedParams(), Device::Cpu, fixture);
    for (int t = 0; t < 3; ++t) {
        const SynthFrame f = makeFrame(o, t);
        const Image a = builtin.denoiseFrame(f.frame()), b = explicitBuiltin.denoiseFrame(f.frame()),
                    c = other.denoiseFrame(f.frame());
        EXPECT_TRUE(bitEqual(a, b)) << "frame " << t;
        ASSERT_TRUE(allFinite(c)) << "frame " << t;
        // Outputs are O(1): random weights against trained ones differ far above rounding.
        EXPECT_GT(maxAbsDiff(a, c), 1e-2f) << "frame " << t;
    }
}

// The cascade's temporaries (and on CUDA the network's copy) live in the state between frames
// (LearnedCache): new weights mid-sequence and a new size each give what a fresh pipeline gives.
// The history does not depend on the weights (HistoryIsSvgfsOwn), so the frames are bit-identical.
TEST(SvgfLearned, CachedTemporariesFollowTheWeightsAndTheSize) {
    const LearnedWeights fixture = LearnedWeights::parse(test::fixture().weights.data(), test::fixture().weights.size(),
                                                         "fixture");
    SceneOptions o;
    o.noiseSigma = 0.2f;
    svgf::SvgfPipeline<CpuExec> pipe(learnedParams()), fresh(learnedParams());
    fresh.setLearnedWeights(fixture);
    for (int t = 0; t < 3; ++t) pipe.run(makeFrame(o, t).frame()), fresh.run(makeFrame(o, t).frame());
    EXPECT_FALSE(bitEqual(pipe.state().output, fresh.state().output));
    pipe.setLearnedWeights(fixture);
    pipe.run(makeFrame(o, 3).frame()), fresh.run(makeFrame(o, 3).frame());
    EXPECT_TRUE(bitEqual(pipe.state().output, fresh.state().output));
    SceneOptions small = o;
    small.width = 40, small.height = 28;  // fewer pixels: stale planes would be read at the old stride
    svgf::SvgfPipeline<CpuExec> freshSmall(learnedParams());
    freshSmall.setLearnedWeights(fixture);
    for (int t = 0; t < 2; ++t) pipe.run(makeFrame(small, t).frame()), freshSmall.run(makeFrame(small, t).frame());
    ASSERT_EQ(pipe.state().output.width(), 40);
    EXPECT_TRUE(bitEqual(pipe.state().output, freshSmall.state().output));
    EXPECT_EQ(pipe.state().learnedCache.width, 40);
}

// The table's row: `learned_spatial` (CLI --svgf-learned-spatial, Python learned_spatial=True).
TEST(SvgfLearned, IsARowOfTheSvgfTable) {
    const ParamField<SvgfParams>* f = svgfParams().find("learned_spatial");
    ASSERT_NE(f, nullptr);
    EXPECT_EQ(svgfParams().flag(*f), "--svgf-learned-spatial");
    EXPECT_FALSE(
        SvgfParams{}.learnedSpatial);  // SVGF's à-trous until the learned one is measured better
}

// Per-stage timings in the filter reports (DenoiseReport::stages, SvgfReport): the stage list is
// the driver's, in order, and the times are consistent with the totals. Timings themselves are not
// checked against any speed (that is the benchmarks' job): only that they are finite, >= 0 and
// add up.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/svgf.h"
#include "denoise_test_util.h"
#include "stage_times_test_util.h"

using namespace atrous;

// The stage report of one still denoise (default options but the method and level count) of a
// 48 x 40 synthetic scene.
static DenoiseReport stillReport(DenoiseMethod method, int levels, unsigned seed) {
    const test::SyntheticScene scene = test::makeScene(48, 40, 0.3f, seed);
    DenoiseOptions o;
    o.method = method;
    o.eaw.levels = levels;
    DenoiseReport rep;
    test::denoiseReporting(scene.inputs(), o, rep);
    return rep;
}

TEST(StageTimes, EawReportListsEveryStageInOrder) {
    const DenoiseReport rep = stillReport(DenoiseMethod::Eaw, 3, 7);
    const std::vector<std::string> expected = {"sanitize", "fireflies", "demodulate", "sigma scales", "level 0",
                                               "level 1",  "level 2",   "give-back",  "remodulate"};
    EXPECT_EQ(test::stageNames(rep.stages), expected);
    // The stages are timed inside the window of rep.milliseconds with the same steady clock, so
    // their sum cannot exceed it (1e-6 ms: rounding of the two subtractions).
    EXPECT_LE(test::stageSum(rep.stages), rep.milliseconds + 1e-6);
    EXPECT_GT(test::stageSum(rep.stages), 0.0);
}

TEST(StageTimes, SureReportHasTheChoiceAfterEachLevel) {
    const DenoiseReport rep = stillReport(DenoiseMethod::Sure, 2, 8);
    const std::vector<std::string> expected = {"sanitize", "fireflies", "demodulate", "sigma scales", "level 0",
                                               "sure 0",   "level 1",   "sure 1",     "give-back",    "remodulate"};
    EXPECT_EQ(test::stageNames(rep.stages), expected);
    EXPECT_LE(test::stageSum(rep.stages), rep.milliseconds + 1e-6);
}

// Without a variance buffer the noise estimate's two stages come in under their own names (the
// global MAD before the sanitise pass, the per-pixel estimate after the demodulation); without an
// albedo there is no give-back.
TEST(StageTimes, NoiseEstimateStagesWithoutAVariance) {
    const test::SyntheticScene scene = test::makeScene(48, 40, 0.3f, 7);
    DenoiseOptions o;
    o.method = DenoiseMethod::Eaw;
    o.eaw.levels = 2;
    DenoiseReport rep;
    Frame in = scene.inputs();
    in.variance = nullptr;
    in.albedo = nullptr;
    test::denoiseReporting(in, o, rep);
    const std::vector<std::string> expected = {"noise sigma", "sanitize", "fireflies", "demodulate", "noise estimate",
                                               "sigma scales", "level 0", "level 1", "remodulate"};
    EXPECT_EQ(test::stageNames(rep.stages), expected);
    EXPECT_LE(test::stageSum(rep.stages), rep.milliseconds + 1e-6);
}

TEST(StageTimes, SvgfReportFollowsTheFramesWhileTimed) {
    const test::SyntheticScene scene = test::makeScene(40, 32, 0.3f, 9);
    SvgfParams p;
    p.levels = 2;
    p.feedbackTap = 0;
    p.taa = true;
    SvgfDenoiser d(p);
    Frame f;
    f.color = &scene.noisy;
    f.albedo = &scene.albedo;
    f.normal = &scene.normal;
    f.depth = &scene.depth;
    d.denoiseFrame(f);  // untimed: timing is off by default
    EXPECT_TRUE(d.lastReport().stages.empty());
    d.setTiming(true);
    d.denoiseFrame(f);
    const SvgfReport rep = d.lastReport();
    const std::vector<std::string> expected = {"demodulate", "reproject", "accumulate", "variance",
                                               "level 0",    "level 1",   "remodulate", "taa", "safety net"};
    EXPECT_EQ(test::stageNames(rep.stages), expected);
    // milliseconds is the start-to-last-mark span, i.e. the sum of the stages up to rounding.
    EXPECT_NEAR(rep.milliseconds, test::stageSum(rep.stages), 1e-6);
    // Off again: no report, and later frames are not timed.
    d.setTiming(false);
    d.denoiseFrame(f);
    EXPECT_TRUE(d.lastReport().stages.empty());
    EXPECT_EQ(d.lastReport().milliseconds, 0.0);
}

// The viewer's timing table (apps/atrous/view/stage_history.h, header-only, no GL).
#include "../apps/atrous/view/stage_history.h"

TEST(StageHistory, MeansOverTheWindowAndRestartsWhenTheStagesChange) {
    view::StageHistory h(3);
    for (double v : {1.0, 2.0, 3.0, 10.0}) h.add({{"render", v}, {"A level 0", 2 * v}});
    ASSERT_EQ(h.size(), 2u);
    EXPECT_EQ(h.name(1), "A level 0");
    EXPECT_EQ(h.frames(), 3u);  // the window keeps the last 3 frames: 2, 3, 10
    EXPECT_DOUBLE_EQ(h.mean(0), 5.0);
    EXPECT_DOUBLE_EQ(h.median(0), 3.0);
    EXPECT_DOUBLE_EQ(h.mean(1), 10.0);
    // Another method: another stage list, and nothing of the old one is mixed in.
    h.add({{"render", 4.0}, {"A reproject", 1.0}});
    ASSERT_EQ(h.size(), 2u);
    EXPECT_EQ(h.name(1), "A reproject");
    EXPECT_EQ(h.frames(), 1u);
    EXPECT_DOUBLE_EQ(h.mean(0), 4.0);
}

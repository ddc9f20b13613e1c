// The viewer's frame pipeline (apps/atrous/view/view_pipeline.h) without a window, on the CPU:
// stepping and the running mean, what restarts it (camera move, reset, spp, accumulation off),
// the comparison slots and a method switch, filter errors, the debug buffers, SVGF's motion
// vectors, the buffer dump; the orbit camera; and the host tonemapping of the buffer views
// (buffer_view.h). The headless window runs are tests/view_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/metrics.h"
#include "atrous/render.h"
#include "atrous/temporal.h"
#include "test_util.h"
#include "view/buffer_view.h"
#include "atrous/view_pipeline.h"
#include "render/scene_data.h"  // the scene's camera (white-box)

using atrous::DenoiseMethod;
using atrous::Device;
using atrous::Image;
using atrous::InputError;
using atrous::Scene;
using atrous::Vec3;
namespace pt = atrous::pt;
using namespace atrous::view;

namespace {

constexpr int kW = 32, kH = 24;

const Scene& cornell() {
    static const Scene s = Scene::builtin("cornell");
    return s;
}

Method svgfMethod() { return Method::of(*atrous::findSequenceMethod(atrous::kSvgfMethod)); }
Method temporalMethod() { return Method::of(*atrous::findSequenceMethod(atrous::kTemporalMethod)); }

PipelineSettings settings(Method a = Method::none(), int spp = 1) {
    PipelineSettings s;
    s.methodA = a;
    s.sppPerFrame = spp;
    s.maxDepth = 3;
    return s;
}

double meanOf(const Image& img) {
    double s = 0;
    for (size_t i = 0; i < img.size(); ++i) s += img.data()[i];
    return s / double(img.size());
}

bool allFinite(const Image& img) {
    for (size_t i = 0; i < img.size(); ++i)
        if (!std::isfinite(img.data()[i])) return false;
    return true;
}

float maxAbsDiff(const Image& a, const Image& b) {
    float m = 0;
    for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::fabs(a.data()[i] - b.data()[i]));
    return m;
}

// Mean squared difference of the two images clamped to [0, 1] (what the display shows, before
// the sRGB curve; the light, at 17, would otherwise outweigh everything else).
double displayMse(const Image& a, const Image& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        const double d = std::clamp(double(a.data()[i]), 0.0, 1.0) - std::clamp(double(b.data()[i]), 0.0, 1.0);
        s += d * d;
    }
    return s / double(a.size());
}

// Of the pixels where both depth buffers hit something (the background is 1e30), the fraction
// whose depths agree within the relative tolerance `tol`.
double fractionClose(const Image& a, const Image& b, float tol) {
    int n = 0, hits = 0;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x) {
            const float da = a(x, y, 0), db = b(x, y, 0);
            if (!(da < 1e29f && db < 1e29f)) continue;
            ++hits;
            n += std::fabs(da - db) <= tol * da;
        }
    return hits ? double(n) / hits : 0.0;
}

// The scene camera turned by `yaw` radians about the box's centre.
pt::Camera turned(const ViewPipeline& pl, float yaw) {
    OrbitCamera o = OrbitCamera::fromCamera(pl.sceneCamera(), 8.0f);
    o.orbit(yaw, 0.0f);
    return o.camera();
}

}  // namespace

TEST(ViewPipeline, MethodNamesRoundTripAndUnknownOnesAreInputErrors) {
    for (const std::string& n : methodNames()) EXPECT_EQ(methodName(parseMethod(n)), n);
    // The list is the library's: none, every still method, every causal sequence method.
    std::vector<std::string> expected{"none"};
    for (const auto& m : atrous::denoiseMethods()) expected.push_back(m.name);
    for (const auto& m : atrous::sequenceMethods())
        if (m.causal || m.causalMode) expected.push_back(m.name);
    EXPECT_EQ(methodNames(), expected);
    EXPECT_EQ(parseMethod("svgf"), svgfMethod());
    EXPECT_EQ(parseMethod("sure"), Method::of(DenoiseMethod::Sure));
    EXPECT_THROW(parseMethod("bilateral"), InputError);
    EXPECT_THROW(ViewPipeline(cornell(), 0, kH, Device::Cpu, 1), InputError);
}

TEST(ViewPipeline, StepsAccumulateFramesAndSamples) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    EXPECT_EQ(pl.framesAccumulated(), 0);
    pl.step(settings(Method::none(), 2));
    EXPECT_EQ(pl.framesAccumulated(), 1);
    EXPECT_EQ(pl.samplesPerPixel(), 2);
    EXPECT_TRUE(pl.varianceValid());  // 2 samples: a variance estimate exists
    pl.step(settings(Method::none(), 2));
    pl.step(settings(Method::none(), 2));
    EXPECT_EQ(pl.framesAccumulated(), 3);
    EXPECT_EQ(pl.samplesPerPixel(), 6);
    for (const Image* img : {&pl.color(), &pl.variance(), &pl.albedo(), &pl.normal(), &pl.position(), &pl.depth(),
                             &pl.ids()}) {
        EXPECT_EQ(img->width(), kW);
        EXPECT_EQ(img->height(), kH);
        EXPECT_TRUE(allFinite(*img));
    }
    EXPECT_GT(meanOf(pl.color()), 0.05);  // a lit box
    EXPECT_GT(pl.times().render, 0.0);
    EXPECT_GT(pl.times().accumulate, 0.0);
}

TEST(ViewPipeline, OneSamplePerPixelHasNoVarianceEstimate) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    pl.step(settings(Method::none(), 1));
    EXPECT_FALSE(pl.varianceValid());
    pl.step(settings(Method::none(), 1));
    EXPECT_TRUE(pl.varianceValid());  // two frames of one sample
}

TEST(ViewPipeline, TheAccumulatedColourIsTheMeanOfTheFrames) {
    // Same seed: frame k of both pipelines draws the same samples. The second one does not
    // accumulate, so its colour after step 2 is frame 2 alone.
    ViewPipeline acc(cornell(), kW, kH, Device::Cpu, 7), single(cornell(), kW, kH, Device::Cpu, 7);
    PipelineSettings off = settings();
    off.accumulate = false;
    acc.step(settings());
    single.step(off);
    const Image first = acc.color().clone();
    EXPECT_EQ(maxAbsDiff(first, single.color()), 0.0f);  // frame 1 alike
    acc.step(settings());
    single.step(off);
    EXPECT_EQ(single.framesAccumulated(), 1);
    EXPECT_GT(maxAbsDiff(first, single.color()), 1e-3f);  // fresh samples every frame
    float err = 0;
    for (size_t i = 0; i < first.size(); ++i) {
        const float mean = 0.5f * (first.data()[i] + single.color().data()[i]);
        err = std::max(err, std::fabs(acc.color().data()[i] - mean) / std::max(1.0f, std::fabs(mean)));
    }
    EXPECT_LT(err, 1e-5f);
}

TEST(ViewPipeline, ACameraMoveRestartsTheAccumulationAndChangesTheView) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    for (int i = 0; i < 3; ++i) pl.step(settings());
    ASSERT_EQ(pl.framesAccumulated(), 3);
    const Image depth = pl.depth().clone();
    pl.setCamera(turned(pl, 0.3f));
    pl.step(settings());
    EXPECT_EQ(pl.framesAccumulated(), 1);
    EXPECT_EQ(pl.samplesPerPixel(), 1);
    EXPECT_LT(fractionClose(depth, pl.depth(), 1e-3f), 0.5);  // another view
    pl.step(settings());
    EXPECT_EQ(pl.framesAccumulated(), 2);  // and accumulates again from there
    pl.setCamera(pl.sceneCamera());
    pl.step(settings());
    EXPECT_EQ(pl.framesAccumulated(), 1);
}

TEST(ViewPipeline, TheCameraSetIsTheOneRendered) {
    // Same seed, no accumulation: each frame is its own samples, so a pipeline whose camera went
    // away and came back renders what one that never moved renders, bit for bit.
    ViewPipeline moved(cornell(), kW, kH, Device::Cpu, 5), still(cornell(), kW, kH, Device::Cpu, 5);
    PipelineSettings off = settings();
    off.accumulate = false;
    moved.step(off);
    still.step(off);
    moved.setCamera(turned(moved, 0.3f));
    moved.step(off);
    still.step(off);
    EXPECT_LT(fractionClose(still.depth(), moved.depth(), 1e-3f), 0.5);
    EXPECT_GT(maxAbsDiff(still.color(), moved.color()), 1e-2f);
    moved.setCamera(moved.sceneCamera());
    moved.step(off);
    still.step(off);
    EXPECT_EQ(maxAbsDiff(still.depth(), moved.depth()), 0.0f);
    EXPECT_EQ(maxAbsDiff(still.color(), moved.color()), 0.0f);
}

TEST(ViewPipeline, ResetSppChangeAndAccumulationOffRestart) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    pl.step(settings());
    pl.step(settings());
    pl.resetAccumulation();
    pl.step(settings());
    EXPECT_EQ(pl.framesAccumulated(), 1);
    pl.step(settings());
    EXPECT_EQ(pl.framesAccumulated(), 2);
    pl.step(settings(Method::none(), 2));  // a running mean holds frames of one spp only
    EXPECT_EQ(pl.framesAccumulated(), 1);
    EXPECT_EQ(pl.samplesPerPixel(), 2);
    PipelineSettings off = settings(Method::none(), 2);
    off.accumulate = false;
    pl.step(off);
    pl.step(off);
    EXPECT_EQ(pl.framesAccumulated(), 1);
    // Nothing reads the running mean: skipped, and restarted when needed again.
    PipelineSettings skip = settings(svgfMethod(), 2);
    skip.needAccumulated = false;
    pl.step(settings(Method::none(), 2));
    pl.step(settings(Method::none(), 2));
    ASSERT_EQ(pl.framesAccumulated(), 2);
    pl.step(skip);
    EXPECT_EQ(pl.framesAccumulated(), 1);
    pl.step(settings(Method::none(), 2));
    EXPECT_EQ(pl.framesAccumulated(), 1);  // not 3: the skipped frame broke the running mean
}

TEST(ViewPipeline, TheSameSeedGivesTheSameFramesAndAnotherSeedOthers) {
    ViewPipeline a(cornell(), kW, kH, Device::Cpu, 3), b(cornell(), kW, kH, Device::Cpu, 3),
        c(cornell(), kW, kH, Device::Cpu, 4);
    for (ViewPipeline* p : {&a, &b, &c}) p->step(settings());
    EXPECT_EQ(maxAbsDiff(a.color(), b.color()), 0.0f);
    EXPECT_GT(maxAbsDiff(a.color(), c.color()), 1e-3f);
}

TEST(ViewPipeline, SlotsFollowTheMethodAndTheSplit) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    pl.step(settings(Method::none(), 1));
    EXPECT_EQ(pl.slot(0).method, Method::none());
    EXPECT_EQ(maxAbsDiff(pl.slot(0).image, pl.color()), 0.0f);  // none: the noisy input itself
    EXPECT_TRUE(pl.slot(1).image.empty());                       // no split: slot B not computed

    PipelineSettings s = settings(Method::of(DenoiseMethod::Eaw), 1);
    s.split = true;
    s.methodB = Method::none();
    pl.step(s);  // the method switch takes effect on the next step
    const SlotResult& a = pl.slot(0);
    EXPECT_EQ(a.method, Method::of(DenoiseMethod::Eaw));
    EXPECT_TRUE(a.error.empty()) << a.error;
    ASSERT_EQ(a.image.width(), kW);
    EXPECT_TRUE(allFinite(a.image));
    EXPECT_FALSE(a.stages.empty());
    EXPECT_GT(a.filterMs, 0.0);
    EXPECT_EQ(pl.slot(1).method, Method::none());
    EXPECT_EQ(maxAbsDiff(pl.slot(1).image, pl.color()), 0.0f);
    // EAW brings the 2-spp mean closer to a 256-spp render (another seed): MSE ratio 0.65 measured
    // (0.55 to 0.8 over seeds); 1 when the filter does nothing.
    ViewPipeline ref(cornell(), kW, kH, Device::Cpu, 99);
    for (int i = 0; i < 4; ++i) ref.step(settings(Method::none(), 64));
    EXPECT_LT(displayMse(a.image, ref.color()), 0.9 * displayMse(pl.color(), ref.color()));
    EXPECT_EQ(&pl.resultHost(0), &pl.slot(0).image);            // CPU: the result is on the host

    s.split = false;
    pl.step(s);
    EXPECT_EQ(pl.slot(1).method, Method::none());
    EXPECT_TRUE(pl.slot(1).image.empty());
}

TEST(ViewPipeline, EverySlotMethodRunsAndSvgfTakesTheFramesOwnSamples) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    for (Method m : {Method::of(DenoiseMethod::Sure), svgfMethod(), Method::of(DenoiseMethod::Eaw), svgfMethod(),
                     Method::of(DenoiseMethod::Learned), temporalMethod()}) {
        pl.step(settings(m));
        const SlotResult& r = pl.slot(0);
        EXPECT_EQ(r.method, m);
        EXPECT_TRUE(r.error.empty()) << methodName(m) << ": " << r.error;
        ASSERT_EQ(r.image.width(), kW) << methodName(m);
        EXPECT_TRUE(allFinite(r.image)) << methodName(m);
        EXPECT_FALSE(r.stages.empty()) << methodName(m);
    }
    // SVGF reads this frame's emission (the renderer's, on the CPU) and a motion buffer: zero for
    // a camera that did not move.
    const Image& m = pl.motion();
    for (size_t i = 0; i < m.size(); ++i) ASSERT_EQ(m.data()[i], 0.0f);
    EXPECT_EQ(pl.emission().width(), kW);
}

// The temporal method runs causal in the viewer, on each frame's own samples: with a still camera,
// from the fourth frame on (frames t-3..t averaged) it is closer to a 512-spp render than the same
// still method (auto) on each frame alone (the per-frame filter, accumulation off): measured 0.90x
// on cornell-point at 32x24 (0.1047 against 0.1158; the library through Python: 0.0985 against
// 0.1068 on its own frames); bound 0.97x. Its history restarts with the accumulation, and rejected parameters land in the slot.
TEST(ViewPipeline, TemporalRunsCausalOnTheFramesOwnSamples) {
    const Scene scene = Scene::builtin("cornell-point");
    atrous::RenderSettings rs;
    rs.width = kW, rs.height = kH, rs.spp = 512, rs.maxDepth = 3, rs.seed = 99;
    const Image ref = atrous::render(scene, rs).color;
    auto err = [&](const Image& img) { return atrous::computeMetrics(img, ref).relMse; };
    PipelineSettings s = settings(temporalMethod());
    PipelineSettings alone = settings(Method::of(DenoiseMethod::Auto));
    alone.accumulate = false;
    alone.split = true, alone.methodB = temporalMethod();  // the same frames through both
    ViewPipeline pl(scene, kW, kH, Device::Cpu, 1);
    double sumAlone = 0, sumTemporal = 0;
    for (int k = 0; k < 8; ++k) {
        pl.step(alone);
        ASSERT_TRUE(pl.slot(1).error.empty()) << pl.slot(1).error;
        ASSERT_TRUE(allFinite(pl.slot(1).image));
        if (k >= 3) sumAlone += err(pl.slot(0).image), sumTemporal += err(pl.slot(1).image);
    }
    std::printf("temporal in the viewer: relMSE %.4f against %.4f per frame (frames 4-8)\n", sumTemporal / 5, sumAlone / 5);
    EXPECT_LT(sumTemporal, 0.97 * sumAlone);
    pl.resetAccumulation();
    pl.step(s);
    EXPECT_TRUE(pl.slot(0).error.empty()) << pl.slot(0).error;
    sequenceParams(s, *atrous::findSequenceMethod(atrous::kTemporalMethod)).get<atrous::TemporalParams>()->radius = -1;
    pl.step(s);
    EXPECT_NE(pl.slot(0).error.find("radius"), std::string::npos) << pl.slot(0).error;
    EXPECT_EQ(pl.slot(0).image.width(), kW);
}

TEST(ViewPipeline, RejectedParametersLandInTheSlotAndTheInputIsShown) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    PipelineSettings s = settings(Method::of(DenoiseMethod::Eaw));
    s.denoise.eaw.levels = 0;  // 1..10
    ASSERT_NO_THROW(pl.step(s));
    EXPECT_FALSE(pl.slot(0).error.empty());
    EXPECT_EQ(maxAbsDiff(pl.slot(0).image, pl.color()), 0.0f);
    s.denoise.eaw.levels = 3;
    pl.step(s);
    EXPECT_TRUE(pl.slot(0).error.empty()) << pl.slot(0).error;

    PipelineSettings v = settings(svgfMethod());
    sequenceParams(v, *atrous::findSequenceMethod(atrous::kSvgfMethod)).get<atrous::SvgfParams>()->alpha = -1.0f;
    ASSERT_NO_THROW(pl.step(v));
    EXPECT_FALSE(pl.slot(0).error.empty());
    EXPECT_EQ(pl.slot(0).image.width(), kW);
}

TEST(ViewPipeline, DebugBuffersOnlyWhenAsked) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    PipelineSettings s = settings(Method::of(DenoiseMethod::Sure), 2);
    pl.step(s);
    EXPECT_TRUE(pl.detail().empty());
    EXPECT_EQ(pl.detailLevel(), -1);
    EXPECT_TRUE(pl.sureFractions().empty());

    s.detailLevel = 0;
    s.sureFractions = true;
    pl.step(s);
    ASSERT_EQ(pl.detail().width(), kW);
    EXPECT_EQ(pl.detailLevel(), 0);
    double e = 0;
    for (size_t i = 0; i < pl.detail().size(); ++i) e += std::fabs(pl.detail().data()[i]);
    EXPECT_GT(e / double(pl.detail().size()), 1e-4);  // d_0 = c_0 - c_1 holds the finest noise
    const Image& f = pl.sureFractions();
    ASSERT_EQ(f.channels(), s.denoise.eaw.levels);
    for (size_t i = 0; i < f.size(); ++i) {
        ASSERT_GE(f.data()[i], 0.0f);
        ASSERT_LE(f.data()[i], 1.0f);
    }

    s.detailLevel = s.denoise.eaw.levels;  // past the last level: nothing
    s.sureFractions = false;
    pl.step(s);
    EXPECT_TRUE(pl.detail().empty());
    EXPECT_TRUE(pl.sureFractions().empty());
}

TEST(ViewPipeline, SvgfGetsMotionVectorsWhenTheCameraMoves) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    pl.step(settings(svgfMethod()));
    pl.setCamera(turned(pl, 0.1f));
    pl.step(settings(svgfMethod()));
    const Image& m = pl.motion();
    int moving = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            ASSERT_TRUE(std::isfinite(m(x, y, 0)) && std::isfinite(m(x, y, 1)));
            moving += std::fabs(m(x, y, 0)) + std::fabs(m(x, y, 1)) > 0.1f;
        }
    EXPECT_GT(moving, kW * kH / 2);
    EXPECT_TRUE(pl.slot(0).error.empty()) << pl.slot(0).error;
    pl.step(settings(svgfMethod()));  // still again: no motion
    for (size_t i = 0; i < pl.motion().size(); ++i) ASSERT_EQ(pl.motion().data()[i], 0.0f);
}

TEST(ViewPipeline, SaveBuffersWritesWhatTheStepComputed) {
    atrous::test::TempDir dir;
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    PipelineSettings s = settings(Method::of(DenoiseMethod::Eaw), 2);
    s.split = true;
    s.methodB = svgfMethod();
    s.detailLevel = 1;
    pl.step(s);
    const std::vector<std::string> names = pl.saveBuffers(dir / "out");
    for (const char* f : {"color.exr", "variance.exr", "albedo.exr", "normal.exr", "position.exr", "depth.exr", "ids.exr",
                          "motion.exr", "emission.exr", "denoised_a_eaw.exr", "denoised_b_svgf.exr", "detail_level1.exr"}) {
        EXPECT_NE(std::find(names.begin(), names.end(), f), names.end()) << f;
        EXPECT_TRUE(std::filesystem::exists(dir.path() / "out" / f)) << f;
    }
    EXPECT_EQ(atrous::test::countEntries(dir / "out"), int(names.size()));
}

TEST(OrbitCamera, StartsAtTheCameraAndTurnsAboutItsPivot) {
    const pt::Camera c = cornell().data().camera;
    OrbitCamera o = OrbitCamera::fromCamera(c, 8.0f);
    const pt::Camera back = o.camera();
    EXPECT_LT(length(back.position - c.position), 1e-4f);
    EXPECT_LT(length(back.forward - c.forward), 1e-4f);
    EXPECT_EQ(back.tanHalfFov, c.tanHalfFov);
    const Vec3 pivot = o.target;
    o.orbit(1.0f, 0.3f);
    const pt::Camera t = o.camera();
    EXPECT_NEAR(length(t.position - pivot), 8.0f, 1e-3f);  // same distance from the pivot
    EXPECT_LT(length(normalize(pivot - t.position) - t.forward), 1e-4f);  // still looking at it
    o.orbit(0.0f, 10.0f);
    EXPECT_NEAR(o.pitch, 89.0f * 3.14159265f / 180.0f, 1e-5f);  // short of the pole
    o.zoom(0.5f);
    EXPECT_NEAR(o.distance, 4.0f, 1e-5f);
    o.zoom(1e-9f);
    EXPECT_EQ(o.distance, 1e-3f);
    o.pan(o.camera(), 1.0f, 0.0f, 0.0f);
    EXPECT_NEAR(length(o.target - pivot), 1.0f, 1e-4f);
}

TEST(ViewTonemap, ViewsMapTheBuffersAndSayWhenThereIsNothingToShow) {
    ViewPipeline pl(cornell(), kW, kH, Device::Cpu, 1);
    PipelineSettings s = settings(Method::none(), 1);
    pl.step(s);
    std::vector<unsigned char> rgba(size_t(kW) * kH * 4, 7);
    auto px = [&](int x, int y, int c) { return rgba[(size_t(y) * kW + x) * 4 + c]; };
    // Variance at one sample per pixel: a note, and a grey image.
    EXPECT_NE(tonemap(pl, BufferView::Variance, nullptr, 1.0f, 0, 0, kW, rgba).find("variance"), std::string::npos);
    EXPECT_EQ(px(5, 5, 0), 24);
    EXPECT_EQ(px(5, 5, 3), 255);
    EXPECT_NE(tonemap(pl, BufferView::Result, nullptr, 1.0f, 0, 0, kW, rgba), "");
    EXPECT_NE(tonemap(pl, BufferView::Detail, nullptr, 1.0f, 0, 0, kW, rgba), "");
    // The noisy colour through sRGB: exposure 0 is black, and a brighter exposure is brighter.
    EXPECT_EQ(tonemap(pl, BufferView::Noisy, nullptr, 1e-9f, 0, 0, kW, rgba), "");
    EXPECT_EQ(px(kW / 2, kH / 2, 0), 0);
    EXPECT_EQ(tonemap(pl, BufferView::Noisy, nullptr, 1.0f, 0, 0, kW, rgba), "");
    long dim = 0;
    for (size_t i = 0; i < rgba.size(); i += 4) dim += rgba[i];
    tonemap(pl, BufferView::Noisy, nullptr, 4.0f, 0, 0, kW, rgba);
    long bright = 0;
    for (size_t i = 0; i < rgba.size(); i += 4) bright += rgba[i];
    EXPECT_GT(bright, dim);
    // Only columns [x0, x1) are written.
    std::fill(rgba.begin(), rgba.end(), 7);
    tonemap(pl, BufferView::Albedo, nullptr, 1.0f, 0, 0, kW / 2, rgba);
    EXPECT_EQ(px(kW - 1, kH / 2, 0), 7);
    EXPECT_EQ(px(0, kH / 2, 3), 255);
    // Normals map linearly: -1 -> 0, +1 -> 255 (the floor's normal is +y, the ceiling's -y).
    tonemap(pl, BufferView::Normal, nullptr, 1.0f, 0, 0, kW, rgba);
    EXPECT_GE(px(8, kH - 2, 1), 250);
    EXPECT_LE(px(kW / 2, 1, 1), 5);
    // A result image is shown with the exposure; every view fills every pixel's alpha.
    Image white(kW, kH, 3);
    for (size_t i = 0; i < white.size(); ++i) white.data()[i] = 1.0f;
    EXPECT_EQ(tonemap(pl, BufferView::Result, &white, 1.0f, 0, 0, kW, rgba), "");
    EXPECT_EQ(px(3, 3, 0), 255);
    for (int v = 0; v < kViewCount; ++v) {
        std::fill(rgba.begin(), rgba.end(), 0);
        tonemap(pl, BufferView(v), &white, 1.0f, 0, 0, kW, rgba);
        for (size_t i = 3; i < rgba.size(); i += 4) ASSERT_EQ(rgba[i], 255) << kViewFlags[v];
    }
}

TEST(ViewTonemap, BufferFlagsParseAndTheSrgbTableRoundTrips) {
    for (int v = 0; v < kViewCount; ++v) EXPECT_EQ(parseBufferView(kViewFlags[v]), BufferView(v));
    try {
        parseBufferView("normals");
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--buffer"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("sure-s"), std::string::npos);  // lists the choices
    }
    const SrgbLut& L = lut();
    EXPECT_EQ(L(std::nanf("")), 0);
    EXPECT_EQ(L(-1.0f), 0);
    EXPECT_EQ(L(2.0f), 255);
    for (int i = 0; i < 256; ++i) EXPECT_EQ(L(L.dec[i]), i) << i;  // 8-bit sRGB -> linear -> 8-bit
}

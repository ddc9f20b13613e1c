// The viewer's timings (apps/atrous/view/frame_timing.h) without a window: the per-frame stage
// list of the panel's timing table, and the JSON line of --benchmark and headless runs (its keys,
// their order, the warm-up frame left out, medians, the one-line form docs/viewer.md shows).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <string>
#include <thread>
#include <vector>

#include "atrous/device.h"
#include "atrous/render.h"
#include "atrous/svgf.h"
#include "view/frame_timing.h"
#include "view/stage_history.h"
#include "atrous/view_pipeline.h"

using atrous::Device;
using atrous::Scene;
using atrous::StageTime;
using namespace atrous::view;
using ordered_json = nlohmann::ordered_json;

namespace {

std::vector<std::string> names(const std::vector<StageTime>& v) {
    std::vector<std::string> n;
    for (const StageTime& s : v) n.push_back(s.name);
    return n;
}

FrameTiming frameOf(double ms, double cpuMs, double renderMs) {
    FrameTiming f;
    f.frameMs = ms;
    f.frameCpuMs = cpuMs;
    f.displayMs = 0.5;
    f.stages.render = renderMs;
    f.stages.denoiseA = 2.0;
    return f;
}

}  // namespace

TEST(ViewTiming, FrameStagesListThePipelineThenEachSlotThenTheDisplay) {
    ViewPipeline pl(Scene::builtin("cornell"), 24, 16, Device::Cpu, 1);
    PipelineSettings s;
    s.methodA = Method::of(atrous::DenoiseMethod::Eaw);
    s.methodB = Method::none();
    s.split = true;
    s.maxDepth = 2;
    pl.step(s);
    const std::vector<StageTime> v = frameStages(pl, true, 1.5);
    std::vector<std::string> expected = {"render", "accumulate", "motion"};
    double inStages = 0;
    for (const StageTime& t : pl.slot(0).stages) {
        expected.push_back("A " + t.name);
        inStages += t.milliseconds;
    }
    ASSERT_GT(expected.size(), 4u);  // EAW reports its stages
    expected.insert(expected.end(), {"A other", "B none", "debug views", "display"});
    EXPECT_EQ(names(v), expected);
    EXPECT_EQ(v[0].milliseconds, pl.times().render);
    EXPECT_EQ(v[3].name, "A " + pl.slot(0).stages[0].name);
    EXPECT_EQ(v[3].milliseconds, pl.slot(0).stages[0].milliseconds);
    const size_t other = expected.size() - 4;
    EXPECT_DOUBLE_EQ(v[other].milliseconds, std::max(0.0, pl.times().denoiseA - inStages));  // the rest of the slot
    EXPECT_EQ(v[other + 1].milliseconds, pl.times().denoiseB);  // no stages: all of it
    EXPECT_EQ(v.back().milliseconds, 1.5);
    // Without the split, slot B is not listed.
    const std::vector<std::string> one = names(frameStages(pl, false, 1.5));
    EXPECT_EQ(std::count_if(one.begin(), one.end(), [](const std::string& n) { return n[0] == 'B'; }), 0);
    EXPECT_EQ(one.size(), expected.size() - 1);
}

TEST(ViewTiming, JsonLineHasTheKeysInOrderAndLeavesTheWarmupOut) {
    BenchmarkRun run;
    run.scene = "box \"2\"";
    run.width = 64;
    run.height = 48;
    run.settings.methodA = Method::of(atrous::DenoiseMethod::Sure);
    run.settings.methodB = Method::of(*atrous::findSequenceMethod(atrous::kSvgfMethod));
    run.settings.split = true;
    run.settings.sppPerFrame = 2;
    run.display = "host upload";
    // The first frame is the warm-up: its 1000 ms must not reach any figure.
    const std::vector<FrameTiming> frames = {frameOf(1000, 1000, 1000), frameOf(10, 16, 4), frameOf(30, 24, 6),
                                             frameOf(20, 20, 1.23456789)};
    StageHistory stages(100);
    stages.add({{"render", 4}, {"A level 0", 1}});
    stages.add({{"render", 6}, {"A level 0", 3}});
    const std::string line = benchmarkJson(run, frames, stages);
    EXPECT_EQ(line.find('\n'), std::string::npos);
    EXPECT_EQ(line.rfind("{\"benchmark\": \"view\", \"scene\": \"box \\\"2\\\"\", \"width\": 64, ", 0), 0u) << line;
    EXPECT_NE(line.find("\"display\": \"host upload\""), std::string::npos) << line;  // what view_test reads
    EXPECT_NE(line.find("\"stage_ms\": {\"render\": 5.0, \"A level 0\": 2.0}}"), std::string::npos) << line;

    const ordered_json j = ordered_json::parse(line);
    std::vector<std::string> keys;
    for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
    const std::vector<std::string> expected = {
        "benchmark", "scene", "width", "height", "method", "compare", "spp_per_frame", "accumulate", "frames",
        "warmup_frames", "frame_ms_mean", "frame_ms_median", "fps", "render_ms", "accumulate_ms", "motion_ms",
        "denoise_a_ms", "denoise_b_ms", "debug_ms", "display_ms", "cpu_ms_per_frame_median", "render_cpu_ms",
        "accumulate_cpu_ms", "motion_cpu_ms", "denoise_a_cpu_ms", "denoise_b_cpu_ms", "debug_cpu_ms",
        "hardware_threads", "fps_idle_estimate", "device", "display", "stage_ms"};
    EXPECT_EQ(keys, expected);
    EXPECT_EQ(j["method"], "sure");
    EXPECT_EQ(j["compare"], "svgf");
    EXPECT_EQ(j["spp_per_frame"], 2);
    EXPECT_EQ(j["accumulate"], 1);
    EXPECT_EQ(j["frames"], 3);
    EXPECT_EQ(j["warmup_frames"], 1);
    EXPECT_DOUBLE_EQ(j["frame_ms_mean"].get<double>(), 20.0);
    EXPECT_DOUBLE_EQ(j["frame_ms_median"].get<double>(), 20.0);
    EXPECT_DOUBLE_EQ(j["fps"].get<double>(), 50.0);
    EXPECT_DOUBLE_EQ(j["render_ms"].get<double>(), 4.0);  // median of 4, 6, 1.23...
    EXPECT_DOUBLE_EQ(j["denoise_a_ms"].get<double>(), 2.0);
    EXPECT_DOUBLE_EQ(j["display_ms"].get<double>(), 0.5);
    EXPECT_DOUBLE_EQ(j["cpu_ms_per_frame_median"].get<double>(), 20.0);
    const int cores = int(std::thread::hardware_concurrency());
    EXPECT_EQ(j["hardware_threads"], cores);
    EXPECT_DOUBLE_EQ(j["fps_idle_estimate"].get<double>(), 1000.0 * std::max(1, cores) / 20.0);
    EXPECT_EQ(j["device"], atrous::deviceName(Device::Cpu));
}

TEST(ViewTiming, JsonLineOfOneFrameKeepsItAndFiguresHaveSixDigits) {
    BenchmarkRun run;
    run.scene = "cornell";
    run.display = std::string("host upload: \xff");  // not UTF-8: replaced, not thrown
    const std::string line = benchmarkJson(run, {frameOf(1.23456789, 2, 3)}, StageHistory(10));
    const ordered_json j = ordered_json::parse(line);
    EXPECT_EQ(j["frames"], 1);
    EXPECT_EQ(j["warmup_frames"], 0);
    EXPECT_EQ(j["compare"], "");  // no split
    EXPECT_NE(line.find("\"frame_ms_median\": 1.23457, "), std::string::npos) << line;
    EXPECT_NE(line.find("\"stage_ms\": {}}"), std::string::npos) << line;
}

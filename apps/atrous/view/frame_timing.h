// The viewer's timings: one record per frame, the per-stage list that feeds the panel's timing
// table (stage_history.h), and the JSON line of --benchmark and headless runs (docs/viewer.md).
#pragma once
#include <string>
#include <vector>

#include "atrous/stage_time.h"
#include "view/stage_history.h"
#include "atrous/view_pipeline.h"

namespace atrous::view {

// One frame: its wall clock and process CPU time (user + system, all threads), the pipeline's
// stages of its step (the last step's when paused) and the display update.
struct FrameTiming {
    double frameMs = 0, frameCpuMs = 0, displayMs = 0;
    StageTimes stages;
};

// One frame's stages for the timing table, in pipeline order: render, accumulate, motion, then
// each computed slot's filter stages ("A sanitize", ..., "A other"), debug views, display.
std::vector<StageTime> frameStages(const ViewPipeline& pl, bool split, double displayMs);

// What the JSON line says about the run besides its timings.
struct BenchmarkRun {
    std::string scene;
    int width = 0, height = 0;
    PipelineSettings settings;  // at the end of the run
    Device device = Device::Cpu;
    std::string display;  // FrameDisplay::path()
};

// The JSON line (one line, `{"key": value, ...}`): the run, then medians over the frames after
// the first (a warm-up, left out when there are more) of the frame and each pipeline stage, wall
// clock and CPU time, and the per-stage medians of `stages` as "stage_ms".
std::string benchmarkJson(const BenchmarkRun& run, const std::vector<FrameTiming>& frames, const StageHistory& stages);

}  // namespace atrous::view

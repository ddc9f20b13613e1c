// Frame timings and the JSON line (frame_timing.h).
#include "view/frame_timing.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "atrous/device.h"
#include "atrous/timer.h"

namespace atrous::view {
namespace {

using ordered_json = nlohmann::ordered_json;

std::string dumpScalar(const ordered_json& v) {
    return v.dump(-1, ' ', false, ordered_json::error_handler_t::replace);
}

// A figure with the six significant digits the line has always had (nlohmann prints the shortest
// exact form, up to 17 digits, which says nothing more about a timing).
double sig6(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return std::strtod(buf, nullptr);
}

// `{"key": value, ...}` on one line, as docs/viewer.md shows it (nlohmann's compact dump has no
// spaces after ':' and ',').
std::string oneLine(const ordered_json& j) {
    if (!j.is_object()) return dumpScalar(j);
    std::string s = "{";
    for (auto it = j.begin(); it != j.end(); ++it)
        s += (it == j.begin() ? "" : ", ") + dumpScalar(it.key()) + ": " + oneLine(it.value());
    return s + "}";
}

}  // namespace

std::vector<StageTime> frameStages(const ViewPipeline& pl, bool split, double displayMs) {
    const StageTimes& t = pl.times();
    std::vector<StageTime> v = {{"render", t.render}, {"accumulate", t.accumulate}, {"motion", t.motion}};
    for (int i = 0; i < (split ? 2 : 1); ++i) {
        const SlotResult& r = pl.slot(i);
        const std::string prefix = i ? "B " : "A ";
        const double slotMs = i ? t.denoiseB : t.denoiseA;
        double inStages = 0;
        for (const StageTime& s : r.stages) {
            v.push_back({prefix + s.name, s.milliseconds});
            inStages += s.milliseconds;
        }
        // Validation, noise estimation, allocations, transfers, the host copy of the result.
        v.push_back({prefix + (r.stages.empty() ? methodName(r.method) : "other"), std::max(0.0, slotMs - inStages)});
    }
    v.push_back({"debug views", t.debug});
    v.push_back({"display", displayMs});
    return v;
}

std::string benchmarkJson(const BenchmarkRun& run, const std::vector<FrameTiming>& frames, const StageHistory& stages) {
    // The first frame (BVH already built, but first allocations, ImGui font atlas upload) is a
    // warm-up and left out when there are more.
    const size_t skip = frames.size() > 1 ? 1 : 0;
    auto med = [&](auto field) {
        std::vector<double> v;
        for (size_t i = skip; i < frames.size(); ++i) v.push_back(field(frames[i]));
        return median(v);
    };
    const size_t n = frames.size() - skip;
    double mean = 0;
    for (size_t i = skip; i < frames.size(); ++i) mean += frames[i].frameMs;
    mean = n == 0 ? 0 : mean / double(n);
    const double frameMed = med([](const FrameTiming& f) { return f.frameMs; });
    const PipelineSettings& ps = run.settings;
    ordered_json j;
    j["benchmark"] = "view";
    j["scene"] = run.scene;
    j["width"] = run.width;
    j["height"] = run.height;
    j["method"] = methodName(ps.methodA);
    j["compare"] = ps.split ? methodName(ps.methodB) : "";
    j["spp_per_frame"] = ps.sppPerFrame;
    j["accumulate"] = ps.accumulate ? 1 : 0;
    j["frames"] = n;
    j["warmup_frames"] = skip;
    j["frame_ms_mean"] = sig6(mean);
    j["frame_ms_median"] = sig6(frameMed);
    j["fps"] = sig6(frameMed > 0 ? 1000.0 / frameMed : 0.0);
    // Each stage's median wall-clock and CPU milliseconds, under its JSON names.
    struct StageField {
        const char *wall, *cpu;
        double StageTimes::*wallMs, StageTimes::*cpuMs;
    };
    static const StageField kStages[] = {
        {"render_ms", "render_cpu_ms", &StageTimes::render, &StageTimes::renderCpu},
        {"accumulate_ms", "accumulate_cpu_ms", &StageTimes::accumulate, &StageTimes::accumulateCpu},
        {"motion_ms", "motion_cpu_ms", &StageTimes::motion, &StageTimes::motionCpu},
        {"denoise_a_ms", "denoise_a_cpu_ms", &StageTimes::denoiseA, &StageTimes::denoiseACpu},
        {"denoise_b_ms", "denoise_b_cpu_ms", &StageTimes::denoiseB, &StageTimes::denoiseBCpu},
        {"debug_ms", "debug_cpu_ms", &StageTimes::debug, &StageTimes::debugCpu},
    };
    for (const StageField& st : kStages) j[st.wall] = sig6(med([&](const FrameTiming& f) { return f.stages.*st.wallMs; }));
    j["display_ms"] = sig6(med([](const FrameTiming& f) { return f.displayMs; }));
    // CPU time (user + system, all threads) per frame: on a shared machine the wall-clock
    // figures above depend on the other tenants; frame CPU time / cores bounds the frame time
    // on an idle machine from below (exact when every stage keeps all cores busy).
    const double cpuMed = med([](const FrameTiming& f) { return f.frameCpuMs; });
    j["cpu_ms_per_frame_median"] = sig6(cpuMed);
    for (const StageField& st : kStages) j[st.cpu] = sig6(med([&](const FrameTiming& f) { return f.stages.*st.cpuMs; }));
    const int cores = int(std::thread::hardware_concurrency());
    j["hardware_threads"] = cores;
    j["fps_idle_estimate"] = sig6(cpuMed > 0 ? 1000.0 * std::max(1, cores) / cpuMed : 0.0);
    j["device"] = deviceName(run.device);
    j["display"] = run.display;
    // Per-stage medians (ms): the pipeline's stages and each slot's filter stages as the
    // library reported them ("A level 0", ...; "A other" = the slot's wall time not in a stage).
    ordered_json stageMs = ordered_json::object();
    for (size_t i = 0; i < stages.size(); ++i) stageMs[stages.name(i)] = sig6(stages.median(i));
    j["stage_ms"] = stageMs;
    return oneLine(j);
}

}  // namespace atrous::view

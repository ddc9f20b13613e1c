// Speed of the learned filter v3 (docs/learned.md, "Speed") at 512x512 and 1920x1080: the learned
// cascade alone on prepared planes (filters::runLearned on the CPU, per stage: allocate, pass A
// logs, pass B network, the 5 levels), and the whole atrous::denoise with the learned method on
// --device (the driver's stages included, per stage from DenoiseReport). Prints JSON: medians (and
// minima) over >= 20 runs after 3 warm-up runs, the device name and thread count.
// Usage: bench_learned [--runs N] [--device cpu|cuda] [--size WxH] [--threads N] [--only cascade|denoise]
//                      [--weights FILE]
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/learned.h"
#include "bench_cli.h"
#include "bench_scene.h"
#include "core/parallel.h"
#include "atrous/timer.h"
#include "filters/learned.h"

using namespace atrous;

namespace {


double minOf(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

}  // namespace

int main(int argc, char** argv) {
    int runs = 20, threads = 0;
    std::vector<std::pair<int, int>> sizes = {{512, 512}, {1920, 1080}};
    std::string deviceText = "cpu", weightsPath, only;
    CLI::App app{"Speed of the learned filter (cascade alone on the CPU, and denoise() with the learned method) at "
                 "512x512 and 1920x1080; prints JSON",
                 "bench_learned"};
    app.add_option("--runs", runs, "timed runs after warm-up; fewer than 20 are raised to 20")
        ->check(CLI::Range(1, 100000))->capture_default_str();
    app.add_option("--device", deviceText, "device of the denoise() runs: cpu | cuda")
        ->check(CLI::IsMember({"cpu", "cuda"}))->capture_default_str();
    atrous::bench::addSizeOption(app, sizes);
    app.add_option("--threads", threads, "TBB threads (0 = all cores)")->check(CLI::Range(0, 4096))->capture_default_str();
    app.add_option("--only", only, "time only the cascade or only denoise()")->check(CLI::IsMember({"cascade", "denoise"}));
    app.add_option("--weights", weightsPath, "weight file (version 4, or 3; default: the built-in weights)");
    if (int rc = atrous::bench::parseArgs(app, argc, argv); rc >= 0) return rc;
    runs = std::max(20, runs);
    Device device = Device::Cpu;
    LearnedWeights weights;
    try {
        device = parseDevice(deviceText);
        weights = weightsPath.empty() ? LearnedWeights::builtin() : LearnedWeights::load(weightsPath);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_learned: error: %s\n", e.what());
        return 2;
    }
    const int concurrency = threads > 0 ? threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(concurrency));
    std::printf("{\n  \"benchmark\": \"learned\",\n  \"cascade_device\": \"%s\",\n  \"denoise_device\": \"%s\",\n"
                "  \"threads\": %d,\n  \"runs\": %d,\n  \"weights\": \"%s\",\n  \"results\": [\n",
                deviceName(Device::Cpu).c_str(), deviceName(device).c_str(), concurrency, runs,
                weightsPath.empty() ? "built-in" : weightsPath.c_str());
    bool first = true;
    for (auto [w, h] : sizes) {
        const bench::BoxScene s(w, h, true);
        // The cascade alone, on the scene's colour as d (the driver's preparation is timed below).
        Image out(w, h, 3);
        const PreparedView P = filters::preparedView(s.color.view(), s.variance.view(), s.albedo.view(), s.normal.view(),
                                       s.depth.view());
        if (only != "denoise") {
        std::vector<double> total, alloc, ctx, logs, net, levels, cpuCtx, cpuLogs, cpuNet, cpuLevels;
        for (int i = 0; i < 3 + runs; ++i) {
            filters::LearnedStageTimes t;
            Timer timer;
            filters::runLearned(CpuExec{}, weights, P, out.view(), &t);
            if (i < 3) continue;
            total.push_back(timer.ms());
            alloc.push_back(t.allocate * 1e3), logs.push_back(t.logs * 1e3), net.push_back(t.network * 1e3);
            levels.push_back(t.levels * 1e3), ctx.push_back(t.context * 1e3), cpuCtx.push_back(t.cpuContext * 1e3);
            cpuLogs.push_back(t.cpuLogs * 1e3), cpuNet.push_back(t.cpuNetwork * 1e3), cpuLevels.push_back(t.cpuLevels * 1e3);
        }
        std::printf("%s    {\"what\": \"cascade\", \"device\": \"%s\", \"width\": %d, \"height\": %d, \"median_ms\": %.3f, "
                    "\"min_ms\": %.3f, \"stage_median_ms\": {\"allocate\": %.3f, \"context\": %.3f, \"logs\": %.3f, "
                    "\"network\": %.3f, \"levels\": %.3f}, \"stage_min_ms\": {\"allocate\": %.3f, \"context\": %.3f, "
                    "\"logs\": %.3f, \"network\": %.3f, \"levels\": %.3f}, \"stage_cpu_median_ms\": {\"context\": %.3f, "
                    "\"logs\": %.3f, \"network\": %.3f, \"levels\": %.3f}}",
                    first ? "" : ",\n", deviceName(Device::Cpu).c_str(), w, h, median(total), minOf(total),
                    median(alloc), median(ctx), median(logs), median(net), median(levels), minOf(alloc), minOf(ctx),
                    minOf(logs), minOf(net), minOf(levels), median(cpuCtx), median(cpuLogs), median(cpuNet),
                    median(cpuLevels));
        first = false;
        }
        if (only == "cascade") continue;
        // The whole denoise() with the learned method.
        DenoiseOptions o;
        o.method = DenoiseMethod::Learned;
        o.device = device;
        if (!weightsPath.empty()) o.weights = LearnedWeights::load(weightsPath);  // once, not timed
        DenoiseReport rep;
        std::vector<double> whole;
        std::vector<std::string> names;
        std::vector<std::vector<double>> stageMs;
        for (int i = 0; i < 3 + runs; ++i) {
            Timer timer;
            rep = denoiseWithReport(s.learnedInputs(), o).report;
            if (i < 3) continue;
            whole.push_back(timer.ms());
            if (names.empty())
                for (const StageTime& st : rep.stages) names.push_back(st.name);
            stageMs.resize(names.size());
            for (size_t k = 0; k < rep.stages.size() && k < names.size(); ++k)
                stageMs[k].push_back(rep.stages[k].milliseconds);
        }
        std::printf("%s    {\"what\": \"denoise\", \"device\": \"%s\", \"width\": %d, \"height\": %d, \"median_ms\": %.3f, "
                    "\"min_ms\": %.3f, \"stage_median_ms\": {",
                    first ? "" : ",\n", deviceName(device).c_str(), w, h, median(whole), minOf(whole));
        first = false;
        for (size_t k = 0; k < names.size(); ++k)
            std::printf("%s\"%s\": %.3f", k ? ", " : "", names[k].c_str(), median(stageMs[k]));
        std::printf("}}");
    }
    std::printf("\n  ],\n  \"note\": \"cascade: filters::runLearned on the CPU on prepared planes (allocate: the "
                "temporaries; logs: pass A; network: pass B, inputs + MLP + outputs; levels: the 5 levels; stage_cpu: process CPU time, all threads); denoise: "
                "atrous::denoise(method learned) wall time incl. the driver's stages (DenoiseReport::stages)\"\n}\n");
    return 0;
}

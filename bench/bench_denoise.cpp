// Speed of EAW and SURE-À-Trous (5 levels, all feature buffers, firefly pass and demodulation on:
// the defaults) at 512×512 and 1920×1080. Prints JSON: median and min over >= 20 runs after
// warm-up, the device name and thread count.
// Usage: bench_denoise [--runs N] [--device cpu|cuda] [--size WxH] [--method eaw|sure] [--threads N]
// (--size and --method: time only that size / method; default both sizes and both methods; --threads: limit TBB,
// e.g. 1 to measure the work alone on a loaded machine)
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "atrous/denoise.h"
#include "bench_cli.h"
#include "bench_scene.h"
#include "atrous/timer.h"

using namespace atrous;

namespace {

// Process CPU time (user + system, all threads) in ms: on a shared machine wall time depends on
// the other load, CPU time much less.
double cpuMs() {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    return (ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) * 1e3 + (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) * 1e-3;
}


}  // namespace

int main(int argc, char** argv) {
    int runs = 30;
    Device device = Device::Cpu;
    std::vector<std::pair<int, int>> sizes = {{512, 512}, {1920, 1080}};
    std::vector<DenoiseMethod> methods = {DenoiseMethod::Eaw, DenoiseMethod::Sure};
    int threads = 0;  // 0: TBB's default
    std::string deviceText = "cpu", methodText;
    CLI::App app{"Speed of EAW and SURE-A-Trous (defaults: 5 levels, all buffers) at 512x512 and 1920x1080; prints JSON",
                 "bench_denoise"};
    app.add_option("--runs", runs, "timed runs after warm-up; fewer than 20 are raised to 20")
        ->check(CLI::Range(1, 100000))->capture_default_str();
    app.add_option("--device", deviceText, "cpu | cuda")->check(CLI::IsMember({"cpu", "cuda"}))->capture_default_str();
    atrous::bench::addSizeOption(app, sizes);
    app.add_option("--method", methodText, "time only this method")->check(CLI::IsMember({"eaw", "sure"}));
    app.add_option("--threads", threads, "TBB threads (0 = all cores; 1 measures the work alone on a loaded machine)")
        ->check(CLI::Range(0, 4096))->capture_default_str();
    if (int rc = atrous::bench::parseArgs(app, argc, argv); rc >= 0) return rc;
    runs = std::max(20, runs);
    try {
        device = parseDevice(deviceText);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_denoise: error: --device: %s\n", e.what());
        return 2;
    }
    if (!methodText.empty()) methods = {parseDenoiseMethod(methodText)};
    const int concurrency = threads > 0 ? threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(concurrency));
    std::printf("{\n  \"benchmark\": \"denoise\",\n  \"device\": \"%s\",\n  \"threads\": %d,\n  \"runs\": %d,\n  \"results\": [\n",
                deviceName(device).c_str(), concurrency, runs);
    bool first = true;
    for (auto& sz : sizes) {
        const bench::BoxScene b(sz.first, sz.second, false);
        for (DenoiseMethod m : methods) {
            DenoiseOptions o;
            o.method = m;
            o.device = device;
            DenoiseReport rep;
            for (int i = 0; i < 3; ++i) denoise(b.allInputs(), o);  // warm-up
            std::vector<double> filterMs, totalMs;
            std::vector<std::string> stageNames;
            std::vector<std::vector<double>> stageMs;  // [stage][run]
            const double cpu0 = cpuMs();
            for (int i = 0; i < runs; ++i) {
                Timer t;
                rep = denoiseWithReport(b.allInputs(), o).report;  // the image is freed before t.ms()
                totalMs.push_back(t.ms());
                filterMs.push_back(rep.milliseconds);
                if (i == 0)
                    for (const StageTime& st : rep.stages) stageNames.push_back(st.name);
                stageMs.resize(stageNames.size());
                for (size_t k = 0; k < rep.stages.size() && k < stageNames.size(); ++k)
                    stageMs[k].push_back(rep.stages[k].milliseconds);
            }
            const double cpuPerCall = (cpuMs() - cpu0) / runs;
            std::printf("%s    {\"method\": \"%s\", \"width\": %d, \"height\": %d, \"levels\": 5, \"median_ms\": %.3f, "
                        "\"min_ms\": %.3f, \"median_total_ms\": %.3f, \"cpu_ms_per_call\": %.3f, \"stage_median_ms\": {",
                        first ? "" : ",\n", denoiseMethodName(m), sz.first, sz.second, median(filterMs),
                        *std::min_element(filterMs.begin(), filterMs.end()), median(totalMs), cpuPerCall);
            for (size_t k = 0; k < stageNames.size(); ++k)
                std::printf("%s\"%s\": %.3f", k ? ", " : "", stageNames[k].c_str(), median(stageMs[k]));
            std::printf("}}");
            first = false;
        }
    }
    std::printf("\n  ],\n  \"note\": \"median_ms: the filter (firefly pass, demodulation, 5 levels, recombination); "
                "median_total_ms adds input validation and the report; cpu_ms_per_call: process CPU time (all threads, "
                "getrusage) per whole denoise() call, mean over the runs; stage_median_ms: per stage of the filter (DenoiseReport::stages)\"\n}\n");
    return 0;
}

// SVGF benchmark: the whole per-frame pipeline (demodulate, G-buffer, reprojection, accumulation,
// variance, 5 à-trous levels, remodulation) on a synthetic 1-spp-like animated sequence, at
// 512x512 and 1920x1080. Inputs are prepared on the device beforehand and the result stays there,
// so the figure is the filter alone. Prints JSON: median (and min) milliseconds per frame over
// many frames after a warm-up long enough for the histories to fill, and the median process CPU
// time per frame (all threads together; robust to other load on a shared machine).
//
// With --stages also the median per-stage milliseconds (SvgfReport::stages; the timing itself
// costs ~1 µs per frame). --avx2 runs the CPU à-trous fast path's AVX2 loops where the CPU has
// AVX-512 (to compare the two); --generic the per-pixel functor instead of the fast path.
//
//   build/bench/bench_svgf [--device cpu|cuda] [--runs N] [--warmup N] [--taa] [--stages] [--avx2] [--generic]
//   (--help: the usage; a bad flag or value exits 2 before any timing)
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "atrous/device.h"
#include "atrous/error.h"
#include "atrous/svgf.h"
#include "atrous/timer.h"
#include "filters/svgf_atrous.h"
#include "bench_cli.h"

using namespace atrous;

namespace {

struct BenchFrame {
    Image color, albedo, normal, depth, ids, motion;
};

// A textured ground plane receding in depth under a camera that pans 1.5 px per frame, a sky strip,
// and a box moving the other way: every stage (bilinear reprojection, disocclusion, edges) works.
BenchFrame makeFrame(int w, int h, int t, Device device) {
    BenchFrame f{Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image(w, h, 3)};
    std::mt19937 rng(1234u + unsigned(t));
    std::exponential_distribution<float> spp1(1.0f);  // 1-spp-like: heavy-tailed, mean 1
    const float pan = 1.5f * float(t);
    const int bx = w / 3 - 2 * t, by = h / 3, bs = h / 4;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool sky = y < h / 8;
            bool box = x >= bx && x < bx + bs && y >= by && y < by + bs;
            float u = float(x) + pan;
            float a = box ? 0.6f : (((int(u) / 16 + y / 16) % 2) ? 0.8f : 0.3f);
            float e = sky ? 2.0f : (box ? 1.5f : 1.0f + 0.5f * std::sin(u / 40.0f));
            float z = sky ? 1e30f : (box ? 2.0f : 3.0f + 10.0f * float(y) / float(h));
            float noise = spp1(rng);
            for (int c = 0; c < 3; ++c) {
                f.albedo(x, y, c) = sky ? 1.0f : a;
                f.color(x, y, c) = (sky ? 1.0f : a) * e * noise;
                f.depth(x, y, c) = z;
                f.ids(x, y, c) = sky ? -1.0f : (box ? 1.0f : 0.0f);
            }
            f.normal(x, y, 0) = 0.0f;
            f.normal(x, y, 1) = sky ? 0.0f : (box ? 0.0f : 0.8f);
            f.normal(x, y, 2) = sky ? 0.0f : (box ? 1.0f : 0.6f);
            f.motion(x, y, 0) = box ? 2.0f : 1.5f;  // previous - current
        }
    if (device != Device::Cpu)
        f = BenchFrame{f.color.to(device), f.albedo.to(device), f.normal.to(device), f.depth.to(device), f.ids.to(device),
                  f.motion.to(device)};
    return f;
}

// CPU time of the whole process (all threads), in ms: on a shared machine this is far less
// disturbed by other processes than the wall clock, and wall ≈ cpu / threads when the machine is idle.
double processCpuMs() {
    timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

}  // namespace

int main(int argc, char** argv) {
    int runs = 15, warmup = 6;
    std::string deviceName_ = "cpu";
    bool taa = false, stages = false, avx2 = false, generic = false;
    CLI::App app{"Speed of the whole SVGF pipeline per frame at 512x512 and 1920x1080; prints JSON", "bench_svgf"};
    app.add_option("--runs", runs, "timed frames after the warm-up")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    app.add_option("--warmup", warmup, "frames before timing (histories fill)")
        ->check(CLI::Range(0, 100000))
        ->capture_default_str();
    app.add_option("--device", deviceName_, "cpu | cuda")->check(CLI::IsMember({"cpu", "cuda"}))->capture_default_str();
    app.add_flag("--taa", taa, "with the TAA stage");
    app.add_flag("--stages", stages, "also the median time of each stage (SvgfReport::stages)");
    app.add_flag("--avx2", avx2, "CPU: the à-trous fast path's AVX2 loops even where the CPU has AVX-512");
    app.add_flag("--generic", generic, "CPU: the per-pixel à-trous functor instead of the fast path");
    if (int rc = atrous::bench::parseArgs(app, argc, argv); rc >= 0) return rc;
    if (avx2) svgf::svgfCpuAvx512() = false;
    if (generic) svgf::svgfCpuFastPath() = false;
    try {
        const Device device = parseDevice(deviceName_);
        SvgfParams params;
        params.taa = taa;
        nlohmann::json out;
        out["benchmark"] = "svgf";
        out["device"] = deviceName(device);
        out["backend"] = deviceToString(device);
        out["params"] = {{"levels", params.levels}, {"taa", params.taa}, {"feedbackTap", params.feedbackTap}};
        if (device == Device::Cpu)
            out["atrous_cpu"] =
                !svgf::svgfCpuFastPath() ? "generic functor" : (svgf::svgfCpuAvx512() ? "avx512" : "avx2");
        out["what"] = "whole SVGF pipeline per frame, inputs and output on the device";
        const int sizes[2][2] = {{512, 512}, {1920, 1080}};
        for (const auto& sz : sizes) {
            const int w = sz[0], h = sz[1];
            std::vector<BenchFrame> frames;
            for (int t = 0; t < 4; ++t) frames.push_back(makeFrame(w, h, t, device));
            SvgfDenoiser denoiser(params, device);
            denoiser.setTiming(stages);
            std::vector<std::string> stageOrder;
            std::map<std::string, std::vector<double>> stageMs;
            std::vector<double> ms, cpuMs;
            for (int i = 0; i < warmup + runs; ++i) {
                const BenchFrame& f = frames[i % frames.size()];
                Frame in;
                in.color = &f.color, in.albedo = &f.albedo, in.normal = &f.normal;
                in.depth = &f.depth, in.ids = &f.ids, in.motion = &f.motion;
                double cpu0 = processCpuMs();
                Timer timer;
                denoiser.denoiseFrameOnDevice(in);  // synchronises before returning
                if (i >= warmup) {
                    ms.push_back(timer.ms());
                    cpuMs.push_back(processCpuMs() - cpu0);
                    for (const StageTime& st : denoiser.lastReport().stages) {
                        if (!stageMs.count(st.name)) stageOrder.push_back(st.name);
                        stageMs[st.name].push_back(st.milliseconds);
                    }
                }
            }
            double mn = *std::min_element(ms.begin(), ms.end());
            nlohmann::json r = {{"width", w}, {"height", h}, {"runs", runs}, {"warmup", warmup},
                                {"ms_median", median(ms)}, {"ms_min", mn}, {"cpu_ms_median", median(cpuMs)}};
            if (stages) {
                nlohmann::json st = nlohmann::json::array();  // in the pipeline's order
                for (const std::string& name : stageOrder)
                    st.push_back({{"stage", name}, {"ms_median", median(stageMs[name])}});
                r["stages"] = st;
            }
            out["results"].push_back(r);
        }
        std::printf("%s\n", out.dump(2).c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_svgf: error: %s\n", e.what());
        return 2;
    }
    return 0;
}

// `atrous bench`: timings of every render and denoise path at several resolutions, as JSON.
// Each figure is the median of --runs timed runs after --warmup untimed ones. Denoiser times are
// the filter alone (inputs already in place; on CUDA the driver ends with a stream synchronise, so
// the time covers every kernel); `total_ms` adds validation and, on CUDA, the host<->device copies
// of the public denoise() call.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/render.h"
#include "atrous/svgf.h"
#include "commands.h"
#include "core/timer.h"

namespace atrous::cli {
namespace {

struct BenchArgs {
    std::string device = "auto";
    std::string sizes = "512x512,1280x720,1920x1080,3840x2160";
    std::string what = "eaw,sure,svgf,render";
    std::string scene = "cornell";
    int runs = 0;  // 0: 50 on CUDA, 10 on the CPU
    int warmup = 3;
    bool json = false;
};

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ','))
        if (!item.empty()) out.push_back(item);
    return out;
}

std::pair<int, int> parseSize(const std::string& s) {
    int w = 0, h = 0;
    char x = 0;
    std::stringstream ss(s);
    if (!(ss >> w >> x >> h) || x != 'x' || w <= 0 || h <= 0 || w > kMaxImageDim || h > kMaxImageDim)
        throw InputError("--sizes: '" + s + "' is not a size like 1920x1080");
    return {w, h};
}

template <class F>
std::vector<double> repeat(int warmup, int runs, F&& f) {
    for (int i = 0; i < warmup; ++i) f();
    std::vector<double> t;
    for (int i = 0; i < runs; ++i) t.push_back(f());
    return t;
}

// Per-stage times of the timed runs (DenoiseReport / SvgfReport stages), reported as medians in the
// filter's own stage order (a JSON array: an object would sort the names).
struct StageSamples {
    std::vector<std::string> names;
    std::vector<std::vector<double>> ms;
    void add(const std::vector<StageTime>& stages) {
        for (const StageTime& s : stages) {
            const size_t i = size_t(std::find(names.begin(), names.end(), s.name) - names.begin());
            if (i == names.size()) {
                names.push_back(s.name);
                ms.emplace_back();
            }
            ms[i].push_back(s.milliseconds);
        }
    }
    nlohmann::json json() const {
        nlohmann::json a = nlohmann::json::array();
        for (size_t i = 0; i < names.size(); ++i) a.push_back({{"stage", names[i]}, {"median_ms", median(ms[i])}});
        return a;
    }
};

nlohmann::json stats(const std::vector<double>& ms) {
    std::vector<double> s = ms;
    std::sort(s.begin(), s.end());
    return {{"median_ms", median(ms)}, {"min_ms", s.front()}, {"max_ms", s.back()}, {"runs", int(ms.size())}};
}

void run(const BenchArgs& a) {
    const Device device = parseDevice(a.device);
    const int runs = a.runs > 0 ? a.runs : (device == Device::Cuda ? 50 : 10);
    if (a.warmup < 0) throw InputError("--warmup must be >= 0");
    std::vector<std::string> what = split(a.what);
    for (auto& w : what)
        if (w != "eaw" && w != "sure" && w != "svgf" && w != "render")
            throw InputError("--what: unknown item '" + w + "' (expected eaw, sure, svgf, render)");
    auto wants = [&](const char* k) { return std::find(what.begin(), what.end(), k) != what.end(); };
    std::vector<std::pair<int, int>> sizes;
    for (auto& s : split(a.sizes)) sizes.push_back(parseSize(s));
    if (sizes.empty()) throw InputError("--sizes: no size given");
    Scene scene = Scene::loadByNameOrFile(a.scene);

    nlohmann::json doc;
    doc["device"] = deviceToString(device);
    doc["device_name"] = deviceName(device);
    doc["scene"] = a.scene;
    doc["warmup"] = a.warmup;
    doc["results"] = nlohmann::json::array();
    for (auto [w, h] : sizes) {
        // Inputs: the scene at 2 spp (the filters' cost does not depend on the noise level).
        RenderSettings rs;
        rs.width = w;
        rs.height = h;
        rs.spp = 2;
        rs.seed = 7;
        RenderBuffers b = render(scene, rs);
        if (wants("render")) {
            // The CPU path tracer (the GPU one is timed by bench/bench_render on CUDA builds).
            RenderSettings one = rs;
            one.spp = 1;
            auto t = repeat(1, std::max(3, runs / 10), [&] {
                Timer tt;
                render(scene, one);
                return tt.ms();
            });
            nlohmann::json r = stats(t);
            r["what"] = "render";
            r["device"] = "cpu";
            r["width"] = w;
            r["height"] = h;
            r["spp"] = 1;
            r["msamples_per_s"] = double(w) * h / (median(t) * 1e3);
            doc["results"].push_back(r);
        }
        for (const char* m : {"eaw", "sure"}) {
            if (!wants(m)) continue;
            DenoiseInputs in = denoiseInputsOf(b);
            DenoiseReport rep;
            DenoiseOptions o;
            o.method = parseDenoiseMethod(m);
            o.device = device;
            o.report = &rep;
            std::vector<double> total;
            StageSamples stages;
            int call = 0;
            auto t = repeat(a.warmup, runs, [&] {
                Timer tt;
                denoise(in, o);
                total.push_back(tt.ms());
                if (call++ >= a.warmup) stages.add(rep.stages);
                return rep.milliseconds;
            });
            total.erase(total.begin(), total.begin() + a.warmup);
            nlohmann::json r = stats(t);
            r["what"] = m;
            r["device"] = deviceToString(device);
            r["width"] = w;
            r["height"] = h;
            r["levels"] = o.eaw.levels;
            r["total_ms"] = median(total);
            r["mpixels_per_s"] = double(w) * h / (median(t) * 1e3);
            r["stages"] = stages.json();
            doc["results"].push_back(r);
        }
        if (wants("svgf")) {
            SvgfDenoiser sv(SvgfParams{}, device);
            Image motion(w, h, 2);
            SvgfFrame f;
            f.color = &b.color;
            f.albedo = &b.albedo;
            f.normal = &b.normal;
            f.depth = &b.depth;
            f.ids = &b.ids;
            f.motion = &motion;
            SvgfReport srep;
            sv.setReport(&srep);
            StageSamples stages;
            int call = 0;
            auto t = repeat(a.warmup, runs, [&] {
                Timer tt;
                sv.denoiseFrameOnDevice(f);
                const double ms = tt.ms();
                if (call++ >= a.warmup) stages.add(srep.stages);
                return ms;
            });
            nlohmann::json r = stats(t);
            r["what"] = "svgf";
            r["device"] = deviceToString(device);
            r["width"] = w;
            r["height"] = h;
            r["note"] = "whole SVGF frame; host inputs are uploaded inside the timed call on CUDA";
            r["stages"] = stages.json();
            doc["results"].push_back(r);
        }
    }
    if (a.json) {
        std::printf("%s\n", doc.dump(2).c_str());
        return;
    }
    std::printf("atrous bench on %s (%s), median of %d runs after %d warm-up\n", deviceToString(device),
                doc["device_name"].get<std::string>().c_str(), runs, a.warmup);
    for (auto& r : doc["results"]) {
        std::printf("  %-6s %5dx%-5d %10.3f ms", r["what"].get<std::string>().c_str(), r["width"].get<int>(),
                    r["height"].get<int>(), r["median_ms"].get<double>());
        if (r.contains("msamples_per_s")) std::printf("  (%.2f M samples/s)", r["msamples_per_s"].get<double>());
        std::printf("\n");
    }
}

}  // namespace

void addBenchCommand(CLI::App& app) {
    auto args = std::make_shared<BenchArgs>();
    auto* cmd = app.add_subcommand("bench", "Time every render and denoise path at several resolutions");
    cmd->add_option("--device", args->device, "cpu, cuda or auto (cuda when a GPU is present)")->capture_default_str();
    cmd->add_option("--sizes", args->sizes, "comma-separated WxH list")->capture_default_str();
    cmd->add_option("--what", args->what, "comma-separated: eaw, sure, svgf, render")->capture_default_str();
    cmd->add_option("--scene", args->scene, "scene whose buffers are denoised")->capture_default_str();
    cmd->add_option("--runs", args->runs, "timed runs per figure (0: 50 on CUDA, 10 on the CPU)");
    cmd->add_option("--warmup", args->warmup, "untimed runs first")->capture_default_str();
    cmd->add_flag("--json", args->json, "print JSON");
    cmd->callback([args] { run(*args); });
}

}  // namespace atrous::cli

// `atrous bench`: timings of every render and denoise path (the still methods, the sequence methods)
// at several resolutions, as JSON.
// Each figure is the median of --runs timed runs after --warmup untimed ones. Denoiser times are
// the filter alone (inputs already in place; on CUDA the driver ends with a stream synchronise, so
// the time covers every kernel); `total_ms` is the whole public denoise() call (validation, the
// noise estimate when there is no variance, the report). On CUDA the inputs are uploaded once
// before timing, and each EAW/SURE row adds the modelled compulsory DRAM traffic, the bandwidth
// it achieves and the GPU's peak.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/learned.h"
#include "atrous/render.h"
#include "atrous/sequence_methods.h"
#include "cli_flags.h"
#include "commands.h"
#include "atrous/timer.h"

namespace atrous::cli {
namespace {

// The built-in still methods but auto, the built-in causal sequence methods (a frame as it comes:
// svgf) and the renderer.
std::string defaultWhat() {
    std::string s;
    for (const DenoiseMethodInfo& m : denoiseMethods())
        if (!m.registered() && m.method != DenoiseMethod::Auto) s += std::string(m.name) + ",";
    for (const SequenceMethodInfo& m : sequenceMethods())
        if (!m.registered && m.causal) s += std::string(m.name) + ",";
    return s + "render";
}

// What --what takes: every still method but auto, every sequence method, render.
std::string whatItems() {
    std::string s;
    for (const DenoiseMethodInfo& m : denoiseMethods())
        if (m.method != DenoiseMethod::Auto) s += std::string(m.name) + ", ";
    for (const SequenceMethodInfo& m : sequenceMethods()) s += std::string(m.name) + ", ";
    return s + "render";
}

struct BenchArgs {
    std::string device = "auto";
    std::string sizes = "512x512,1280x720,1920x1080,3840x2160";
    std::string what = defaultWhat();
    std::string learnedWeights;  // "" = the built-in weights
    std::string scene = "cornell";
    int runs = 0;  // 0: 50 on CUDA, 10 on the CPU
    int warmup = 3;
    int threads = 0;  // --threads: 0 = all cores
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

// Compulsory DRAM traffic of one CUDA EAW/SURE call, in bytes: each pass of the driver
// (src/filters/still_pipeline.h, CudaExec) is counted as reading every plane it uses once and
// writing every plane it produces once; the 25 taps of a level are assumed to hit in cache (they
// reach ±2·step rows: at step 16, 65 rows × 1920 px × 60 B ≈ 7.5 MB, well under an H100's 50 MB
// L2). This is the floor of the
// present pass structure, not of the method: fusing the pre-passes and storing the features in
// half precision lower it (docs/benchmarks.md, "CUDA: bandwidth floor"). Keep it in step with
// the driver when passes change.
double cudaDenoiseTrafficBytes(const DenoiseOptions& o, const Frame& in, int w, int h) {
    const bool sure = o.method == DenoiseMethod::Sure;
    auto has = [](const Image* i) { return i != nullptr; };
    double planes = 12;  // SanitizeColor: colour + variance in, c_0 + v_0 out
    // sanitizedFeature copies each feature (read + write) on the GPU.
    planes += 2 * (3 * has(in.normal) + 3 * has(in.position) + 1 * has(in.depth) + 2 * has(in.ids));
    if (has(in.emission)) {
        planes += 6 + 9;                        // copy; SubtractEmission reads e, updates c_0
        planes += 9 * o.eaw.emissionLevels;     // EmissionLevel: e and variance in, e out
    }
    if (o.firefly.enabled) planes += 13;        // c, v in; c, v, flag out
    planes += 6;                                // Copy3 of c_0 for the report
    const bool demod = o.demodulate && has(in.albedo);
    if (demod) planes += 6 + 15;                // albedo copy; Demodulate: albedo in, c, v updated
    planes += 4 + 6;                            // ColorScale (v -> S); Footprint (x, z -> 1/σ_x, 1/σ_z)
    const int levels = o.eaw.levels;
    for (int i = 0; i < levels; ++i) {
        planes += 18;                           // EawLevel: c, S, n, x, 1/σ_x, z, 1/σ_z, ids in; c out
        if (sure) {
            planes += 8;                        // v in, v out, detail (D, V) out
            if (i >= o.sure.firstLevel) planes += 4 + 14;  // SureBoxH; SureChoose (box, c_i, c_i+1, acc)
        }
    }
    planes += 3 + 3 * sure + 3 * demod + 3 * has(in.emission) + 3;  // Recombine
    return planes * 4.0 * double(w) * double(h);
}

// A sequence method on the scene's buffers as a stream of still frames (zero motion): each timed
// run pushes one frame and takes out what is ready (a method with a window of later frames fills
// it during the warm-up). The time is its frame's filter, the output left on the device.
nlohmann::json benchSequence(const SequenceMethodInfo& m, const RenderBuffers& inputs, Device device,
                             const LearnedWeights& weights, const BenchArgs& a, int runs, int w, int h) {
    SequenceSetup setup;
    setup.device = device;
    setup.still.weights = weights;
    setup.timing = true;
    setup.keepOnDevice = true;
    std::unique_ptr<SequenceDenoiser> den = makeSequenceDenoiser(m.name, setup);
    Image motion(w, h, 2);
    const Image motionIn = device == Device::Cuda ? motion.to(Device::Cuda) : Image();
    Frame f;
    f.color = &inputs.color;
    f.albedo = &inputs.albedo;
    f.normal = &inputs.normal;
    f.depth = &inputs.depth;
    f.ids = &inputs.ids;
    f.motion = device == Device::Cuda ? &motionIn : &motion;
    StageSamples stages;
    int call = 0;
    auto t = repeat(a.warmup + den->lookahead(), runs, [&] {
        Timer tt;
        den->push({f, nullptr});  // the buffers outlive the denoiser
        double ms = 0;
        while (den->ready()) {
            const SequenceOutput out = den->next();
            ms = tt.ms();
            if (call >= a.warmup + den->lookahead()) stages.add(out.stages);
        }
        ++call;
        return ms;
    });
    nlohmann::json r = stats(t);
    r["what"] = m.name;
    r["device"] = deviceToString(device);
    r["width"] = w;
    r["height"] = h;
    r["note"] = std::string("whole ") + m.label + " frame (inputs already on the device)";
    r["stages"] = stages.json();
    return r;
}

void run(const BenchArgs& a) {
    const auto threadLimit = limitThreads(a.threads);  // for the whole run
    const Device device = parseDevice(a.device);
    const int runs = a.runs > 0 ? a.runs : (device == Device::Cuda ? 50 : 10);
    if (a.warmup < 0) throw InputError("--warmup must be >= 0");
    std::vector<std::string> what = split(a.what);
    for (auto& w : what)
        if ((!findDenoiseMethod(w) || findDenoiseMethod(w)->kind == CascadeKind::Auto) && !findSequenceMethod(w) && w != "render")
            throw InputError("--what: unknown item '" + w + "' (expected a denoise method but auto (" + denoiseMethodNames() +
                             "), a sequence method (" + sequenceMethodNames() + ") or render)");
    auto wants = [&](const char* k) { return std::find(what.begin(), what.end(), k) != what.end(); };
    bool anyLearned = false;
    for (const DenoiseMethodInfo& m : denoiseMethods()) anyLearned = anyLearned || (readsWeights(m) && wants(m.name));
    LearnedWeights weights;  // loaded once, before any timing (empty: the built-in weights)
    if (anyLearned && !a.learnedWeights.empty()) {
        try {
            weights = LearnedWeights::load(a.learnedWeights);  // a bad file: one line
        } catch (const InputError& e) {
            throw InputError(std::string("--learned-weights: ") + e.what());
        }
    }
    std::vector<std::pair<int, int>> sizes;
    for (auto& s : split(a.sizes)) sizes.push_back(parseSize(s));
    if (sizes.empty()) throw InputError("--sizes: no size given");
    Scene scene = Scene::loadByNameOrFile(a.scene);
    std::unique_ptr<SceneRenderer> cudaRenderer;  // made on first use (--device cuda)

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
            // The CPU path tracer (Embree); with --device cuda also the CUDA one, below.
            RenderSettings one = rs;
            one.spp = 1;
            auto t = repeat(1, std::max(3, runs / 10), [&] {
                Timer tt;
                render(scene, one);
                return tt.ms();
            });
            // One JSON row per renderer: stats of the 1-spp times and the sample rate.
            auto renderRow = [&](const std::vector<double>& times, const char* dev) {
                nlohmann::json r = stats(times);
                r["what"] = "render";
                r["device"] = dev;
                r["width"] = w;
                r["height"] = h;
                r["spp"] = 1;
                r["msamples_per_s"] = double(w) * h / (median(times) * 1e3);
                return r;
            };
            doc["results"].push_back(renderRow(t, "cpu"));
            if (device == Device::Cuda) {
                // The CUDA path tracer as the viewer runs it: one persistent renderer (scene and BVH
                // uploaded once, outside the timing), 1 spp into its device buffers, no download.
                // renderInPlace returns after the kernel has finished, so the wall clock covers it.
                if (!cudaRenderer) cudaRenderer = std::make_unique<SceneRenderer>(scene, Device::Cuda);
                auto tc = repeat(a.warmup, runs, [&] {
                    Timer tt;
                    cudaRenderer->renderInPlace(one);
                    return tt.ms();
                });
                nlohmann::json rc = renderRow(tc, "cuda");
                rc["note"] = "BVH traversal of the Embree-built BVH; buffers left on the GPU";
                doc["results"].push_back(rc);
            }
        }
        // On CUDA the inputs are uploaded once, outside the timed calls: the filters then read
        // them in place (as the viewer and DLPack callers do) and total_ms covers no transfer.
        RenderBuffers onDevice;
        bool anyFilter = false;
        for (const DenoiseMethodInfo& m : denoiseMethods()) anyFilter = anyFilter || wants(m.name);
        for (const SequenceMethodInfo& m : sequenceMethods()) anyFilter = anyFilter || wants(m.name);
        if (device == Device::Cuda && anyFilter) {
            for (auto [dst, src] : {std::pair<Image*, const Image*>{&onDevice.color, &b.color},
                                    {&onDevice.variance, &b.variance}, {&onDevice.albedo, &b.albedo},
                                    {&onDevice.normal, &b.normal}, {&onDevice.position, &b.position},
                                    {&onDevice.depth, &b.depth}, {&onDevice.ids, &b.ids},
                                    {&onDevice.emission, &b.emission}})
                *dst = src->to(Device::Cuda);
        }
        const RenderBuffers& inputs = device == Device::Cuda ? onDevice : b;
        for (const DenoiseMethodInfo& info : denoiseMethods()) {
            const char* m = info.name;
            if (info.method == DenoiseMethod::Auto || !wants(m)) continue;
            Frame in = inputs.frame();
            DenoiseOptions o;
            o.method = parseDenoiseMethod(m);
            o.weights = weights;
            const bool learned = readsWeights(info);
            o.device = device;
            std::vector<double> total;
            StageSamples stages;
            int call = 0;
            auto t = repeat(a.warmup, runs, [&] {
                Timer tt;
                const DenoiseResult res = denoiseWithReport(in, o);
                total.push_back(tt.ms());
                if (call++ >= a.warmup) stages.add(res.report.stages);
                return res.report.milliseconds;
            });
            total.erase(total.begin(), total.begin() + a.warmup);
            nlohmann::json r = stats(t);
            r["what"] = m;
            r["device"] = deviceToString(device);
            r["width"] = w;
            r["height"] = h;
            if (learned)
                r["weights"] = a.learnedWeights.empty() ? "built-in" : a.learnedWeights;
            else
                r["levels"] = o.eaw.levels;
            r["total_ms"] = median(total);
            r["mpixels_per_s"] = double(w) * h / (median(t) * 1e3);
            r["stages"] = stages.json();
            if (device == Device::Cuda && !learned) {
                // Achieved bandwidth of the compulsory traffic, against the GPU's peak.
                const double bytes = cudaDenoiseTrafficBytes(o, in, w, h);
                const double peak = cudaPeakBandwidthGBs();
                const double achieved = bytes / (median(t) * 1e-3) / 1e9;
                r["model_dram_mb"] = bytes / 1e6;
                r["achieved_gb_s"] = achieved;
                r["peak_gb_s"] = peak;
                r["fraction_of_peak"] = peak > 0 ? achieved / peak : 0.0;
                r["bandwidth_floor_ms"] = peak > 0 ? bytes / (peak * 1e9) * 1e3 : 0.0;
            }
            doc["results"].push_back(r);
        }
        for (const SequenceMethodInfo& m : sequenceMethods())
            if (wants(m.name)) doc["results"].push_back(benchSequence(m, inputs, device, weights, a, runs, w, h));
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
    cmd->add_option("--what", args->what, "comma-separated: " + whatItems())->capture_default_str();
    cmd->add_option("--learned-weights", args->learnedWeights,
                    "weight file of the learned filter (default: the built-in weights)");
    cmd->add_option("--scene", args->scene, "scene whose buffers are denoised")->capture_default_str();
    cmd->add_option("--runs", args->runs,
                    "timed runs per denoiser figure (0: 50 on CUDA, 10 on the CPU); render rows time max(3, runs/10) "
                    "renders after one warm-up")
        ->check(CLI::Range(0, 1000000));
    cmd->add_option("--warmup", args->warmup, "untimed runs first")->check(CLI::Range(0, 1000000))->capture_default_str();
    cmd->add_option("--threads", args->threads, "CPU worker threads (TBB; 0 = all cores)")->capture_default_str();
    cmd->add_flag("--json", args->json, "print JSON");
    cmd->callback([args] { run(*args); });
}

}  // namespace atrous::cli

// Path-tracing throughput of the BVH renderer: the CUDA path tracer (renderBvhCuda) next to the
// same functor on CPU threads (renderBvhCpu) and the Embree CPU renderer (atrous::render), on one
// built-in scene. Times are end to end (BVH build, uploads and downloads included), median of
// several runs after a warm-up. Prints one JSON object; "cuda" is null without a GPU.
//   bench_gpu_render [--scene cornell] [--width 512] [--height 512] [--spp 16] [--runs 5]
//                    [--max-depth 8] [--skip-cpu 1]
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "atrous/device.h"
#include "bench_cli.h"
#include "atrous/render.h"
#include "atrous/timer.h"
#include "render/bvh_render.h"

using namespace atrous;

static nlohmann::json timeIt(int runs, double samples, const std::function<void()>& f) {
    f();  // warm-up (CUDA context, page faults, thread start-up)
    std::vector<double> t;
    for (int r = 0; r < runs; ++r) {
        Timer timer;
        f();
        t.push_back(timer.seconds());
    }
    double med = median(t);
    return {{"median_s", med}, {"msamples_per_s", samples / med * 1e-6}};
}

int main(int argc, char** argv) {
    std::string sceneName = "cornell";
    RenderSettings s;
    s.width = 512;
    s.height = 512;
    s.spp = 16;
    int runs = 5;
    bool skipCpu = false;
    int skipCpuValue = 0;
    CLI::App app{"Path-tracing throughput: CUDA BVH renderer, the same functor on CPU threads, and Embree; prints JSON "
                 "(\"cuda\" is null without a GPU)",
                 "bench_gpu_render"};
    app.add_option("--scene", sceneName, "built-in scene or scene .json file")->capture_default_str();
    app.add_option("--width", s.width, "image width")->capture_default_str();
    app.add_option("--height", s.height, "image height")->capture_default_str();
    app.add_option("--spp", s.spp, "samples per pixel")->capture_default_str();
    app.add_option("--runs", runs, "timed runs after a warm-up (median kept)")->check(CLI::Range(1, 100000))->capture_default_str();
    app.add_option("--max-depth", s.maxDepth, "maximum bounces")->capture_default_str();
    app.add_option("--skip-cpu", skipCpuValue, "1: time the CUDA renderer only")->check(CLI::IsMember({0, 1}))->capture_default_str();
    if (int rc = atrous::bench::parseArgs(app, argc, argv); rc >= 0) return rc;
    skipCpu = skipCpuValue != 0;
    try {
        validateRenderSettings(s);  // bad --width/--spp/... exit 2 before the warm-up
        Scene scene = Scene::loadByNameOrFile(sceneName);
        double samples = double(s.width) * s.height * s.spp;
        nlohmann::json out;
        out["benchmark"] = "gpu_render";
        out["scene"] = sceneName;
        out["width"] = s.width;
        out["height"] = s.height;
        out["spp"] = s.spp;
        out["max_depth"] = s.maxDepth;
        out["runs"] = runs;
        out["cpu_device"] = deviceName(Device::Cpu);
        if (cudaAvailable()) {
            out["cuda_device"] = deviceName(Device::Cuda);
            out["cuda"] = timeIt(runs, samples, [&] { renderBvhCuda(scene, s); });
        } else {
            out["cuda_device"] = nullptr;
            out["cuda"] = nullptr;
        }
        if (!skipCpu) {
            out["cpu_bvh"] = timeIt(runs, samples, [&] { renderBvhCpu(scene, s); });
            out["cpu_embree"] = timeIt(runs, samples, [&] { render(scene, s); });
        }
        std::printf("%s\n", out.dump(2).c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_gpu_render: %s\n", e.what());
        return 2;
    }
    return 0;
}

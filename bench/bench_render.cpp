// Path-tracing throughput: samples per second on the CPU (Embree + TBB) for a built-in scene.
// Prints one JSON object: median over several runs after a warm-up run.
//   bench_render [--scene cornell] [--width 512] [--height 512] [--spp 4] [--runs 7] [--threads 0] [--max-depth 8]
#include <tbb/info.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "atrous/device.h"
#include "atrous/render.h"
#include "core/timer.h"

int main(int argc, char** argv) {
    std::string scene = "cornell";
    atrous::RenderSettings s;
    s.width = 512;
    s.height = 512;
    s.spp = 4;
    int runs = 7;
    for (int i = 1; i + 1 < argc; i += 2) {
        std::string k = argv[i];
        const char* v = argv[i + 1];
        if (k == "--scene") scene = v;
        else if (k == "--width") s.width = std::atoi(v);
        else if (k == "--height") s.height = std::atoi(v);
        else if (k == "--spp") s.spp = std::atoi(v);
        else if (k == "--runs") runs = std::atoi(v);
        else if (k == "--threads") s.threads = std::atoi(v);
        else if (k == "--max-depth") s.maxDepth = std::atoi(v);
        else {
            std::fprintf(stderr, "bench_render: unknown option %s\n", k.c_str());
            return 2;
        }
    }
    try {
        atrous::Scene sc = atrous::Scene::loadByNameOrFile(scene);
        atrous::render(sc, s);  // warm-up: page faults, Embree/TBB start-up
        std::vector<double> times;
        for (int r = 0; r < runs; ++r) {
            atrous::Timer t;
            atrous::RenderBuffers b = atrous::render(sc, s);
            times.push_back(t.seconds());
        }
        double med = atrous::median(times);
        double samples = double(s.width) * s.height * s.spp;
        int threads = s.threads > 0 ? s.threads : tbb::info::default_concurrency();
        std::printf("{\"benchmark\": \"render\", \"scene\": \"%s\", \"device\": \"%s\", \"threads\": %d, "
                    "\"width\": %d, \"height\": %d, \"spp\": %d, \"max_depth\": %d, \"runs\": %d, "
                    "\"median_s\": %.5f, \"min_s\": %.5f, \"samples_per_s\": %.0f, \"msamples_per_s\": %.3f}\n",
                    scene.c_str(), atrous::deviceName(atrous::Device::Cpu).c_str(), threads, s.width, s.height, s.spp,
                    s.maxDepth, runs, med, *std::min_element(times.begin(), times.end()), samples / med, samples / med * 1e-6);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_render: %s\n", e.what());
        return 2;
    }
    return 0;
}

// Path-tracing throughput: samples per second on the CPU (Embree + TBB) for a built-in scene.
// Prints one JSON object: median over several runs after a warm-up run.
//   bench_render [--scene cornell] [--width 512] [--height 512] [--spp 4] [--runs 7] [--threads 0] [--max-depth 8]
#include <sys/resource.h>
#include <tbb/info.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "atrous/device.h"
#include "bench_cli.h"
#include "atrous/render.h"
#include "atrous/timer.h"

// CPU seconds (user + system) this process has used: on a shared machine, samples per CPU-second
// is a figure the other tenants do not distort as much as wall-clock throughput.
static double cpuSeconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

int main(int argc, char** argv) {
    std::string scene = "cornell";
    atrous::RenderSettings s;
    s.width = 512;
    s.height = 512;
    s.spp = 4;
    int runs = 7;
    CLI::App app{"Path-tracing throughput of the Embree CPU renderer (samples/s); prints JSON", "bench_render"};
    app.add_option("--scene", scene, "built-in scene or scene .json file")->capture_default_str();
    app.add_option("--width", s.width, "image width")->capture_default_str();
    app.add_option("--height", s.height, "image height")->capture_default_str();
    app.add_option("--spp", s.spp, "samples per pixel")->capture_default_str();
    app.add_option("--runs", runs, "timed runs after a warm-up (median kept)")->check(CLI::Range(1, 100000))->capture_default_str();
    app.add_option("--threads", s.threads, "worker threads (0 = all cores)")->capture_default_str();
    app.add_option("--max-depth", s.maxDepth, "maximum bounces")->capture_default_str();
    if (int rc = atrous::bench::parseArgs(app, argc, argv); rc >= 0) return rc;
    try {
        atrous::validateRenderSettings(s);  // bad --width/--spp/... exit 2 before the warm-up
        atrous::Scene sc = atrous::Scene::loadByNameOrFile(scene);
        atrous::render(sc, s);  // warm-up: page faults, Embree/TBB start-up
        std::vector<double> times, cpu;
        for (int r = 0; r < runs; ++r) {
            double c0 = cpuSeconds();
            atrous::Timer t;
            atrous::RenderBuffers b = atrous::render(sc, s);
            times.push_back(t.seconds());
            cpu.push_back(cpuSeconds() - c0);
        }
        double med = atrous::median(times);
        double samples = double(s.width) * s.height * s.spp;
        int threads = s.threads > 0 ? s.threads : tbb::info::default_concurrency();
        std::printf("{\"benchmark\": \"render\", \"scene\": \"%s\", \"device\": \"%s\", \"threads\": %d, "
                    "\"width\": %d, \"height\": %d, \"spp\": %d, \"max_depth\": %d, \"runs\": %d, "
                    "\"median_s\": %.5f, \"min_s\": %.5f, \"samples_per_s\": %.0f, \"msamples_per_s\": %.3f, "
                    "\"median_cpu_s\": %.5f, \"msamples_per_cpu_s\": %.3f}\n",
                    scene.c_str(), atrous::deviceName(atrous::Device::Cpu).c_str(), threads, s.width, s.height, s.spp,
                    s.maxDepth, runs, med, *std::min_element(times.begin(), times.end()), samples / med, samples / med * 1e-6, atrous::median(cpu), samples / atrous::median(cpu) * 1e-6);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_render: %s\n", e.what());
        return 2;
    }
    return 0;
}

// The still filters on a render read from files, as `atrous denoise --in DIR` runs them, in two
// modes (issue 30, "From file to file as fast as in memory"):
//   --warm N   the const denoise() N times after warm-ups on the same buffers: median filter and
//              per-stage times (the in-memory figure, on real buffers rather than bench's 2 spp)
//   --one-shot read the buffers compactly (depth 1 channel, ids 2, only what the method reads),
//              hand colour, variance and emission over (denoise(DenoiseBuffers&)), once: the
//              filter's time and stages, and the process's peak resident memory (getrusage), as the
//              CLI will run once it holds its inputs that way.
// Prints one JSON object. Usage:
//   bench_file_filter --in DIR [--method eaw|sure|learned] [--no-variance] [--warm N | --one-shot]
//                     [--huge-pages] [--threads N]
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/scalable_allocator.h>

#include <memory>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "bench_cli.h"
#include "atrous/timer.h"
#include "atrous/io/buffer_set.h"

using namespace atrous;

namespace {

double peakRssMb() {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    return double(ru.ru_maxrss) / 1024.0;
}

Image firstChannels(Image&& src, int channels) {
    if (src.empty() || src.channels() <= channels) return std::move(src);
    Image out = Image::uninitialized(src.width(), src.height(), channels);
    std::memcpy(out.data(), src.data(), out.size() * sizeof(float));
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    std::string in, method = "eaw";
    bool noVariance = false, oneShot = false, hugePages = false;
    int warm = 10, threads = 0;
    CLI::App app{"still filters on a render read from files: warm runs or one compact one-shot call"};
    app.add_option("--in", in, "render directory (atrous render --out)")->required();
    app.add_option("--method", method, "eaw | sure | learned")->check(CLI::IsMember({"eaw", "sure", "learned"}));
    app.add_flag("--no-variance", noVariance, "leave the variance out (the noise is estimated)");
    app.add_option("--warm", warm, "timed runs of the const denoise() after 2 warm-ups");
    app.add_flag("--one-shot", oneShot, "one denoise(DenoiseBuffers&) call on compactly held buffers");
    app.add_flag("--huge-pages", hugePages, "scalable_allocation_mode(TBBMALLOC_USE_HUGE_PAGES, 1) first");
    app.add_option("--threads", threads, "TBB threads (0 = all cores; 1 measures the work alone on a loaded machine)");
    if (const int rc = bench::parseArgs(app, argc, argv); rc >= 0) return rc;
    try {
        if (hugePages) scalable_allocation_mode(TBBMALLOC_USE_HUGE_PAGES, 1);
        std::unique_ptr<tbb::global_control> limit;
        if (threads > 0)
            limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
        DenoiseOptions o;
        o.method = parseDenoiseMethod(method);
        const BufferMask use = denoiseReads(o, o.method);
        io::BufferFiles files;
        files.in = in;
        files.wanted = [&](io::Buffer b, const bool*) {
            if (b == io::Buffer::Variance && noVariance) return false;
            return use.has(b);
        };
        Timer readTimer;
        io::BufferSet set = io::loadBuffers(files);
        const double readMs = readTimer.ms();
        Image* img = set.image;
        const int depth = int(io::Buffer::Depth), ids = int(io::Buffer::ObjectId);
        img[depth] = firstChannels(std::move(img[depth]), 1);
        img[ids] = firstChannels(std::move(img[ids]), 2);
        const double rssInputs = peakRssMb();
        DenoiseReport rep;
        auto ptr = [&](io::Buffer b) { return img[int(b)].empty() ? nullptr : &img[int(b)]; };
        std::printf("{\"in\": \"%s\", \"method\": \"%s\", \"width\": %d, \"height\": %d, \"read_ms\": %.1f, "
                    "\"peak_rss_after_read_mb\": %.1f",
                    in.c_str(), method.c_str(), img[0].width(), img[0].height(), readMs, rssInputs);
        if (oneShot) {
            DenoiseBuffers b;
            b.color = ptr(io::Buffer::Color), b.variance = ptr(io::Buffer::Variance), b.emission = ptr(io::Buffer::Emission);
            b.albedo = ptr(io::Buffer::Albedo), b.normal = ptr(io::Buffer::Normal), b.position = ptr(io::Buffer::Position);
            b.depth = ptr(io::Buffer::Depth), b.ids = ptr(io::Buffer::ObjectId);
            Timer t;
            DenoiseResult res = denoiseWithReport(b, o);
            const Image out = std::move(res.image);
            rep = std::move(res.report);
            std::printf(", \"mode\": \"one-shot\", \"total_ms\": %.1f, \"filter_ms\": %.1f, \"peak_rss_mb\": %.1f, \"stages\": [",
                        t.ms(), rep.milliseconds, peakRssMb());
            for (size_t i = 0; i < rep.stages.size(); ++i)
                std::printf("%s[\"%s\", %.2f]", i ? ", " : "", rep.stages[i].name.c_str(), rep.stages[i].milliseconds);
            std::printf("]}\n");
            return out.empty() ? 1 : 0;
        }
        const Frame di = set.inputs();
        std::vector<double> filter, total;
        std::vector<std::string> names;
        std::vector<std::vector<double>> stage;
        for (int i = 0; i < warm + 2; ++i) {
            Timer t;
            rep = denoiseWithReport(di, o).report;
            if (i < 2) continue;
            total.push_back(t.ms());
            filter.push_back(rep.milliseconds);
            for (const StageTime& s : rep.stages) {
                const size_t k = size_t(std::find(names.begin(), names.end(), s.name) - names.begin());
                if (k == names.size()) names.push_back(s.name), stage.emplace_back();
                stage[k].push_back(s.milliseconds);
            }
        }
        std::printf(", \"mode\": \"warm\", \"runs\": %d, \"filter_median_ms\": %.2f, \"total_median_ms\": %.2f, "
                    "\"peak_rss_mb\": %.1f, \"stages\": [",
                    warm, median(filter), median(total), peakRssMb());
        for (size_t k = 0; k < names.size(); ++k)
            std::printf("%s[\"%s\", %.2f]", k ? ", " : "", names[k].c_str(), median(stage[k]));
        std::printf("]}\n");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_file_filter: error: %s\n", e.what());
        return 2;
    }
    return 0;
}

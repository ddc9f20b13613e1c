// Helper of bench/svgf_quality.py (not a timing benchmark):
//   svgf_sequence_tool denoise --method svgf|eaw|sure --sequence DIR --out OUTDIR
//       the body of `atrous denoise --sequence` (runSequenceDenoise), for builds where the CLI
//       does not have --sequence wired in yet;
//   svgf_sequence_tool metrics SEQDIR OUTDIR
//       JSON per frame: relMSE of OUTDIR/frame_NNNN.exr against SEQDIR/frame_NNNN/reference.exr and
//       the temporal error, the relMSE of the frame-to-frame difference (x_f - x_{f-1}) against the
//       references' difference (r_f - r_{f-1}) (ALGORITHMS.md section 5); null for frame 0; and
//       "temporal_no_emitters", the same leaving out pixels whose emission.exr is non-zero in
//       either frame. At 1 spp the jittered sample of a pixel on a light's edge hits the light
//       (radiance 17) or the ceiling (~0.7) at random, every method passes that through, and with
//       the metric's 0.01 floor under tiny reference differences those few pixels outweigh the
//       rest of the image (measured: the top 1% of pixels carried all of the error).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../apps/atrous/denoise_sequence.cpp"  // runSequenceDenoise without the CLI wiring
#include "atrous/error.h"
#include "atrous/metrics.h"
#include "io/image_io.h"
#include "io/sequence.h"

namespace {

using namespace atrous;

// relMSE = mean((x - r)^2 / (r^2 + 0.01)) over all channels, as atrous::computeMetrics.
double relMse(const Image& x, const Image& r) { return computeMetrics(x, r).relMse; }

// relMSE of x against r over the pixels where keep[pixel] != 0 (all when keep is empty).
double relMseMasked(const Image& x, const Image& r, const std::vector<char>& keep) {
    const size_t plane = size_t(x.width()) * x.height();
    double sum = 0.0;
    size_t n = 0;
    for (int c = 0; c < x.channels(); ++c)
        for (size_t i = 0; i < plane; ++i) {
            if (!keep.empty() && !keep[i]) continue;
            double xv = x.data()[c * plane + i], rv = r.data()[c * plane + i];
            double e = (xv - rv) * (xv - rv) / (rv * rv + 0.01);
            if (std::isfinite(e)) {
                sum += e;
                ++n;
            }
        }
    return n ? sum / double(n) : 0.0;
}

// 1 where no channel of the emission buffer is above 0 (empty when there is no emission.exr).
std::vector<char> nonEmitters(const std::string& frameDir) {
    std::string p = (std::filesystem::path(frameDir) / "emission.exr").string();
    if (!std::filesystem::exists(p)) return {};
    Image e = io::readImage(p);
    const size_t plane = size_t(e.width()) * e.height();
    std::vector<char> keep(plane, 1);
    for (int c = 0; c < e.channels(); ++c)
        for (size_t i = 0; i < plane; ++i)
            if (e.data()[c * plane + i] > 0.0f) keep[i] = 0;
    return keep;
}

Image difference(const Image& a, const Image& b) {
    Image d(a.width(), a.height(), a.channels());
    for (size_t i = 0; i < a.size(); ++i) d.data()[i] = a.data()[i] - b.data()[i];
    return d;
}

int metrics(const std::string& seqDir, const std::string& outDir) {
    std::vector<std::string> frames = io::listSequenceFrames(seqDir);
    nlohmann::json j = nlohmann::json::array();
    Image prevX, prevR;
    std::vector<char> prevKeep;
    for (const std::string& dir : frames) {
        std::string name = std::filesystem::path(dir).filename().string();
        Image r = io::readImage((std::filesystem::path(dir) / "reference.exr").string());
        Image x = io::readImage((std::filesystem::path(outDir) / (name + ".exr")).string());
        nlohmann::json f;
        f["frame"] = name;
        f["relmse"] = relMse(x, r);
        std::vector<char> keep = nonEmitters(dir);
        if (!prevX.empty()) {
            Image dx = difference(x, prevX), dr = difference(r, prevR);
            f["temporal"] = relMse(dx, dr);
            std::vector<char> both = keep;
            for (size_t i = 0; i < both.size() && i < prevKeep.size(); ++i) both[i] = both[i] && prevKeep[i];
            f["temporal_no_emitters"] = relMseMasked(dx, dr, both);
        } else {
            f["temporal"] = nullptr;
            f["temporal_no_emitters"] = nullptr;
        }
        prevKeep = std::move(keep);
        j.push_back(f);
        prevX = std::move(x);
        prevR = std::move(r);
    }
    std::printf("%s\n", j.dump(1).c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        if (argc == 4 && std::strcmp(argv[1], "metrics") == 0) return metrics(argv[2], argv[3]);
        if (argc >= 2 && std::strcmp(argv[1], "denoise") == 0) {
            CLI::App app("svgf_sequence_tool denoise");
            atrous::cli::SequenceDenoiseArgs a;
            a.preview = false;
            app.add_option("--method", a.method)->required();
            app.add_option("--sequence", a.sequenceDir)->required();
            app.add_option("--out", a.outDir)->required();
            app.add_flag("--quiet", a.quiet);
            atrous::cli::addSvgfOptions(app, a.svgf);
            try {
                app.parse(argc - 1, argv + 1);
            } catch (const CLI::ParseError& e) {
                return app.exit(e);
            }
            return atrous::cli::runSequenceDenoise(a);
        }
        std::fprintf(stderr, "usage: svgf_sequence_tool denoise --method M --sequence DIR --out OUT | metrics SEQDIR OUTDIR\n");
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "svgf_sequence_tool: error: %s\n", e.what());
        return 2;
    }
}

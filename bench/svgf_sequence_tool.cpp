// Helper of bench/svgf_quality.py (not a timing benchmark):
//   svgf_sequence_tool denoise --method svgf|eaw|sure --sequence DIR --out OUTDIR
//       the body of `atrous denoise --sequence` (runSequenceDenoise), for builds where the CLI
//       does not have --sequence wired in yet;
//   svgf_sequence_tool metrics SEQDIR OUTDIR
//       JSON per frame: relMSE of OUTDIR/frame_NNNN.exr against SEQDIR/frame_NNNN/reference.exr and
//       the temporal error, the relMSE of the frame-to-frame difference (x_f - x_{f-1}) against the
//       references' difference (r_f - r_{f-1}) (ALGORITHMS.md section 5); null for frame 0.
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

Image difference(const Image& a, const Image& b) {
    Image d(a.width(), a.height(), a.channels());
    for (size_t i = 0; i < a.size(); ++i) d.data()[i] = a.data()[i] - b.data()[i];
    return d;
}

int metrics(const std::string& seqDir, const std::string& outDir) {
    std::vector<std::string> frames = io::listSequenceFrames(seqDir);
    nlohmann::json j = nlohmann::json::array();
    Image prevX, prevR;
    for (const std::string& dir : frames) {
        std::string name = std::filesystem::path(dir).filename().string();
        Image r = io::readImage((std::filesystem::path(dir) / "reference.exr").string());
        Image x = io::readImage((std::filesystem::path(outDir) / (name + ".exr")).string());
        nlohmann::json f;
        f["frame"] = name;
        f["relmse"] = relMse(x, r);
        if (!prevX.empty()) f["temporal"] = relMse(difference(x, prevX), difference(r, prevR));
        else f["temporal"] = nullptr;
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

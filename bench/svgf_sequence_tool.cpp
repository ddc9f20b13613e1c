// Helper of atrous.eval sequences (python/atrous/eval/sequences.py) (not a timing benchmark):
//   svgf_sequence_tool denoise --method svgf|eaw|sure --sequence DIR --out OUTDIR
//       the body of `atrous denoise --sequence` (runSequenceDenoise), for builds where the CLI
//       does not have --sequence wired in yet;
//   svgf_sequence_tool metrics SEQDIR OUTDIR
//       JSON per frame: relMSE of OUTDIR/frame_NNNN.exr against SEQDIR/frame_NNNN/reference.exr and
//       the temporal error, the relMSE of the frame-to-frame difference (x_f - x_{f-1}) against the
//       references' difference (r_f - r_{f-1}) (docs/eval.md, "What is measured"); null for frame 0; and
//       "temporal_no_emitters", the same leaving out pixels whose emission.exr is non-zero in
//       either frame or in one of their 8 neighbours (partly covered light-edge pixels). At 1 spp
//       the jittered sample of a pixel on a light's edge hits the light (radiance 17) or the
//       ceiling (~0.7) at random; unless the emission is accumulated (SVGF's emissionAlpha < 1)
//       that flicker passes straight through, and with the metric's 0.01 floor under tiny
//       reference differences those few pixels outweigh the rest of the image (measured: the top
//       1% of pixels carried all of the error). This column shows the rest of the image.
//   svgf_sequence_tool crop IN.exr OUT.png X Y W H SCALE [EXPOSURE]
//       a W x H crop at (X, Y), enlarged SCALE times (nearest neighbour), as a PNG preview: for
//       looking at ghosting around a light's edge.
//   svgf_sequence_tool errmap X.exr REF.exr OUT.png [SCALE]
//       per-pixel relMSE (x - r)^2 / (r^2 + 0.01), channel mean, as a grey PNG (value * SCALE,
//       default 10); prints JSON with the total and the 10 largest pixels (where the error is).
//   svgf_sequence_tool probe IMG.exr X Y W H [CHANNEL]
//       prints one channel (default 0) of a W x H block at (X, Y) as a table (to read values near a light).
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <deque>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../apps/atrous/denoise_sequence.cpp"  // runSequenceDenoise and the SVGF flags without the CLI wiring
#include "atrous/error.h"
#include "atrous/metrics.h"
#include "atrous/io/image_io.h"
#include "atrous/io/sequence.h"

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
    Image e = atrous::readImage(p);
    const size_t plane = size_t(e.width()) * e.height();
    std::vector<char> emits(plane, 0);
    for (int c = 0; c < e.channels(); ++c)
        for (size_t i = 0; i < plane; ++i)
            if (e.data()[c * plane + i] > 0.0f) emits[i] = 1;
    // Dilated by one pixel: a pixel next to an emitting one may be partly covered by the light
    // although its one sample missed it this frame (SVGF's accumulated emission is non-zero there).
    std::vector<char> keep(plane, 1);
    const int w = e.width(), h = e.height();
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int j = -1; j <= 1; ++j)
                for (int i = -1; i <= 1; ++i) {
                    int qx = x + i, qy = y + j;
                    if (qx >= 0 && qy >= 0 && qx < w && qy < h && emits[size_t(qy) * w + qx]) keep[size_t(y) * w + x] = 0;
                }
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
        Image r = atrous::readImage((std::filesystem::path(dir) / "reference.exr").string());
        Image x = atrous::readImage((std::filesystem::path(outDir) / (name + ".exr")).string());
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

int crop(int argc, char** argv) {
    Image in = atrous::readImage(argv[2]);
    const int x0 = std::stoi(argv[4]), y0 = std::stoi(argv[5]), w = std::stoi(argv[6]), h = std::stoi(argv[7]);
    const int scale = std::stoi(argv[8]);
    const float exposure = argc > 9 ? std::stof(argv[9]) : 1.0f;
    if (w <= 0 || h <= 0 || scale <= 0 || x0 < 0 || y0 < 0 || x0 + w > in.width() || y0 + h > in.height())
        throw InputError("crop: the rectangle is empty or leaves the " + std::to_string(in.width()) + "x" +
                         std::to_string(in.height()) + " image");
    Image out(w * scale, h * scale, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h * scale; ++y)
            for (int x = 0; x < w * scale; ++x) out.view()(x, y, c) = in.view()(x0 + x / scale, y0 + y / scale, c);
    io::writePng(argv[3], out, exposure);
    return 0;
}

int errmap(int argc, char** argv) {
    Image x = atrous::readImage(argv[2]), r = atrous::readImage(argv[3]);
    if (x.width() != r.width() || x.height() != r.height()) throw InputError("errmap: the images differ in size");
    const float scale = argc > 5 ? std::stof(argv[5]) : 10.0f;
    Image e(x.width(), x.height(), 3);
    std::vector<std::pair<double, int>> px;
    double total = 0.0;
    for (int y = 0; y < x.height(); ++y)
        for (int i = 0; i < x.width(); ++i) {
            double s = 0.0;
            for (int c = 0; c < 3; ++c) {
                double d = double(x.view()(i, y, c)) - r.view()(i, y, c), rv = r.view()(i, y, c);
                s += d * d / (rv * rv + 0.01) / 3.0;
            }
            total += s;
            px.push_back({s, y * x.width() + i});
            for (int c = 0; c < 3; ++c) e.view()(i, y, c) = float(s) * scale;
        }
    io::writePng(argv[4], e, 1.0f);
    std::sort(px.rbegin(), px.rend());
    nlohmann::json j;
    j["relmse"] = total / double(px.size());
    for (int k = 0; k < 10 && k < int(px.size()); ++k)
        j["top"].push_back({{"x", px[k].second % x.width()}, {"y", px[k].second / x.width()}, {"relmse", px[k].first}});
    std::printf("%s\n", j.dump().c_str());
    return 0;
}

int probe(int argc, char** argv) {
    Image img = atrous::readImage(argv[2]);
    const int x0 = std::stoi(argv[3]), y0 = std::stoi(argv[4]), w = std::stoi(argv[5]), h = std::stoi(argv[6]);
    const int channel = argc > 7 ? std::stoi(argv[7]) : 0;
    if (channel < 0 || channel >= img.channels()) throw InputError("probe: no channel " + std::to_string(channel));
    for (int y = y0; y < y0 + h && y < img.height(); ++y) {
        std::printf("%4d:", y);
        for (int x = x0; x < x0 + w && x < img.width(); ++x) std::printf(" %6.2f", img.view()(x, y, channel));
        std::printf("\n");
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        if (argc == 4 && std::strcmp(argv[1], "metrics") == 0) return metrics(argv[2], argv[3]);
        if ((argc == 9 || argc == 10) && std::strcmp(argv[1], "crop") == 0) return crop(argc, argv);
        if ((argc == 5 || argc == 6) && std::strcmp(argv[1], "errmap") == 0) return errmap(argc, argv);
        if ((argc == 7 || argc == 8) && std::strcmp(argv[1], "probe") == 0) return probe(argc, argv);
        if (argc >= 2 && std::strcmp(argv[1], "denoise") == 0) {
            CLI::App app("svgf_sequence_tool denoise");
            atrous::cli::SequenceDenoiseArgs a;
            a.options.preview = false;
            app.add_option("--method", a.options.method)->required();
            app.add_option("--sequence", a.sequenceDir)->required();
            app.add_option("--out", a.outDir)->required();
            atrous::cli::addVerbosityFlags(app);  // --quiet, -v (progress.h, through denoise_sequence.cpp)
            std::deque<atrous::ParamSet> params;  // each sequence method's flags (--svgf-*, --temporal-*)
            atrous::cli::addSequenceOptions(app, params);
            try {
                app.parse(argc - 1, argv + 1);
            } catch (const CLI::CallForHelp& e) {
                return app.exit(e);
            } catch (const CLI::ParseError& e) {
                std::fprintf(stderr, "svgf_sequence_tool denoise: error: %s (see --help)\n", e.what());
                return 2;
            }
            for (size_t i = 0; i < atrous::sequenceMethods().size(); ++i)
                if (a.options.method == atrous::sequenceMethods()[i].name) a.options.params = params[i];
            return atrous::cli::runSequenceDenoise(a);
        }
        const bool help = argc == 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0);
        std::fprintf(help ? stdout : stderr, "usage: svgf_sequence_tool denoise --method M --sequence DIR --out OUT | metrics SEQDIR OUTDIR | "
                     "crop IN.exr OUT.png X Y W H SCALE [EXPOSURE] | errmap X.exr REF.exr OUT.png [SCALE] | "
                     "probe IMG.exr X Y W H [CHANNEL]\n");
        return help ? 0 : 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "svgf_sequence_tool: error: %s\n", e.what());
        return 2;
    }
}

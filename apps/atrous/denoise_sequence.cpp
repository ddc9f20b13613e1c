#include "denoise_sequence.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <vector>

#include "atrous/error.h"
#include "core/timer.h"
#include "io/image_io.h"
#include "io/sequence.h"

namespace fs = std::filesystem;

namespace atrous::cli {

namespace {

// Mean squared error over all channels, skipping non-finite reference values.
double meanSquaredError(const Image& a, const Image& b) {
    double sum = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
        double d = double(a.data()[i]) - double(b.data()[i]);
        if (std::isfinite(d)) {
            sum += d * d;
            ++n;
        }
    }
    return n ? sum / double(n) : 0.0;
}

std::string shellQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += (c == '\'') ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

void writeAnimatedPreview(const std::string& outDir, int firstIndex, bool quiet) {
    std::string ffmpeg = findOnPath("ffmpeg");
    if (ffmpeg.empty()) {
        std::printf("ffmpeg is not on PATH: skipping the animated preview (the per-frame PNGs are in %s)\n", outDir.c_str());
        return;
    }
    std::string finalPath = (fs::path(outDir) / "preview.mp4").string();
    std::string tmpPath = (fs::path(outDir) / ".preview.tmp.mp4").string();
    // Even dimensions for yuv420p; 24 frames per second.
    std::string cmd = shellQuote(ffmpeg) + " -nostdin -y -loglevel error -framerate 24 -start_number " +
                      std::to_string(firstIndex) + " -i " + shellQuote((fs::path(outDir) / "frame_%04d.png").string()) +
                      " -vf " + shellQuote("pad=ceil(iw/2)*2:ceil(ih/2)*2") + " -pix_fmt yuv420p -f mp4 " + shellQuote(tmpPath);
    int rc = std::system(cmd.c_str());
    std::error_code ec;
    if (rc != 0) {
        fs::remove(tmpPath, ec);
        std::printf("warning: ffmpeg failed (exit status %d); no animated preview written\n", rc);
        return;
    }
    fs::rename(tmpPath, finalPath, ec);
    if (ec) {
        fs::remove(tmpPath, ec);
        std::printf("warning: could not rename the animated preview into place\n");
        return;
    }
    if (!quiet) std::printf("animated preview: %s\n", finalPath.c_str());
}

}  // namespace

void addSvgfOptions(CLI::App& cmd, SvgfParams& p) {
    const char* g = "SVGF (--method svgf)";
    cmd.add_option("--svgf-sigma-l", p.sigmaL, "luminance edge stop σ_l, in standard deviations")->capture_default_str()->group(g);
    cmd.add_option("--svgf-sigma-n", p.sigmaN, "normal edge stop exponent σ_n")->capture_default_str()->group(g);
    cmd.add_option("--svgf-sigma-z", p.sigmaZ, "depth edge stop σ_z, relative to the depth gradient")->capture_default_str()->group(g);
    cmd.add_option("--svgf-alpha", p.alpha, "minimum temporal blend factor of the colour, (0, 1]")->capture_default_str()->group(g);
    cmd.add_option("--svgf-moments-alpha", p.momentsAlpha, "minimum temporal blend factor of the moments, (0, 1]")
        ->capture_default_str()->group(g);
    cmd.add_option("--svgf-history-cap", p.historyCap, "maximum history length in frames")->capture_default_str()->group(g);
    cmd.add_option("--svgf-levels", p.levels, "à-trous levels (0 = temporal accumulation only)")->capture_default_str()->group(g);
    cmd.add_option("--svgf-feedback-tap", p.feedbackTap, "level whose output becomes the colour history (-1 = unfiltered)")
        ->capture_default_str()->group(g);
    cmd.add_option("--svgf-spatial-variance-frames", p.spatialVarianceFrames,
                   "history length below which the variance is estimated spatially (7x7)")
        ->capture_default_str()->group(g);
    cmd.add_option("--svgf-depth-tolerance", p.reprojectDepthTolerance, "reprojection depth test τ_z")
        ->capture_default_str()->group(g);
    cmd.add_option("--svgf-normal-cos", p.reprojectNormalCos, "reprojection: minimum cosine between normals")
        ->capture_default_str()->group(g);
    cmd.add_flag("--taa", p.taa, "temporal anti-aliasing after SVGF (off by default)")->group(g);
    cmd.add_option("--taa-alpha", p.taaAlpha, "TAA blend weight of the current frame, (0, 1]")->capture_default_str()->group(g);
    cmd.add_option("--svgf-emission-alpha", p.emissionAlpha,
                   "minimum temporal blend factor of the emission (3x3-clamped history; 1 = raw emission), (0, 1]")
        ->capture_default_str()->group(g);
    cmd.add_option("--svgf-emission-motion-alpha", p.emissionMotionAlpha,
                   "emission blend factor at least this times the motion across a light's edge, pixels per frame (0 = off), >= 0")
        ->capture_default_str()->group(g);
}

std::string findOnPath(const std::string& name) {
    const char* path = std::getenv("PATH");
    if (!path) return "";
    std::stringstream ss(path);
    std::string dir;
    while (std::getline(ss, dir, ':')) {
        if (dir.empty()) continue;
        fs::path candidate = fs::path(dir) / name;
        std::error_code ec;
        if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
    return "";
}

int runSequenceDenoise(const SequenceDenoiseArgs& args) {
    const bool svgf = args.method == "svgf";
    if (!svgf && args.method != "eaw" && args.method != "sure")
        throw InputError("--method '" + args.method + "' cannot denoise a sequence (expected svgf, eaw or sure)");
    if (args.sequenceDir.empty()) throw InputError("--sequence: no directory given");
    if (args.outDir.empty()) throw InputError("--out: no output directory given");
    if (!(args.exposure > 0.0f)) throw InputError("--exposure must be > 0");

    // Everything that can be checked before writing is checked first (nothing is written on error).
    std::vector<std::string> frames = io::listSequenceFrames(args.sequenceDir);
    int width = 0, height = 0;
    io::validateSequence(frames, width, height);
    std::unique_ptr<SvgfDenoiser> svgfDenoiser;
    DenoiseOptions options = args.frameOptions;
    if (svgf) {
        svgfDenoiser = std::make_unique<SvgfDenoiser>(args.svgf, args.device);
    } else {
        options.method = parseDenoiseMethod(args.method);
        options.device = args.device;
        validateDenoiseOptions(options);
    }
    io::ensureWritableDirectory(args.outDir);

    int firstIndex = -1;
    for (const auto& dir : frames) {
        io::SequenceFrame f = io::loadSequenceFrame(dir);
        if (firstIndex < 0) firstIndex = f.index;
        Timer timer;
        Image out;
        if (svgf) {
            SvgfFrame in;
            in.color = &f.color;
            in.albedo = &f.albedo;
            in.normal = &f.normal;
            in.depth = &f.depth;
            in.ids = &f.ids;
            in.motion = &f.motion;
            in.emission = f.emission.empty() ? nullptr : &f.emission;
            out = svgfDenoiser->denoiseFrame(in);
        } else {
            DenoiseInputs in;
            in.color = &f.color;
            in.variance = f.variance.empty() ? nullptr : &f.variance;
            in.albedo = &f.albedo;
            in.normal = &f.normal;
            in.position = &f.position;
            in.depth = &f.depth;
            in.ids = &f.ids;
            out = denoise(in, options);
        }
        double ms = timer.ms();
        std::string name = io::sequenceFrameName(f.index);
        io::writeImage((fs::path(args.outDir) / (name + ".exr")).string(), out);
        io::writePng((fs::path(args.outDir) / (name + ".png")).string(), out, args.exposure);
        if (!args.quiet) {
            std::printf("%s: %s %.1f ms", name.c_str(), args.method.c_str(), ms);
            if (!f.reference.empty())
                std::printf(", MSE vs reference %.6g (input %.6g)", meanSquaredError(out, f.reference),
                            meanSquaredError(f.color, f.reference));
            std::printf("\n");
            std::fflush(stdout);
        }
    }
    if (args.preview) writeAnimatedPreview(args.outDir, firstIndex, args.quiet);
    return 0;
}

}  // namespace atrous::cli

// `atrous render`: path-traces a built-in or JSON scene and writes the colour with its denoiser
// buffers (EXR) and a PNG preview; optionally denoises the result.
#include <tbb/task_arena.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/params.h"
#include "atrous/render.h"
#include "cli_flags.h"
#include "commands.h"
#include "atrous/timer.h"
#include "atrous/io/image_io.h"
#include "atrous/io/sequence.h"
#include "progress.h"

namespace atrous::cli {
namespace {

struct RenderArgs {
    std::string scene;
    std::string out;
    std::string denoise;
    RenderSettings settings;
    // Animation (--frames): 0 = a still image as before.
    int frames = 0;
    bool framesGiven = false;
    int referenceSpp = 0;
    std::string cameraPath = "auto";
    std::string device = "auto";
};

// Seeds of the noisy and reference renders of frame f: every noisy frame gets its own noise (a
// temporal filter must not see the same pattern twice). References all use one other seed, never
// a noisy frame's: their residual noise then stays put from frame to frame instead of flickering,
// so reference differences r_f - r_{f-1} (the temporal error's yardstick) show the true change.
uint32_t frameSeed(uint32_t seed, int f) { return seed + uint32_t(f); }
uint32_t referenceSeed(uint32_t seed) { return seed + 0x9E3779B9u; }

// Sequence frames at 1 spp leave variance.exr out: the variance is unknown there (written as 0),
// and a sequence's optional variance.exr would tell per-frame EAW/SURE the frame is noise-free.
void writeBuffers(const std::string& dir, const RenderBuffers& b, bool withVariance = true) {
    namespace fs = std::filesystem;
    auto path = [&](const std::string& name) { return (fs::path(dir) / name).string(); };
    for (const RenderBufferField& f : kRenderBufferFields) {  // NAME.exr for every buffer it has
        const Image& img = b.*f.image;
        if (!img.empty() && (withVariance || f.image != &RenderBuffers::variance))
            atrous::writeImage(path(std::string(f.name) + ".exr"), img);
    }
}

// `atrous render --frames F`: DIR/frame_NNNN/ per frame (time t = f / max(F - 1, 1)) with the
// usual buffers plus motion.exr and emission.exr, and reference.exr with --reference-spp.
void runFrames(const RenderArgs& a) {
    if (a.frames < 1) throw InputError("--frames: must be at least 1 (got " + std::to_string(a.frames) + ")");
    if (a.frames > 100000) throw InputError("--frames: at most 100000 (got " + std::to_string(a.frames) + ")");
    if (a.referenceSpp < 0) throw InputError("--reference-spp: must be at least 1 (got " + std::to_string(a.referenceSpp) + ")");
    if (!a.denoise.empty()) throw InputError("--denoise: not with --frames (denoise the sequence with atrous denoise --sequence)");
    const RenderSettings& s = a.settings;
    validateRenderSettings(s);
    RenderSettings ref = s;
    ref.spp = a.referenceSpp > 0 ? a.referenceSpp : 1;
    validateRenderSettings(ref);
    CameraPath path = parseCameraPath(a.cameraPath);
    Scene scene = Scene::loadByNameOrFile(a.scene);
    (void)scene.atTime(0.0f, path);  // InputError now (keyframes missing), before anything is written
    io::ensureWritableDirectory(a.out);

    namespace fs = std::filesystem;
    // An earlier, longer sequence in OUT would leave frames this run does not render; a later
    // `atrous denoise --sequence OUT` would take them in. They go first (said in one line).
    const std::vector<std::string> stale =
        io::removeSequenceEntries(a.out, "", [&](int index) { return index < a.frames; });
    if (!stale.empty())
        logLine("render: removed %zu frame director%s of an earlier run from %s (%s%s)\n", stale.size(),
                     stale.size() == 1 ? "y" : "ies", a.out.c_str(), stale.front().c_str(),
                     stale.size() > 2 ? (", ..., " + stale.back()).c_str() : stale.size() == 2 ? (", " + stale.back()).c_str() : "");
    Timer total;
    const uint64_t frameSamples = uint64_t(s.width) * uint64_t(s.height) * uint64_t(s.spp + a.referenceSpp);
    ProgressLine progress(!quiet() && stderrIsTerminal(), "render", frameSamples * uint64_t(a.frames), a.frames);
    for (int f = 0; f < a.frames; ++f) {
        progress.setFrame(f);
        const float t = frameTime(f, a.frames);
        const float tPrev = f > 0 ? frameTime(f - 1, a.frames) : t;  // frame 0: no previous frame, motion 0
        RenderSettings fs_ = s;
        fs_.seed = frameSeed(s.seed, f);
        fs_.samplesDone = progress.counter();
        Timer timer;
        RenderBuffers b = renderFrame(scene, path, t, tPrev, fs_);
        Image reference;
        if (a.referenceSpp > 0) {
            ref.seed = referenceSeed(s.seed);
            ref.samplesDone = progress.counter();
            reference = renderFrame(scene, path, t, t, ref).color;
        }
        double seconds = timer.seconds();
        const std::string dir = (fs::path(a.out) / io::sequenceFrameName(f)).string();
        // The frame is written into a hidden directory that then replaces frame_NNNN/ whole: an
        // earlier run's optional buffers (reference.exr, variance.exr) never survive next to this run's.
        const std::string stage = (fs::path(a.out) / ("." + io::sequenceFrameName(f) + ".partial")).string();
        std::error_code ec;
        fs::remove_all(stage, ec);
        io::ensureWritableDirectory(stage);
        try {
            writeBuffers(stage, b, /*withVariance=*/s.spp > 1);  // motion.exr too
            if (!reference.empty()) atrous::writeImage((fs::path(stage) / "reference.exr").string(), reference);
            io::writePng((fs::path(stage) / "color.png").string(), b.color);
        } catch (...) {
            fs::remove_all(stage, ec);  // e.g. disk full: no half-written hidden frame left behind
            throw;
        }
        fs::remove_all(dir, ec);
        if (!ec) fs::rename(stage, dir, ec);
        if (ec) throw RuntimeError(dir + ": cannot move the frame into place (" + ec.message() + ")");
        progress.above(
            [&] { resultLine("frame %d/%d (t = %.4f): %.3f s -> %s\n", f + 1, a.frames, t, seconds, dir.c_str()); });
    }
    progress.finish();
    resultLine("rendered %s: %d frames, %dx%d, %d spp%s, %.3f s -> %s\n", scene.name().c_str(), a.frames, s.width,
                s.height, s.spp, a.referenceSpp > 0 ? (", reference " + std::to_string(a.referenceSpp) + " spp").c_str() : "",
                total.seconds(), a.out.c_str());
}

std::vector<DenoiseMethod> parseMethods(const std::string& list) {
    std::vector<DenoiseMethod> methods;
    if (list.empty()) return methods;
    std::stringstream ss(list);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty()) throw InputError("--denoise: empty method name in \"" + list + "\"");
        methods.push_back(withFlag("--denoise", [&] { return parseDenoiseMethod(item); }));
    }
    return methods;
}

void run(const RenderArgs& a) {
    // InputError for cuda without a GPU or CUDA build. Animations render on the CPU (auto picks it).
    const Device device = parseDevice(a.framesGiven && a.device == "auto" ? "cpu" : a.device);
    if (a.framesGiven) {
        if (device == Device::Cuda) throw InputError("--frames: animation renders on the CPU only so far (use --device cpu)");
        return runFrames(a);
    }
    if (a.referenceSpp != 0) throw InputError("--reference-spp: only with --frames");
    if (a.cameraPath != "auto") throw InputError("--camera-path: only with --frames");
    // Everything that can be checked before rendering is: settings, scene, methods, output dir.
    std::vector<DenoiseMethod> methods = parseMethods(a.denoise);
    const RenderSettings& s = a.settings;
    validateRenderSettings(s);
    Scene scene = Scene::loadByNameOrFile(a.scene);
    io::ensureWritableDirectory(a.out);

    Timer timer;
    // The CUDA path tracer runs the same per-pixel kernel over a BVH built by Embree's builder
    // (no progress line there: it reports no tiles, and it is fast).
    RenderSettings rs = s;
    ProgressLine progress(!quiet() && stderrIsTerminal() && device == Device::Cpu, "render",
                          uint64_t(s.width) * uint64_t(s.height) * uint64_t(s.spp));
    rs.samplesDone = progress.counter();
    RenderBuffers b = render(scene, device == Device::Cuda ? s : rs, device);
    progress.finish();
    double seconds = timer.seconds();

    std::vector<std::pair<std::string, Image>> denoised;
    double denoiseSeconds = 0.0;
    if (!methods.empty()) {
        // Every buffer, emission included: filtering color - emission keeps a visible light's
        // anti-aliased edge out of its surroundings.
        Frame in = b.frame();
        Timer dt;
        for (DenoiseMethod m : methods) {
            DenoiseOptions opt;
            opt.method = m;
            opt.device = device;
            denoised.emplace_back(denoiseMethodName(m), denoise(in, opt));
        }
        denoiseSeconds = dt.seconds();
    }

    // All in memory: now write, each file atomically.
    namespace fs = std::filesystem;
    auto path = [&](const std::string& name) { return (fs::path(a.out) / name).string(); };
    writeBuffers(a.out, b);
    io::writePng(path("color.png"), b.color);
    for (const auto& [name, img] : denoised) {
        atrous::writeImage(path("denoised_" + name + ".exr"), img);
        io::writePng(path("denoised_" + name + ".png"), img);
    }

    double samples = double(s.width) * s.height * s.spp;
    char secondsText[32];
    std::snprintf(secondsText, sizeof secondsText, "%.3f", denoiseSeconds);
    const std::string denoisedText = denoised.empty() ? "" : ", denoised (" + a.denoise + ") in " + secondsText + " s";
    resultLine("rendered %s on %s: %dx%d, %d spp, max depth %d, %.3f s, %.2f M samples/s%s -> %s\n", scene.name().c_str(),
           deviceToString(device), s.width, s.height, s.spp, s.maxDepth, seconds, samples / seconds * 1e-6, denoisedText.c_str(),
           a.out.c_str());
}

}  // namespace

void addRenderCommand(CLI::App& app) {
    auto args = std::make_shared<RenderArgs>();
    auto* cmd = app.add_subcommand("render", "Path-trace a scene; write color, variance and feature buffers (EXR) and a PNG preview");
    std::string names;
    for (const auto& n : builtinSceneNames()) names += (names.empty() ? "" : ", ") + n;
    cmd->add_option("--scene", args->scene, "Built-in scene (" + names + ") or a scene .json file")->required();
    cmd->add_option("--out", args->out,
                    "Output directory (created if missing). With --frames, OUT/frame_NNNN/ is replaced whole, and "
                    "frame_NNNN/ directories of an earlier run with NNNN >= --frames are removed (one note on stderr)")
        ->required();
    // --width, --height, --spp, --seed, --max-depth, --threads, --no-light-sampling: the render
    // parameter table (atrous/params.h); out-of-range values are the library's ParamError, which
    // main.cpp shows with the row's flag.
    addParamOptions(*cmd, args->settings, renderParams(), [](const ParamField<RenderSettings>&) { return "Render settings"; });
    cmd->add_option("--device", args->device, "cpu, cuda or auto (cuda when a GPU is present; the GPU path tracer runs over a BVH built by Embree)")
        ->capture_default_str();
    cmd->add_option("--denoise", args->denoise, "Also denoise with these methods (a comma list of " + denoiseMethodNames() + ")");
    auto* frames = cmd->add_option("--frames", args->frames,
                                   "Render an animation of this many frames into OUT/frame_NNNN/ (time t = f / max(F-1, 1))")->check(kNonEmptyNumber);
    cmd->add_option("--reference-spp", args->referenceSpp, "With --frames: also write reference.exr per frame at this spp (other seed)")->check(kNonEmptyNumber);
    cmd->add_option("--camera-path", args->cameraPath, "With --frames: auto, static, orbit, dolly or keyframes")->capture_default_str();
    // --quiet: nothing but errors (also no progress line, which is shown only when stderr is a terminal:
    // per frame with an ETA for --frames, by finished tiles for a still image); -v.
    addVerbosityFlags(*cmd);
    cmd->callback([args, frames] {
        args->framesGiven = frames->count() > 0;
        // --threads (the render table's row: the path tracer's arena) also limits the rest of the
        // run, the --denoise filters and the writers, through TBB's global_control (cli_flags.h).
        const auto threadLimit = limitThreads(args->settings.threads);
        run(*args);
    });
}

}  // namespace atrous::cli

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
#include "atrous/render.h"
#include "commands.h"
#include "core/timer.h"
#include "io/image_io.h"

namespace atrous::cli {
namespace {

struct RenderArgs {
    std::string scene;
    std::string out;
    std::string denoise;
    RenderSettings settings;
};

std::vector<DenoiseMethod> parseMethods(const std::string& list) {
    std::vector<DenoiseMethod> methods;
    if (list.empty()) return methods;
    std::stringstream ss(list);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty()) throw InputError("--denoise: empty method name in \"" + list + "\"");
        methods.push_back(parseDenoiseMethod(item));  // InputError names the bad method
    }
    return methods;
}

void run(const RenderArgs& a) {
    // Everything that can be checked before rendering is: settings, scene, methods, output dir.
    std::vector<DenoiseMethod> methods = parseMethods(a.denoise);
    const RenderSettings& s = a.settings;
    validateRenderSettings(s);
    Scene scene = Scene::loadByNameOrFile(a.scene);
    io::ensureWritableDirectory(a.out);

    Timer timer;
    RenderBuffers b = render(scene, s);
    double seconds = timer.seconds();

    std::vector<std::pair<std::string, Image>> denoised;
    double denoiseSeconds = 0.0;
    if (!methods.empty()) {
        DenoiseInputs in;
        in.color = &b.color;
        in.variance = &b.variance;
        in.albedo = &b.albedo;
        in.normal = &b.normal;
        in.position = &b.position;
        in.depth = &b.depth;
        in.ids = &b.ids;
        Timer dt;
        for (DenoiseMethod m : methods) {
            DenoiseOptions opt;
            opt.method = m;
            denoised.emplace_back(denoiseMethodName(m), denoise(in, opt));
        }
        denoiseSeconds = dt.seconds();
    }

    // All in memory: now write, each file atomically.
    namespace fs = std::filesystem;
    auto path = [&](const std::string& name) { return (fs::path(a.out) / name).string(); };
    io::writeImage(path("color.exr"), b.color);
    io::writeImage(path("variance.exr"), b.variance);
    io::writeImage(path("albedo.exr"), b.albedo);
    io::writeImage(path("normal.exr"), b.normal);
    io::writeImage(path("position.exr"), b.position);
    io::writeImage(path("depth.exr"), b.depth);
    io::writeImage(path("ids.exr"), b.ids);
    io::writePng(path("color.png"), b.color);
    for (const auto& [name, img] : denoised) {
        io::writeImage(path("denoised_" + name + ".exr"), img);
        io::writePng(path("denoised_" + name + ".png"), img);
    }

    double samples = double(s.width) * s.height * s.spp;
    std::printf("rendered %s: %dx%d, %d spp, max depth %d, %.3f s, %.2f M samples/s", scene.name().c_str(), s.width,
                s.height, s.spp, s.maxDepth, seconds, samples / seconds * 1e-6);
    if (!denoised.empty()) std::printf(", denoised (%s) in %.3f s", a.denoise.c_str(), denoiseSeconds);
    std::printf(" -> %s\n", a.out.c_str());
}

}  // namespace

void addRenderCommand(CLI::App& app) {
    auto args = std::make_shared<RenderArgs>();
    auto* cmd = app.add_subcommand("render", "Path-trace a scene; write color, variance and feature buffers (EXR) and a PNG preview");
    std::string names;
    for (const auto& n : builtinSceneNames()) names += (names.empty() ? "" : ", ") + n;
    cmd->add_option("--scene", args->scene, "Built-in scene (" + names + ") or a scene .json file")->required();
    cmd->add_option("--out", args->out, "Output directory (created if missing)")->required();
    cmd->add_option("--width", args->settings.width, "Image width in pixels")->capture_default_str();
    cmd->add_option("--height", args->settings.height, "Image height in pixels")->capture_default_str();
    cmd->add_option("--spp", args->settings.spp, "Samples per pixel")->capture_default_str();
    cmd->add_option("--seed", args->settings.seed, "Random seed (same seed, same image)")->capture_default_str();
    cmd->add_option("--max-depth", args->settings.maxDepth, "Maximum bounces (1 = direct light only)")->capture_default_str();
    cmd->add_option("--threads", args->settings.threads, "Worker threads (0 = all cores)")->capture_default_str();
    cmd->add_option("--denoise", args->denoise, "Also denoise with these methods (comma list: eaw,sure)");
    cmd->callback([args] { run(*args); });
}

}  // namespace atrous::cli

// `atrous view`: the interactive viewer (apps/atrous/view/, docs/viewer.md). Compiled in only when
// GLFW, OpenGL and imgui were found (ATROUS_HAVE_VIEWER); otherwise the command exists and says so.
#include <string>

#include "atrous/error.h"
#include "commands.h"
#if defined(ATROUS_HAVE_VIEWER)
#include "atrous/params.h"
#include "cli_flags.h"
#include "denoise_sequence.h"
#include "input_flags.h"
#include "atrous/view_pipeline.h"
#include "view/viewer.h"
#endif

namespace atrous::cli {

#if defined(ATROUS_HAVE_VIEWER)
namespace {
// "none | eaw | ...": the viewer's list, which is the library's (view::methodNames()).
std::string methodList() {
    std::string s;
    for (const std::string& n : view::methodNames()) s += (s.empty() ? "" : " | ") + n;
    return s;
}
// Flags that cannot apply are refused, never ignored: the render's (its table's flags, --orbit,
// --no-accumulate) with a render read from files, the input's own with a scene.
void refuseInapplicable(const CLI::App& cmd, const view::ViewerOptions& o) {
    const bool files = o.input.any() || !o.sequenceInput.empty();
    std::vector<std::string> flags{"--orbit", "--no-accumulate"};
    for (const ParamField<RenderSettings>& f : renderParams()) flags.push_back(renderParams().flag(f));
    if (!files) flags = {"--pass", "--layer"};
    std::string given;
    for (const std::string& f : flags)
        if (cmd.get_option_no_throw(f) && cmd.count(f) > 0) given += (given.empty() ? "" : ", ") + f;
    if (given.empty()) return;
    throw InputError(given + (files ? ": a render read from files (--in, --sequence) is not rendered; drop "
                                    : ": read a render's passes (give --in or --sequence); drop ") +
                     (given.find(',') == std::string::npos ? "it" : "them"));
}

}  // namespace

void addViewCommand(CLI::App& app) {
    auto opt = std::make_shared<view::ViewerOptions>();
    CLI::App* cmd = app.add_subcommand("view",
                                       "Interactive viewer: progressive path tracing with live "
                                       "denoising (GLFW + OpenGL + Dear ImGui)");
    view::ViewerOptions& o = *opt;
    cmd->add_option("--scene", o.scene, "Built-in scene name or JSON scene file (a render: --in)")
        ->capture_default_str();
    // A render instead of a scene: a still as `atrous denoise --in` reads it, or a sequence.
    const char* kGroupInput = "Your render (instead of --scene; docs/viewer.md)";
    cli::addInputFlags(*cmd, o.input, kGroupInput, kGroupInput);
    cmd->add_option("--sequence", o.sequenceInput,
                    "A rendered sequence as `atrous denoise --sequence` reads it (a folder or DIR/render####.exr): "
                    "Left/Right step through its frames")
        ->group(kGroupInput);
    cmd->add_option("--start", o.range.start, "With --sequence: the first frame")->group(kGroupInput);
    cmd->add_option("--end", o.range.end, "With --sequence: the last frame")->group(kGroupInput);
    cmd->add_option("--step", o.range.step, "With --sequence: every step-th frame")->group(kGroupInput);
    cmd->add_option("--device", o.device, "cpu | cuda | auto")->capture_default_str();
    // --width, --height, --spp (per frame), --max-depth, --seed from the render parameter table
    // (frame k takes sample indices k*spp.. of each pixel, so frames add fresh samples); the
    // viewer's renderer uses all its threads and light sampling.
    addParamOptions(*cmd, o.render, renderParams(), [](const ParamField<RenderSettings>&) { return "Render settings"; },
                    +[](const ParamField<RenderSettings>& f) {
                        const std::string n = f.name;
                        return n != "threads" && n != "light_sampling";
                    });
    cmd->add_option("--method", o.method, "Denoiser of the main view: " + methodList())
        ->capture_default_str();
    // --svgf-* (and --taa), --temporal-*: the tables of the sequence methods the viewer runs, start
    // values of the panel's sections.
    // The still methods' parameters (`atrous denoise`'s flags): start values of the panel.
    addParamOptions(*cmd, o.denoise, denoiseParams(),
                    [](const ParamField<DenoiseOptions>&) { return "Still methods' parameters (start values)"; });
    addSequenceOptions(*cmd, o.sequence, +[](const SequenceMethodInfo& m) { return m.causal || m.causalMode; }, false);
    cmd->add_option("--compare", o.compare, "Split screen: the method shown on the right half");
    cmd->add_flag("--no-accumulate", o.noAccumulate,
                  "Filter each frame on its own (no running mean)");
    cmd->add_option("--buffer", o.bufferView,
                    "Initial buffer view: result, color, variance, albedo, normal, position, "
                    "depth, mesh-ids, "
                    "material-ids, motion, detail, sure-s")
        ->capture_default_str();
    cmd->add_option("--exposure", o.exposure, "Display exposure (linear scale)")
        ->capture_default_str();
    cmd->add_option("--frames", o.frames,
                    "Headless: render N frames (with --sequence: show its first N frames in turn), save --screenshot/--dump, exit");
    cmd->add_option("--screenshot", o.screenshot,
                    "Headless: PNG of the window's framebuffer after the last frame");
    cmd->add_option("--dump", o.dumpDir,
                    "Headless: directory for every buffer (EXR) after the last frame");
    cmd->add_option("--out", o.outDir, "Directory of the F12 / P snapshots and of the O key's image and command")
        ->capture_default_str();
    cmd->add_flag("--write-image", o.writeImage,
                  "Headless: after the last frame, write the image and its `atrous denoise` command as the O key does");
    cmd->add_option("--orbit", o.orbitDegPerFrame,
                    "Turntable: orbit the camera by this many degrees per frame");
    cmd->add_flag("--hide-ui", o.hideUi,
                  "No control panel: the window is exactly --width x --height");
    cmd->add_flag("--benchmark", o.benchmark,
                  "Print a JSON line of frame and stage timings at exit");
    cmd->callback([opt, cmd] {
        opt->sceneGiven = cmd->count("--scene") > 0;
        refuseInapplicable(*cmd, *opt);
        for (const char* f : {"--start", "--end", "--step"})
            if (cmd->count(f) > 0 && opt->sequenceInput.empty()) throw InputError(std::string(f) + ": picks frames of a --sequence; give one");
        view::runViewer(*opt);
    });
}
#else
void addViewCommand(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand("view", "Interactive viewer (not in this build)");
    cmd->allow_extras();
    cmd->callback(
        [] { throw InputError("built without the viewer (install libglfw3-dev libimgui-dev)"); });
}
#endif

}  // namespace atrous::cli

// `atrous view`: the interactive viewer (GLFW window, OpenGL 3.3 core, Dear ImGui). Built only
// when GLFW, OpenGL and imgui are found (ATROUS_HAVE_VIEWER); docs/viewer.md.
#pragma once
#include <cstdint>
#include <deque>
#include <string>

#include "atrous/denoise.h"
#include "atrous/param_set.h"
#include "atrous/io/sequence.h"
#include "atrous/render.h"
#include "input_flags.h"

namespace atrous::view {

struct ViewerOptions {
    std::string scene = "cornell";
    bool sceneGiven = false;  // --scene was on the command line (not only its default)
    // A render to open instead of a scene (docs/viewer.md, "Your render"): a still as `atrous
    // denoise --in` reads it, or a sequence (a folder or a pattern, the frames of `range`).
    cli::InputFlags input;
    std::string sequenceInput;  // --sequence
    io::FrameRange range;
    // The still methods' parameters: the start values of the panel (the flags of `atrous denoise`).
    DenoiseOptions denoise;
    bool writeImage = false;  // headless: after the last frame, write the image and its command (the O key)
    std::string device = "cpu";
    // Image size, samples per pixel per frame, bounces and seed (flags from the render parameter
    // table, atrous/params.h); one sample per pixel per frame by default.
    RenderSettings render = [] {
        RenderSettings r;
        r.spp = 1;
        return r;
    }();
    std::string method = denoiseMethodName(DenoiseMethod::Blend);  // slot A: a name of methodNames() (blend: auto's choice, the renderer gives every buffer)
    std::string compare;         // slot B for the split screen (empty: no split)
    bool noAccumulate = false;
    std::string bufferView = "result";  // initial buffer view (see docs/viewer.md)
    float exposure = 1.0f;
    // Headless: render this many frames, save --screenshot (window framebuffer) and exit.
    int frames = 0;
    std::string screenshot;
    std::string dumpDir;                 // headless: also write every buffer (EXR) here at the end
    std::string outDir = "atrous_view";  // F12 / P snapshots go to OUT/snap_NNNN/
    float orbitDegPerFrame = 0.0f;       // turntable: yaw the orbit camera by this much every frame
    bool hideUi = false;                 // no control panel: the window is exactly width x height
    bool benchmark = false;              // print a JSON line with frame and stage timings at exit
    // The sequence methods' flags (--svgf-*, --temporal-*: their tables), by their place in
    // sequenceMethods(): the start values of the panel's sections.
    std::deque<ParamSet> sequence;
};

// Opens the window and runs until it is closed (or --frames are done). Throws InputError for bad
// flags, an unknown scene, no display or no OpenGL 3.3 context (the CLI exits 2).
void runViewer(const ViewerOptions& options);

}  // namespace atrous::view

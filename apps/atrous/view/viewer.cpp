// `atrous view`: GLFW window + OpenGL 3.3 core + Dear ImGui over the frame pipeline
// (view_pipeline.h). This file is the frame loop; its parts live beside it: window.h (window,
// context, ImGui, screenshots), camera_input.h (mouse and keyboard camera), display.h (the image's
// way into the display texture: host upload, or CUDA-OpenGL interop with --device cuda),
// buffer_view.h (the buffer views and their tonemapping), panel.h (layout, image, control panel)
// and frame_timing.h (timing table and the JSON line).
#include "view/viewer.h"

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "atrous/device.h"
#include "atrous/error.h"
#include "atrous/render.h"
#include "atrous/timer.h"
#include "atrous/io/image_io.h"
#include "view/buffer_view.h"
#include "view/camera_input.h"
#include "view/display.h"
#include "view/file_source.h"
#include "view/frame_timing.h"
#include "view/panel.h"
#include "view/stage_history.h"
#include "atrous/view_pipeline.h"
#include "view/window.h"
#include "view/write_result.h"

namespace atrous::view {
namespace {

// The flags that can be checked before a window opens (InputError names the flag), and the
// initial state they give.
ViewerState checkOptions(const ViewerOptions& opt) {
    ViewerState st;
    PipelineSettings& ps = st.ps;
    ps.methodA = parseMethod(opt.method);
    ps.split = !opt.compare.empty();
    if (ps.split) ps.methodB = parseMethod(opt.compare);
    ps.sppPerFrame = opt.render.spp;
    ps.maxDepth = opt.render.maxDepth;
    ps.accumulate = !opt.noAccumulate;
    ps.denoise = opt.denoise;
    ParamSet::bind(denoiseParams(), ps.denoise).validate();  // ParamError naming the field; main.cpp shows its flag
    for (const ParamSet& p : opt.sequence) {
        p.validate();  // ParamError naming the field; main.cpp shows its flag
        ps.sequence.push_back(p);
    }
    st.view = parseBufferView(opt.bufferView);
    if (opt.frames < 0) throw InputError("--frames: must be 0 (interactive) or more");
    if (!opt.screenshot.empty()) {
        if (opt.frames == 0) throw InputError("--screenshot needs --frames N (headless mode)");
        if (io::extensionOf(opt.screenshot) != ".png")
            throw InputError("--screenshot: " + opt.screenshot + " must end in .png");
        const std::filesystem::path parent = std::filesystem::path(opt.screenshot).parent_path();
        io::ensureWritableDirectory(parent.empty() ? "." : parent.string());
    }
    if (opt.writeImage && opt.frames == 0) throw InputError("--write-image needs --frames N (headless mode; interactively: the O key)");
    if (!opt.dumpDir.empty()) {
        if (opt.frames == 0) throw InputError("--dump needs --frames N (headless mode)");
        io::ensureWritableDirectory(opt.dumpDir);
    }
    if (!(opt.exposure > 0.0f)) throw InputError("--exposure: must be > 0");
    validateRenderSettings(opt.render);  // ParamError naming the field; main.cpp shows its flag
    st.exposure = opt.exposure;
    st.uiVisible = !opt.hideUi;
    return st;
}

// What this frame's step must compute: the debug buffers of the view, and whether anything reads
// the accumulated buffers (the EAW/SURE/none slots, every view but the result and motion, a
// snapshot or the final dump).
void prepareStep(PipelineSettings& ps, BufferView view, int level, bool snapshot, bool finalDump, Device device) {
    ps.detailLevel = view == BufferView::Detail ? level : -1;
    ps.sureFractions = view == BufferView::SureFractions;
    ps.needAccumulated = !ps.methodA.ownSamples() || (ps.split && !ps.methodB.ownSamples()) ||
                         !(view == BufferView::Result || view == BufferView::Motion) || snapshot || finalDump;
    // CUDA: results stay on the GPU; the host path downloads them only when it shows them
    // (resultHost), the interop path never.
    ps.deviceResults = device == Device::Cuda;
}

// F12 / P / the panel's button: every buffer and the window into OUT/snap_NNNN/. Returns the
// status line (also printed on stderr).
std::string saveSnapshot(const ViewPipeline& pl, const std::string& outDir, int index, int fbw, int fbh) {
    std::string status;
    try {
        char name[32];
        std::snprintf(name, sizeof(name), "snap_%04d", index);
        const std::string dir = (std::filesystem::path(outDir) / name).string();
        std::vector<std::string> files = pl.saveBuffers(dir);
        saveFramebuffer((std::filesystem::path(dir) / "screenshot.png").string(), fbw, fbh);
        status = "saved " + dir + " (" + std::to_string(files.size() + 1) + " files)";
    } catch (const std::exception& e) {
        status = std::string("snapshot failed: ") + e.what();
    }
    std::fprintf(stderr, "atrous view: %s\n", status.c_str());
    return status;
}

// What --scene, --in and --sequence open: a FileSource for a render (null for a scene). A render
// given where a scene is expected, or both at once, is refused with what to type instead.
std::unique_ptr<FileSource> openFiles(const ViewerOptions& opt) {
    const bool still = opt.input.any() && opt.sequenceInput.empty(), sequence = !opt.sequenceInput.empty();
    if (opt.sceneGiven && (still || sequence))
        throw InputError(std::string(still ? "--in" : "--sequence") + " and --scene: give one (--scene renders a scene, " +
                         (still ? "--in opens a render" : "--sequence opens a rendered sequence") + ")");
    if (!still && !sequence) {
        namespace fs = std::filesystem;
        const std::string ext = io::extensionOf(opt.scene);
        std::error_code ec;
        if (ext == ".exr" || ext == ".pfm" || ext == ".png" || ext == ".jpg" || ext == ".jpeg" || fs::is_directory(opt.scene, ec))
            throw InputError("--scene " + opt.scene + ": a render, not a scene: open it with --in " + opt.scene);
        return nullptr;
    }
    return std::make_unique<FileSource>(opt.input, opt.sequenceInput, opt.range);
}

// The O key, the panel's button and --write-image: the image and its command (write_result.h).
// Returns the status line; the command goes to stdout.
std::string writeImageAndCommand(const ViewPipeline& pl, const PipelineSettings& ps, const FileSource* files,
                                 const ViewerOptions& opt) {
    try {
        const WrittenResult w = writeResult(pl, ps, files, opt.device, opt.outDir);
        if (!w.command.empty()) std::printf("%s\n", w.command.c_str());
        std::fflush(stdout);
        std::fprintf(stderr, "atrous view: wrote %s, %s and %s%s\n", w.exr.c_str(), w.png.c_str(), w.txt.c_str(),
                     w.note.empty() ? "" : (" (" + w.note + ")").c_str());
        return "wrote " + w.exr + " (+ .png, .txt)" + (w.command.empty() ? ": " + w.note : ": command in the .txt");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "atrous view: write failed: %s\n", e.what());
        return std::string("write failed: ") + e.what();
    }
}

// A sequence's keys (Left/Right, Home/End) and the panel's frame slider: loads the frame asked for.
void stepFrames(ViewPipeline& pl, FileSource& files, int wanted, ViewerState& st) {
    if (!ImGui::GetIO().WantCaptureKeyboard) {
        if (ImGui::IsKeyPressed(GLFW_KEY_RIGHT, true)) wanted = files.current() + 1;
        if (ImGui::IsKeyPressed(GLFW_KEY_LEFT, true)) wanted = files.current() - 1;
        if (ImGui::IsKeyPressed(GLFW_KEY_HOME, false)) wanted = 0;
        if (ImGui::IsKeyPressed(GLFW_KEY_END, false)) wanted = files.frameCount() - 1;
    }
    wanted = std::clamp(wanted, 0, files.frameCount() - 1);
    if (wanted == files.current()) return;
    const int from = files.current();
    try {
        pl.setFrame(files.load(wanted), wanted == from + 1);
        st.status.clear();
    } catch (const InputError& e) {
        st.status = e.what();  // the frame stays; the message in the panel
        std::fprintf(stderr, "atrous view: %s\n", e.what());
    }
}

}  // namespace

void runViewer(const ViewerOptions& opt) {
    // Everything that can be checked before a window opens is checked first.
    const Device device = parseDevice(opt.device);  // "cuda" without a GPU: InputError
    ViewerState st = checkOptions(opt);
    PipelineSettings& ps = st.ps;
    std::unique_ptr<FileSource> files = openFiles(opt);  // InputError naming the file and the problem
    Scene scene = files ? Scene() : Scene::loadByNameOrFile(opt.scene);  // InputError naming the scene or file
    // A render's frame is read before the window opens: its errors end the command like a bad flag.
    std::unique_ptr<ViewPipeline> pipeline =
        files ? std::make_unique<ViewPipeline>(files->load(0), device)
              : std::make_unique<ViewPipeline>(scene, opt.render.width, opt.render.height, device, opt.render.seed);
    ViewPipeline& pl = *pipeline;
    const std::string name = files ? files->frameName(0) : scene.name();
    const bool headless = opt.frames > 0;

    GlfwSession session;
    const int w = pl.width(), h = pl.height();
    const int winW = opt.hideUi ? w : std::min(w, 1600) + int(kPanelWidth);
    const int winH = opt.hideUi ? h : std::max(std::min(h, 1000), 720);
    openWindow(session, winW, winH, "atrous view: " + (files ? files->title() : name), headless);
    GLFWwindow* win = session.window;
    const ImGuiIO& io = ImGui::GetIO();
    // A render's frame is shown from the host (the filters still run on `device`).
    FrameDisplay display(session, files ? Device::Cpu : device, w, h);

    CameraInput input;
    OrbitCamera orbit = orbitAroundScene(pl.camera(), pl);
    int snapCounter = 0;
    std::vector<FrameTiming> timings;
    StageHistory stageHistory(30);      // the panel's table: means over the last 30 frames
    StageHistory benchStages(1u << 20);  // the JSON line: medians over all frames but the first
    Timer frameTimer, sinceLastFrame;

    for (int frame = 0; !glfwWindowShouldClose(win); ++frame) {
        frameTimer.reset();
        const double cpuStart = processCpuMs();
        glfwPollEvents();
        const float dt = float(std::min(0.1, sinceLastFrame.seconds()));
        sinceLastFrame.reset();
        const bool last = headless && frame + 1 >= opt.frames;

        // ---- input: camera (only where ImGui does not want the mouse/keyboard), keys ----
        int fbw = 0, fbh = 0;
        glfwGetFramebufferSize(win, &fbw, &fbh);
        const ImageRect rect = imageRect(fbw, fbh, st.uiVisible, w, h);
        bool moved = !headless && !files && input.update(win, orbit, pl.sceneRadius(), rect.h, dt);
        if (files && headless) st.frameWanted = frame;  // headless: a sequence plays, one frame per frame
        if (files) stepFrames(pl, *files, st.frameWanted, st);
        if (files) st.frameWanted = files->current();
        if (opt.orbitDegPerFrame != 0.0f && !st.paused && frame > 0 && !files) {
            orbit.orbit(opt.orbitDegPerFrame * 3.14159265f / 180.0f, 0.0f);
            moved = true;
        }
        if (moved) pl.setCamera(orbit.camera());
        bool snapshot = ImGui::IsKeyPressed(GLFW_KEY_F12, false) ||
                        (!io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_P, false));
        bool write = !io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_O, false);
        if (!io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_TAB, false))
            st.uiVisible = !st.uiVisible;
        if (!io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false))
            glfwSetWindowShouldClose(win, 1);

        // ---- render, accumulate, denoise ----
        prepareStep(ps, st.view, st.level, snapshot, last && !opt.dumpDir.empty(), device);
        const bool doStep = !st.paused || moved || frame == 0;
        if (doStep) pl.step(ps);

        // ---- display image: every frame (exposure and the view can change while paused) ----
        Timer dispTimer;
        st.viewNote = display.update(pl, DisplaySettings{st.view, ps.split, st.splitPos, st.exposure, st.level});
        const double displayTime = dispTimer.ms();

        // ---- UI ----
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        drawImage(display.texture(), rect, st);
        PanelActions actions;
        if (st.uiVisible) {
            PanelInfo info;
            info.sceneName = files ? files->title() : name;
            info.frameCount = files ? files->frameCount() : 0;
            info.frame = frame;
            info.lastFrameMs = timings.empty() ? 0.0 : timings.back().frameMs;
            info.displayMs = displayTime;
            info.displayPath = display.path();
            info.outDir = opt.outDir;
            info.fbw = fbw, info.fbh = fbh;
            actions = drawPanel(st, input, pl, stageHistory, info);
        }
        snapshot = snapshot || actions.snapshot;
        write = write || actions.write;
        if (actions.resetCamera && !files) {
            orbit = orbitAroundScene(pl.sceneCamera(), pl);
            pl.setCamera(pl.sceneCamera());
        }
        ImGui::Render();
        glViewport(0, 0, fbw, fbh);
        glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

        // ---- snapshots, the headless run's files ----
        if (snapshot) st.status = saveSnapshot(pl, opt.outDir, ++snapCounter, fbw, fbh);
        if (write || (last && opt.writeImage)) st.status = writeImageAndCommand(pl, ps, files.get(), opt);
        if (last) {
            if (!opt.screenshot.empty()) saveFramebuffer(opt.screenshot, fbw, fbh);
            if (!opt.dumpDir.empty()) pl.saveBuffers(opt.dumpDir);
        }
        glfwSwapBuffers(win);

        // ---- timings ----
        FrameTiming ft;
        ft.frameMs = frameTimer.ms();
        ft.frameCpuMs = processCpuMs() - cpuStart;
        ft.displayMs = displayTime;
        ft.stages = pl.times();
        timings.push_back(ft);
        if (doStep && pl.stepFiltered()) {  // a loaded frame's step that filtered nothing is no sample
            const std::vector<StageTime> stages = frameStages(pl, ps.split, displayTime);
            stageHistory.add(stages);
            if (frame > 0 && (opt.benchmark || headless)) benchStages.add(stages);  // for the JSON line
        }
        if (last) break;
    }

    if (opt.benchmark || headless) {
        BenchmarkRun run;
        run.scene = name;
        run.width = w;
        run.height = h;
        run.settings = ps;
        run.device = device;
        run.display = display.path();
        std::printf("%s\n", benchmarkJson(run, timings, benchStages).c_str());
        std::fflush(stdout);
    }
}

}  // namespace atrous::view

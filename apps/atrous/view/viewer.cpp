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
#include "view/frame_timing.h"
#include "view/panel.h"
#include "view/stage_history.h"
#include "atrous/view_pipeline.h"
#include "view/window.h"

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

}  // namespace

void runViewer(const ViewerOptions& opt) {
    // Everything that can be checked before a window opens is checked first.
    const Device device = parseDevice(opt.device);  // "cuda" without a GPU: InputError
    ViewerState st = checkOptions(opt);
    PipelineSettings& ps = st.ps;
    Scene scene = Scene::loadByNameOrFile(opt.scene);  // InputError naming the scene or file
    const bool headless = opt.frames > 0;

    GlfwSession session;
    const int winW = opt.hideUi ? opt.render.width : opt.render.width + int(kPanelWidth);
    const int winH = opt.hideUi ? opt.render.height : std::max(opt.render.height, 720);
    openWindow(session, winW, winH, "atrous view: " + scene.name(), headless);
    GLFWwindow* win = session.window;
    const ImGuiIO& io = ImGui::GetIO();

    ViewPipeline pl(scene, opt.render.width, opt.render.height, device, opt.render.seed);
    const int w = opt.render.width, h = opt.render.height;
    FrameDisplay display(session, device, w, h);

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
        bool moved = !headless && input.update(win, orbit, pl.sceneRadius(), rect.h, dt);
        if (opt.orbitDegPerFrame != 0.0f && !st.paused && frame > 0) {
            orbit.orbit(opt.orbitDegPerFrame * 3.14159265f / 180.0f, 0.0f);
            moved = true;
        }
        if (moved) pl.setCamera(orbit.camera());
        bool snapshot = ImGui::IsKeyPressed(GLFW_KEY_F12, false) ||
                        (!io.WantCaptureKeyboard && ImGui::IsKeyPressed(GLFW_KEY_P, false));
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
            info.sceneName = scene.name();
            info.frame = frame;
            info.lastFrameMs = timings.empty() ? 0.0 : timings.back().frameMs;
            info.displayMs = displayTime;
            info.displayPath = display.path();
            info.outDir = opt.outDir;
            info.fbw = fbw, info.fbh = fbh;
            actions = drawPanel(st, input, pl, stageHistory, info);
        }
        snapshot = snapshot || actions.snapshot;
        if (actions.resetCamera) {
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
        if (doStep) {
            const std::vector<StageTime> stages = frameStages(pl, ps.split, displayTime);
            stageHistory.add(stages);
            if (frame > 0 && (opt.benchmark || headless)) benchStages.add(stages);  // for the JSON line
        }
        if (last) break;
    }

    if (opt.benchmark || headless) {
        BenchmarkRun run;
        run.scene = scene.name();
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

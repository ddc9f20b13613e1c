// The viewer's layout, image and control panel (panel.h).
#include "view/panel.h"

#include <imgui.h>

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "atrous/device.h"

namespace atrous::view {
namespace {

const char* const kMethodNames[] = {"none", "eaw", "sure", "svgf"};

bool comboMethod(const char* label, Method& m) {
    int i = int(m);
    const bool changed = ImGui::Combo(label, &i, kMethodNames, 4);
    m = Method(i);
    return changed;
}

// The timing table: stage, mean ms, and a bar of its share of the frame.
void stageTable(const StageHistory& h) {
    double total = 0;
    for (size_t i = 0; i < h.size(); ++i) total += h.mean(i);
    if (!ImGui::BeginTable("stages", 3, ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_RowBg)) return;
    ImGui::TableSetupColumn("stage", ImGuiTableColumnFlags_WidthFixed, 120.0f);
    ImGui::TableSetupColumn("ms", ImGuiTableColumnFlags_WidthFixed, 52.0f);
    ImGui::TableSetupColumn("share", ImGuiTableColumnFlags_WidthStretch);
    ImGui::TableHeadersRow();
    const float barH = ImGui::GetTextLineHeight() * 0.8f;
    for (size_t i = 0; i < h.size(); ++i) {
        const double ms = h.mean(i);
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(h.name(i).c_str());
        ImGui::TableNextColumn();
        ImGui::Text("%6.2f", ms);
        ImGui::TableNextColumn();
        ImGui::ProgressBar(total > 0 ? float(ms / total) : 0.0f, ImVec2(-1.0f, barH), "");
    }
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted("sum");
    ImGui::TableNextColumn();
    ImGui::Text("%6.2f", total);
    ImGui::EndTable();
}

// Scene, frame and stage times, the display path, the timing table.
void statusSection(const ViewPipeline& pl, const StageHistory& history, const PanelInfo& info) {
    const StageTimes& t = pl.times();
    const double lastMs = info.lastFrameMs;
    ImGui::Text("%s  %dx%d  %s", info.sceneName.c_str(), pl.width(), pl.height(), deviceToString(pl.device()));
    ImGui::Text("frame %d   %d spp   %.1f ms (%.1f fps)", info.frame + 1, pl.samplesPerPixel(),
                lastMs, lastMs > 0 ? 1000.0 / lastMs : 0.0);
    ImGui::Text("render %.1f  accum %.1f  motion %.1f ms", t.render, t.accumulate,
                t.motion);
    ImGui::Text("filter A %.1f (%s %.1f)  B %.1f ms", t.denoiseA,
                methodName(pl.slot(0).method), pl.slot(0).filterMs, t.denoiseB);
    ImGui::Text("debug views %.1f  display %.1f ms", t.debug, info.displayMs);
    ImGui::TextWrapped("display: %s", info.displayPath.c_str());
    if (ImGui::CollapsingHeader("Timing (ms, mean of last 30 frames)", ImGuiTreeNodeFlags_DefaultOpen))
        stageTable(history);
}

// Samples, depth, accumulation, pause, exposure, camera.
void renderSection(ViewerState& st, CameraInput& input, ViewPipeline& pl, PanelActions& a) {
    PipelineSettings& ps = st.ps;
    if (ImGui::SliderInt("spp / frame", &ps.sppPerFrame, 1, 64)) pl.resetAccumulation();
    if (ImGui::SliderInt("max depth", &ps.maxDepth, 0, 32)) pl.resetAccumulation();
    if (ImGui::Checkbox("accumulate", &ps.accumulate)) pl.resetAccumulation();
    ImGui::SameLine();
    ImGui::Checkbox("pause", &st.paused);
    ImGui::SameLine();
    if (ImGui::Button("restart")) pl.resetAccumulation();
    ImGui::SliderFloat("exposure", &st.exposure, 0.05f, 16.0f, "%.2f",
                       ImGuiSliderFlags_Logarithmic);
    ImGui::SliderFloat("move speed", &input.moveSpeed, 0.05f, 4.0f, "%.2f",
                       ImGuiSliderFlags_Logarithmic);
    if (ImGui::Button("reset camera")) a.resetCamera = true;
    ImGui::TextDisabled(
        "drag: left orbit, right/middle pan\nwheel zoom, WASD move, Q/E down/up");
}

// Methods A and B, the split, the buffer view and its level, the view's note, the slots' errors.
void methodSection(ViewerState& st, const ViewPipeline& pl) {
    PipelineSettings& ps = st.ps;
    comboMethod("method A", ps.methodA);
    ImGui::Checkbox("split screen", &ps.split);
    if (ps.split) {
        comboMethod("method B", ps.methodB);
        ImGui::SliderFloat("split", &st.splitPos, 0.0f, 1.0f);
    }
    int v = int(st.view);
    ImGui::Combo("buffer", &v, kViewNames, kViewCount);
    st.view = BufferView(v);
    if (st.view == BufferView::Detail || st.view == BufferView::SureFractions)
        ImGui::SliderInt("level i", &st.level, 0, std::max(0, ps.eaw.levels - 1));
    if (!st.viewNote.empty()) ImGui::TextWrapped("%s", st.viewNote.c_str());
    for (int i = 0; i < 2; ++i)
        if (!pl.slot(i).error.empty())
            ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s: %s", i ? "B" : "A",
                               pl.slot(i).error.c_str());
}

void eawSection(PipelineSettings& ps) {
    if (ImGui::CollapsingHeader("EAW (also SURE's cascade)",
                                ImGuiTreeNodeFlags_DefaultOpen)) {
        EawParams& e = ps.eaw;
        ImGui::SliderInt("levels", &e.levels, 1, 10);
        ImGui::DragFloat("sigma color (0=auto)", &e.sigmaColor, 0.01f, 0.0f, 100.0f);
        ImGui::DragFloat("color scale k_c", &e.colorScale, 0.02f, 0.01f, 20.0f);
        ImGui::SliderFloat("color level factor", &e.colorLevelFactor, 0.05f, 1.0f);
        ImGui::DragFloat("sigma normal (0=off)", &e.sigmaNormal, 0.01f, 0.0f, 10.0f);
        ImGui::Checkbox("normal / step^2", &e.normalStepScale);
        ImGui::DragFloat("sigma position (0=auto)", &e.sigmaPosition, 0.01f, 0.0f, 100.0f);
        ImGui::DragFloat("position scale k_x", &e.positionScale, 0.02f, 0.01f, 20.0f);
        ImGui::DragFloat("sigma depth (0=off)", &e.sigmaDepth, 0.005f, 0.0f, 10.0f);
        ImGui::Checkbox("id edge stop", &e.useIds);
    }
}

void sureSection(ViewerState& st) {
    PipelineSettings& ps = st.ps;
    if (ImGui::CollapsingHeader("SURE")) {
        int mode = int(ps.sure.mode);
        const char* modes[] = {"discrete", "james-stein"};
        ImGui::Combo("mode", &mode, modes, 2);
        ps.sure.mode = SureMode(mode);
        if (ImGui::InputText("candidates", st.candidatesText, sizeof(st.candidatesText))) {
            std::vector<float> c;
            std::stringstream ss(st.candidatesText);
            std::string item;
            bool ok = true;
            while (std::getline(ss, item, ',')) {
                try {
                    c.push_back(std::stof(item));
                } catch (...) {
                    ok = false;
                }
            }
            if (ok && !c.empty())
                ps.sure.candidates = c;  // range errors surface as the slot's error
        }
        ImGui::SliderInt("window radius", &ps.sure.windowRadius, 1, 10);
        ImGui::Checkbox("correlated variance", &ps.sure.correlatedVariance);
    }
}

void fireflySection(PipelineSettings& ps) {
    if (ImGui::CollapsingHeader("Firefly / demodulation")) {
        ImGui::Checkbox("firefly suppression", &ps.firefly.enabled);
        ImGui::DragFloat("firefly k", &ps.firefly.k, 0.05f, 0.1f, 50.0f);
        ImGui::Checkbox("demodulate albedo", &ps.demodulate);
        ImGui::DragFloat("albedo epsilon", &ps.albedoEpsilon, 1e-4f, 1e-6f, 1.0f, "%.5f");
    }
}

void svgfSection(PipelineSettings& ps) {
    if (ImGui::CollapsingHeader("SVGF")) {
        SvgfParams& p = ps.svgf;
        ImGui::DragFloat("sigma_l", &p.sigmaL, 0.05f, 0.0f, 100.0f);
        ImGui::DragFloat("sigma_n", &p.sigmaN, 1.0f, 0.0f, 1024.0f);
        ImGui::DragFloat("sigma_z", &p.sigmaZ, 0.02f, 0.0f, 100.0f);
        ImGui::SliderFloat("alpha", &p.alpha, 0.01f, 1.0f);
        ImGui::SliderFloat("moments alpha", &p.momentsAlpha, 0.01f, 1.0f);
        ImGui::SliderInt("history cap", &p.historyCap, 1, 256);
        ImGui::SliderInt("svgf levels", &p.levels, 0, 10);
        ImGui::SliderInt("feedback tap", &p.feedbackTap, -1, std::max(-1, p.levels - 1));
        ImGui::SliderInt("spatial variance frames", &p.spatialVarianceFrames, 1, 32);
        ImGui::DragFloat("reproject depth tol", &p.reprojectDepthTolerance, 0.05f, 0.0f,
                         100.0f);
        ImGui::SliderFloat("reproject normal cos", &p.reprojectNormalCos, -1.0f, 1.0f);
        ImGui::Checkbox("TAA", &p.taa);
        ImGui::SliderFloat("TAA alpha", &p.taaAlpha, 0.01f, 1.0f);
        ImGui::Checkbox("motion vectors on camera move", &ps.svgfMotionVectors);
        ImGui::TextDisabled(ps.svgfMotionVectors ? "(history reprojected)"
                                                 : "(history reset on move)");
    }
}

}  // namespace

ImageRect imageRect(int fbw, int fbh, bool panelVisible, int imageWidth, int imageHeight) {
    const float w = float(imageWidth), h = float(imageHeight);
    const float areaW = panelVisible ? std::max(1.0f, float(fbw) - kPanelWidth) : float(fbw);
    const float areaH = float(fbh);
    const float scale = std::min(areaW / w, areaH / h);
    ImageRect r;
    r.w = w * scale, r.h = h * scale;
    r.x = 0.5f * (areaW - r.w), r.y = 0.5f * (areaH - r.h);
    return r;
}

void drawImage(unsigned texture, const ImageRect& r, const ViewerState& st) {
    ImDrawList* bg = ImGui::GetBackgroundDrawList();
    bg->AddImage((ImTextureID)(intptr_t)texture, ImVec2(r.x, r.y), ImVec2(r.x + r.w, r.y + r.h));
    if (st.view == BufferView::Result && st.ps.split) {
        const float xs = r.x + st.splitPos * r.w;
        bg->AddLine(ImVec2(xs, r.y), ImVec2(xs, r.y + r.h), IM_COL32(255, 255, 255, 200), 1.0f);
        if (st.uiVisible) {
            bg->AddText(ImVec2(r.x + 6, r.y + 4), IM_COL32(255, 255, 255, 230), methodName(st.ps.methodA));
            bg->AddText(ImVec2(xs + 6, r.y + 4), IM_COL32(255, 255, 255, 230), methodName(st.ps.methodB));
        }
    }
}

PanelActions drawPanel(ViewerState& st, CameraInput& input, ViewPipeline& pl, const StageHistory& history,
                       const PanelInfo& info) {
    PanelActions a;
    ImGui::SetNextWindowPos(ImVec2(float(info.fbw) - kPanelWidth, 0), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(kPanelWidth, float(info.fbh)), ImGuiCond_Always);
    ImGui::Begin(
        "atrous view", nullptr,
        ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    ImGui::PushItemWidth(150.0f);  // leaves the labels their room
    statusSection(pl, history, info);
    ImGui::Separator();
    renderSection(st, input, pl, a);
    ImGui::Separator();
    methodSection(st, pl);
    eawSection(st.ps);
    sureSection(st);
    fireflySection(st.ps);
    svgfSection(st.ps);
    ImGui::Separator();
    if (ImGui::Button("save snapshot (F12 / P)")) a.snapshot = true;
    ImGui::TextDisabled("to %s/snap_NNNN/", info.outDir.c_str());
    if (!st.status.empty()) ImGui::TextWrapped("%s", st.status.c_str());
    ImGui::TextDisabled("Tab hides this panel, Esc quits");
    ImGui::PopItemWidth();
    ImGui::End();
    return a;
}

}  // namespace atrous::view

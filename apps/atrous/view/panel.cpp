// The viewer's layout, image and control panel (panel.h).
#include "view/panel.h"

#include <imgui.h>

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "atrous/device.h"
#include "atrous/param_set.h"
#include "atrous/params.h"
#include "atrous/sequence_methods.h"
#include "atrous/render.h"

namespace atrous::view {
namespace {

// The library's methods (view::methodNames()) in a combo box.
bool comboMethod(const char* label, Method& m) {
    const std::vector<std::string> names = methodNames();
    std::vector<const char*> items;
    int i = 0;
    for (const std::string& n : names) {
        if (n == methodName(m)) i = int(items.size());
        items.push_back(n.c_str());
    }
    const bool changed = ImGui::Combo(label, &i, items.data(), int(items.size()));
    if (changed) m = parseMethod(names[size_t(i)]);
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
    ImGui::TextWrapped("%s  %dx%d  %s", info.sceneName.c_str(), pl.width(), pl.height(), deviceToString(pl.device()));
    if (pl.fromFiles()) {
        ImGui::Text("read from files   %.1f ms (%.1f fps)", lastMs, lastMs > 0 ? 1000.0 / lastMs : 0.0);
    } else {
        ImGui::Text("frame %d   %d spp   %.1f ms (%.1f fps)", info.frame + 1, pl.samplesPerPixel(), lastMs,
                    lastMs > 0 ? 1000.0 / lastMs : 0.0);
        ImGui::Text("render %.1f  accum %.1f  motion %.1f ms", t.render, t.accumulate, t.motion);
    }
    ImGui::Text("filter A %.1f (%s %.1f)  B %.1f ms", t.denoiseA,
                methodName(pl.slot(0).method), pl.slot(0).filterMs, t.denoiseB);
    ImGui::Text("debug views %.1f  display %.1f ms", t.debug, info.displayMs);
    ImGui::TextWrapped("display: %s", info.displayPath.c_str());
    if (ImGui::CollapsingHeader("Timing (ms, mean of last 30 frames)", ImGuiTreeNodeFlags_DefaultOpen))
        stageTable(history);
}

// One control per row of a parameter table (params.h), labelled with the row's name, its doc
// line as the tooltip, limited to its range; the drag speed of a float follows its default (row i
// of `defaults`). Out-of-range values the drags can still reach (the open end of (0, 1]) and
// cross-field rules surface as the slot's error.
void paramControl(ParamSet& s, size_t i, const ParamSet& defaults, ViewerState& st) {
    const ParamRow& f = s.rows()[i];
    const ParamRef r = s.at(i);
    const auto finite = [](double v, float inf) { return std::isinf(v) ? inf : float(v); };
    if (int* const* n = std::get_if<int*>(&r)) {
        const int lo = int(f.range.lo), hi = std::isinf(f.range.hi) ? INT_MAX : int(f.range.hi);
        if (hi - lo <= 64)
            ImGui::SliderInt(f.name, *n, lo, hi);
        else
            ImGui::DragInt(f.name, *n, 0.2f, lo, hi);
    } else if (float* const* x = std::get_if<float*>(&r)) {
        const float d = *std::get<float*>(defaults.at(i));
        const float speed = std::max(std::fabs(d), 0.01f) * 0.01f;
        ImGui::DragFloat(f.name, *x, speed, f.range.zero ? 0.0f : finite(f.range.lo, -FLT_MAX), finite(f.range.hi, FLT_MAX),
                         "%.4g");
    } else if (bool* const* b = std::get_if<bool*>(&r)) {
        ImGui::Checkbox(f.name, *b);
    } else if (SureMode* const* m = std::get_if<SureMode*>(&r)) {
        int n = 0, v = int(**m);
        while (f.choices[n]) ++n;
        if (ImGui::Combo(f.name, &v, f.choices, n)) **m = SureMode(v);
    } else if (ImGui::InputText(f.name, st.candidatesText, sizeof(st.candidatesText))) {
        try {
            s.setText(i, st.candidatesText);
        } catch (const ParamError&) {
            // half-typed: keep the last list that parsed
        }
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", f.doc);
}
template <class S>
void paramControl(S& s, const ParamTable<S>& t, const ParamField<S>& f, ViewerState& st) {
    static const ParamSet defaults(t);
    ParamSet set = ParamSet::bind(t, s);
    paramControl(set, size_t(&f - t.first), defaults, st);
}

// Samples, depth, accumulation, pause, exposure, camera.
void renderSection(ViewerState& st, CameraInput& input, ViewPipeline& pl, PanelActions& a) {
    PipelineSettings& ps = st.ps;
    // spp (per frame) and max_depth: the render table's rows (name, doc line, range).
    RenderSettings rs;
    rs.spp = ps.sppPerFrame;
    rs.maxDepth = ps.maxDepth;
    for (const char* name : {"spp", "max_depth"}) paramControl(rs, renderParams(), *renderParams().find(name), st);
    if (rs.spp != ps.sppPerFrame || rs.maxDepth != ps.maxDepth) {
        ps.sppPerFrame = rs.spp;
        ps.maxDepth = rs.maxDepth;
        pl.resetAccumulation();
    }
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

// A render read from files: its frame (a sequence's slider and buttons, keys Left/Right/Home/End),
// the exposure, and filtering again.
void fileSection(ViewerState& st, ViewPipeline& pl, const PanelInfo& info) {
    if (info.frameCount > 1) {
        int k = st.frameWanted + 1;
        if (ImGui::SliderInt("frame", &k, 1, info.frameCount)) st.frameWanted = k - 1;
        if (ImGui::Button("< prev")) st.frameWanted = std::max(0, st.frameWanted - 1);
        ImGui::SameLine();
        if (ImGui::Button("next >")) st.frameWanted = std::min(info.frameCount - 1, st.frameWanted + 1);
        ImGui::TextDisabled("Left/Right: previous/next frame, Home/End");
    }
    ImGui::SliderFloat("exposure", &st.exposure, 0.05f, 16.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
    if (ImGui::Button("filter again")) pl.resetAccumulation();
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
        ImGui::SliderInt("level i", &st.level, 0, std::max(0, ps.denoise.eaw.levels - 1));
    if (!st.viewNote.empty()) ImGui::TextWrapped("%s", st.viewNote.c_str());
    for (int i = 0; i < 2; ++i)
        if (!pl.slot(i).error.empty())
            ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s: %s", i ? "B" : "A",
                               pl.slot(i).error.c_str());
}

// The still parameters of one group (denoiseParams()' `group`) under a collapsing header: its title.
void paramSection(const std::string& group, DenoiseOptions& s, ViewerState& st, ImGuiTreeNodeFlags flags = 0) {
    const std::string header = denoiseGroupTitle(group);
    if (!ImGui::CollapsingHeader(header.c_str(), flags)) return;
    ImGui::PushID(header.c_str());  // "levels" is a row of two tables
    for (const ParamField<DenoiseOptions>& f : denoiseParams())
        if (group == f.group) paramControl(s, denoiseParams(), f, st);
    ImGui::PopID();
}

// Every row of a set under a collapsing header (a sequence method's table).
void paramSection(const char* header, ParamSet& s, const ParamSet& defaults, ViewerState& st) {
    if (!ImGui::CollapsingHeader(header)) return;
    ImGui::PushID(header);
    for (size_t i = 0; i < s.rows().size(); ++i) paramControl(s, i, defaults, st);
    ImGui::PopID();
}

void filterSections(ViewerState& st) {
    PipelineSettings& ps = st.ps;
    // One section per group of the still parameters, in the table's order (the first open).
    std::vector<std::string> groups;
    for (const ParamField<DenoiseOptions>& f : denoiseParams())
        if (std::find(groups.begin(), groups.end(), std::string(f.group)) == groups.end()) groups.push_back(f.group);
    for (size_t i = 0; i < groups.size(); ++i) paramSection(groups[i], ps.denoise, st, i == 0 ? ImGuiTreeNodeFlags_DefaultOpen : 0);
    // Each sequence method the viewer runs, its table's rows.
    for (const SequenceMethodInfo& m : sequenceMethods()) {
        ParamSet& p = sequenceParams(ps, m);
        if ((m.causal || m.causalMode) && !p.empty()) paramSection(m.label, p, m.params, st);
    }
    if (ImGui::CollapsingHeader("Sequence methods on camera motion")) {
        ImGui::Checkbox("motion vectors on camera move", &ps.sequenceMotionVectors);
        ImGui::TextDisabled(ps.sequenceMotionVectors ? "(history reprojected)" : "(history reset on move)");
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
    if (pl.fromFiles())
        fileSection(st, pl, info);
    else
        renderSection(st, input, pl, a);
    ImGui::Separator();
    methodSection(st, pl);
    filterSections(st);
    ImGui::Separator();
    if (ImGui::Button("save snapshot (F12 / P)")) a.snapshot = true;
    ImGui::TextDisabled("to %s/snap_NNNN/", info.outDir.c_str());
    if (ImGui::Button("write image + command (O)")) a.write = true;
    ImGui::TextDisabled("to %s/view_NNNN.exr/.png/.txt", info.outDir.c_str());
    if (!st.status.empty()) ImGui::TextWrapped("%s", st.status.c_str());
    ImGui::TextDisabled("Tab hides this panel, Esc quits");
    ImGui::PopItemWidth();
    ImGui::End();
    return a;
}

}  // namespace atrous::view

// The viewer's on-screen parts drawn with Dear ImGui: the layout (image area beside the control
// panel), the image with the split line, and the control panel (status and timing table, render
// and camera controls, method and buffer choice, each filter's parameters, snapshots). What the
// panel edits lives in ViewerState; what it only shows comes in PanelInfo.
#pragma once
#include <string>

#include "view/buffer_view.h"
#include "view/camera_input.h"
#include "view/stage_history.h"
#include "atrous/view_pipeline.h"

namespace atrous::view {

constexpr float kPanelWidth = 360.0f;  // the control panel, at the window's right edge

// What the user changes between frames (panel controls, keys, flags).
struct ViewerState {
    PipelineSettings ps;
    BufferView view = BufferView::Result;
    float exposure = 1.0f;
    float splitPos = 0.5f;  // the split line, in [0, 1] of the image width
    int level = 0;          // of the per-level buffer views
    bool paused = false;
    int frameWanted = 0;    // a sequence's frame to show (0-based; the slider and keys set it)
    bool uiVisible = true;
    char candidatesText[128] = "0,0.2,0.4,0.6,0.8,1";  // SURE's candidates as typed
    std::string status;    // the last snapshot's or write's outcome
    std::string viewNote;  // why the buffer view shows nothing (from the display)
};

// Where the image is drawn: the window's framebuffer less the panel (when shown), the image
// scaled to fit it and centred.
struct ImageRect {
    float x = 0, y = 0, w = 0, h = 0;
};
ImageRect imageRect(int fbw, int fbh, bool panelVisible, int imageWidth, int imageHeight);

// Draws the display texture into `r` on ImGui's background, with the split line and (when the
// panel is shown) the two methods' names in the split-screen result view. Between NewFrame and
// Render.
void drawImage(unsigned texture, const ImageRect& r, const ViewerState& st);

// What the panel shows but does not change.
struct PanelInfo {
    std::string sceneName;    // or the render's file or folder (its frame in a sequence)
    int frameCount = 0;       // a render: its frames (1 for a still); 0 for a scene
    int frame = 0;            // 0-based
    double lastFrameMs = 0;   // the previous frame's wall clock (0 before the first)
    double displayMs = 0;     // this frame's display update
    std::string displayPath;  // FrameDisplay::path()
    std::string outDir;       // where snapshots go
    int fbw = 0, fbh = 0;     // the framebuffer's size
};

// What the user asked for with the panel's buttons.
struct PanelActions {
    bool resetCamera = false;
    bool snapshot = false;
    bool write = false;  // the image and its `atrous denoise` command (write_result.h)
};

// Draws the control panel (between NewFrame and Render). A change of spp, depth or accumulation
// restarts the pipeline's accumulation.
PanelActions drawPanel(ViewerState& st, CameraInput& input, ViewPipeline& pl, const StageHistory& history,
                       const PanelInfo& info);

}  // namespace atrous::view

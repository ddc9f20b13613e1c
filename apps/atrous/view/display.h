// How a frame reaches the window: the display texture (width x height RGBA8, drawn by ImGui as a
// textured quad), filled either by the host upload (tonemap on the CPU, buffer_view.h, then
// glTexSubImage2D from host memory) or, with --device cuda, by the CUDA-OpenGL interop path
// (cuda_display.h: a kernel tonemaps the GPU result into a registered pixel unpack buffer, and GL
// copies that into the texture). Any interop failure keeps or falls back to the host upload, and
// path() says why.
#pragma once
#include <string>
#include <vector>

#include "atrous/device.h"
#include "view/buffer_view.h"
#include "atrous/view_pipeline.h"
#include "view/window.h"

namespace atrous::view {

// What the display shows this frame.
struct DisplaySettings {
    BufferView view = BufferView::Result;
    bool split = false;      // split screen: the result view shows A left of splitPos, B right
    float splitPos = 0.5f;   // in [0, 1] of the width
    float exposure = 1.0f;
    int level = 0;           // of the per-level views
};

class FrameDisplay {
  public:
    // Creates the texture in `session` (its GL context current) and, on Device::Cuda, the pixel
    // unpack buffer registered with CUDA; both stay owned by the session.
    FrameDisplay(GlfwSession& session, Device device, int width, int height);

    // Fills the texture from the pipeline's last step. Returns the view's note for the panel
    // ("" when it has something to show).
    std::string update(const ViewPipeline& pl, const DisplaySettings& d);

    GLuint texture() const { return mSession.texture; }
    // "host upload", "CUDA-OpenGL interop (PBO)", or the host upload with why there is no interop.
    const std::string& path() const { return mPath; }

  private:
    GlfwSession& mSession;
    int mWidth, mHeight;
    std::vector<unsigned char> mRgba;  // the host upload's image
    std::string mPath = "host upload";
};

}  // namespace atrous::view

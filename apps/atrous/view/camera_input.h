// The viewer's camera control from the mouse and keyboard, where ImGui does not want them: left
// drag orbits, right or middle drag pans, the wheel zooms, W/S/A/D move forward, back, right and
// left, E/Q up and down (docs/viewer.md). No drawing.
#pragma once
#include <GLFW/glfw3.h>

#include "atrous/camera.h"
#include "atrous/view_pipeline.h"

namespace atrous::view {

// The orbit camera at camera `c`, turning about the point in front of it at the depth of the
// scene's centre (at least a tenth of the scene's radius away).
OrbitCamera orbitAroundScene(const pt::Camera& c, const ViewPipeline& pl);

class CameraInput {
  public:
    float moveSpeed = 0.5f;  // W/S/A/D/Q/E: scene radii per second (the panel's "move speed")

    // Applies this frame's input (ImGui's, read at its last NewFrame, and the keys held in `win`)
    // to `orbit`; true when the camera moved. `imageHeight`: the image's height on screen (pixels),
    // which scales the pan; `dt`: seconds since the last frame.
    bool update(GLFWwindow* win, OrbitCamera& orbit, float sceneRadius, float imageHeight, float dt);

  private:
    bool mDragging[3] = {false, false, false};  // left, right, middle button drags that began on the image
};

}  // namespace atrous::view

// Mouse and keyboard camera control (camera_input.h).
#include "view/camera_input.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>

namespace atrous::view {

OrbitCamera orbitAroundScene(const pt::Camera& c, const ViewPipeline& pl) {
    return OrbitCamera::fromCamera(c, std::max(0.1f * pl.sceneRadius(), dot(pl.sceneCenter() - c.position, c.forward)));
}

bool CameraInput::update(GLFWwindow* win, OrbitCamera& orbit, float sceneRadius, float imageHeight, float dt) {
    const ImGuiIO& io = ImGui::GetIO();
    bool moved = false;
    const pt::Camera cam = orbit.camera();
    for (int b = 0; b < 3; ++b) {
        if (ImGui::IsMouseClicked(b) && !io.WantCaptureMouse) mDragging[b] = true;
        if (!io.MouseDown[b]) mDragging[b] = false;
    }
    const ImVec2 d = io.MouseDelta;
    if (mDragging[0] && (d.x != 0 || d.y != 0)) {  // left: orbit
        orbit.orbit(-d.x * 0.01f, d.y * 0.01f);
        moved = true;
    }
    if ((mDragging[1] || mDragging[2]) && (d.x != 0 || d.y != 0)) {  // right / middle: pan
        const float k = 2.0f * orbit.distance * orbit.tanHalfFov / std::max(1.0f, imageHeight);
        orbit.pan(cam, -d.x * k, d.y * k, 0.0f);
        moved = true;
    }
    if (!io.WantCaptureMouse && io.MouseWheel != 0.0f) {  // wheel: zoom
        orbit.zoom(std::pow(0.9f, io.MouseWheel));
        moved = true;
    }
    if (!io.WantCaptureKeyboard) {
        const float step = moveSpeed * sceneRadius * dt;
        float f = 0, r = 0, u = 0;
        if (glfwGetKey(win, GLFW_KEY_W) == GLFW_PRESS) f += step;
        if (glfwGetKey(win, GLFW_KEY_S) == GLFW_PRESS) f -= step;
        if (glfwGetKey(win, GLFW_KEY_D) == GLFW_PRESS) r += step;
        if (glfwGetKey(win, GLFW_KEY_A) == GLFW_PRESS) r -= step;
        if (glfwGetKey(win, GLFW_KEY_E) == GLFW_PRESS) u += step;
        if (glfwGetKey(win, GLFW_KEY_Q) == GLFW_PRESS) u -= step;
        if (f != 0 || r != 0 || u != 0) {
            orbit.pan(cam, r, u, f);
            moved = true;
        }
    }
    return moved;
}

}  // namespace atrous::view

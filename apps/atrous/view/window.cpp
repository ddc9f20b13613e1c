// The viewer's window and its teardown, framebuffer screenshots (window.h).
#include "view/window.h"

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <vector>

#include "atrous/error.h"
#include "atrous/image.h"
#include "atrous/io/image_io.h"
#include "view/buffer_view.h"

namespace atrous::view {
namespace {

std::string glfwErrorText;
void glfwErrorCallback(int code, const char* description) {
    glfwErrorText = std::string(description ? description : "unknown") + " (GLFW error " +
                    std::to_string(code) + ")";
}

}  // namespace

GlfwSession::~GlfwSession() {
    interop.reset();  // unregister while the context and the buffer still exist
    if (pbo) gl.deleteBuffers(1, &pbo);
    if (texture) glDeleteTextures(1, &texture);
    if (imgui) {
        ImGui_ImplOpenGL3_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
    }
    if (window) glfwDestroyWindow(window);
    glfwTerminate();
}

void openWindow(GlfwSession& session, int winW, int winH, const std::string& title, bool headless) {
    glfwSetErrorCallback(glfwErrorCallback);
    if (!glfwInit())
        throw InputError(
            "view: cannot open a window: " + glfwErrorText +
            ". No display? Run it under a virtual X server: xvfb-run -a atrous view ... --frames N "
            "--screenshot out.png (headless mode)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, headless ? GLFW_FALSE : GLFW_TRUE);
    session.window = glfwCreateWindow(winW, winH, title.c_str(), nullptr, nullptr);
    if (!session.window)
        throw InputError(
            "view: cannot create an OpenGL 3.3 core context: " + glfwErrorText +
            " (try xvfb-run -a, or LIBGL_ALWAYS_SOFTWARE=1 for Mesa's software renderer)");
    GLFWwindow* win = session.window;
    glfwMakeContextCurrent(win);
    glfwSwapInterval(headless ? 0 : 1);

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // no imgui.ini litter in the working directory
    ImGui::StyleColorsDark();
    if (!ImGui_ImplGlfw_InitForOpenGL(win, true) || !ImGui_ImplOpenGL3_Init("#version 330 core")) {
        ImGui::DestroyContext();
        throw InputError("view: cannot initialise Dear ImGui's OpenGL 3 backend");
    }
    session.imgui = true;
}

void saveFramebuffer(const std::string& path, int fbw, int fbh) {
    std::vector<unsigned char> px(size_t(fbw) * fbh * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, fbw, fbh, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
    // writePng encodes linear -> sRGB; decode the 8-bit sRGB values first (the round trip is exact
    // at 8 bits) so the saved file is the framebuffer.
    Image img(fbw, fbh, 3);
    const SrgbLut& L = lut();
    for (int y = 0; y < fbh; ++y)
        for (int x = 0; x < fbw; ++x) {
            const unsigned char* p =
                &px[(size_t(fbh - 1 - y) * fbw + x) * 4];  // GL rows are bottom-up
            for (int c = 0; c < 3; ++c) img(x, y, c) = L.dec[p[c]];
        }
    io::writePng(path, img, 1.0f);
}

}  // namespace atrous::view

// The viewer's window: GLFW, an OpenGL 3.3 core context and Dear ImGui, held by one session object
// that also owns the display's GL objects (display.h) and tears everything down in order; and the
// window framebuffer saved as a PNG (screenshots, snapshots).
#pragma once
#include <GLFW/glfw3.h>
// After GLFW's <GL/gl.h>: the buffer-object types and enums (PFNGLGENBUFFERSPROC, ...).
#include <GL/glext.h>

#include <memory>
#include <string>

#include "view/cuda_display.h"

namespace atrous::view {

// The GL 1.5 buffer-object entry points of the interop path (not exported by every libGL).
struct GlBufferFunctions {
    PFNGLGENBUFFERSPROC genBuffers = nullptr;
    PFNGLDELETEBUFFERSPROC deleteBuffers = nullptr;
    PFNGLBINDBUFFERPROC bindBuffer = nullptr;
    PFNGLBUFFERDATAPROC bufferData = nullptr;
    bool load() {
        genBuffers = reinterpret_cast<PFNGLGENBUFFERSPROC>(glfwGetProcAddress("glGenBuffers"));
        deleteBuffers = reinterpret_cast<PFNGLDELETEBUFFERSPROC>(glfwGetProcAddress("glDeleteBuffers"));
        bindBuffer = reinterpret_cast<PFNGLBINDBUFFERPROC>(glfwGetProcAddress("glBindBuffer"));
        bufferData = reinterpret_cast<PFNGLBUFFERDATAPROC>(glfwGetProcAddress("glBufferData"));
        return genBuffers && deleteBuffers && bindBuffer && bufferData;
    }
};

struct GlfwSession {
    GLFWwindow* window = nullptr;
    bool imgui = false;
    GLuint texture = 0;
    GlBufferFunctions gl;
    GLuint pbo = 0;                          // pixel unpack buffer of the CUDA interop path
    std::unique_ptr<CudaGlDisplay> interop;  // null: host upload
    GlfwSession() = default;
    GlfwSession(const GlfwSession&) = delete;
    GlfwSession& operator=(const GlfwSession&) = delete;
    ~GlfwSession();  // in this order: interop, buffer, texture, ImGui, window, GLFW
};

// Opens a winW x winH window titled `title` with a current OpenGL 3.3 core context (vsync unless
// headless, not resizable when headless) and initialises Dear ImGui's GLFW and OpenGL 3 backends
// (no imgui.ini). Throws InputError when there is no display, no such context or no backend.
void openWindow(GlfwSession& session, int winW, int winH, const std::string& title, bool headless);

// Writes the window's back buffer (fbw x fbh) to the PNG `path`, as the framebuffer shows it.
void saveFramebuffer(const std::string& path, int fbw, int fbh);

}  // namespace atrous::view

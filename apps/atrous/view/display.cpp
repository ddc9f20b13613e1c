// The display texture and its two paths (display.h).
#include "view/display.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

namespace atrous::view {

FrameDisplay::FrameDisplay(GlfwSession& session, Device device, int width, int height)
    : mSession(session), mWidth(width), mHeight(height), mRgba(size_t(width) * height * 4, 0) {
    const int w = width, h = height;
    glGenTextures(1, &session.texture);
    glBindTexture(GL_TEXTURE_2D, session.texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);

    // CUDA: the display's pixel unpack buffer registered with CUDA (cuda_display.h). Any failure
    // keeps the host upload, and the panel says why.
    if (device == Device::Cuda) {
        std::string why;
        if (!session.gl.load()) {
            why = "no GL buffer-object entry points";
        } else {
            session.gl.genBuffers(1, &session.pbo);
            session.gl.bindBuffer(GL_PIXEL_UNPACK_BUFFER, session.pbo);
            session.gl.bufferData(GL_PIXEL_UNPACK_BUFFER, GLsizeiptr(size_t(w) * h * 4), nullptr, GL_STREAM_DRAW);
            session.gl.bindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
            session.interop = createCudaGlDisplay(session.pbo, w, h, why);
        }
        mPath = session.interop ? "CUDA-OpenGL interop (PBO)" : "host upload: CUDA-OpenGL interop unavailable (" + why + ")";
        std::fprintf(stderr, "atrous view: display: %s\n", mPath.c_str());
    }
}

std::string FrameDisplay::update(const ViewPipeline& pl, const DisplaySettings& d) {
    GlfwSession& session = mSession;
    const int w = mWidth, h = mHeight;
    const BufferView view = d.view;
    const bool split = view == BufferView::Result && d.split;
    const int xs = split ? std::clamp(int(std::lround(d.splitPos * float(w))), 0, w) : w;
    // What the interop path can show straight from the GPU: the slots' results, or the noisy
    // colour (the running mean), which the pipeline keeps on the GPU too.
    const Image* left = nullptr;
    const Image* right = nullptr;
    if (session.interop && view == BufferView::Result && !pl.slot(0).deviceImage.empty() &&
        (!split || !pl.slot(1).deviceImage.empty())) {
        left = &pl.slot(0).deviceImage;
        right = split ? &pl.slot(1).deviceImage : nullptr;
    } else if (session.interop && view == BufferView::Noisy) {
        left = &pl.deviceBuffer(ViewPipeline::kColor);
    }
    if (left) {
        // GPU to GPU: tonemap kernel into the PBO, then PBO -> texture inside GL.
        try {
            session.interop->write(*left, right, xs, d.exposure);
            session.gl.bindBuffer(GL_PIXEL_UNPACK_BUFFER, session.pbo);
            glBindTexture(GL_TEXTURE_2D, session.texture);
            glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
            session.gl.bindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
            return "";
        } catch (const std::exception& e) {
            session.interop.reset();
            mPath = std::string("host upload: CUDA-OpenGL interop failed (") + e.what() + ")";
            std::fprintf(stderr, "atrous view: display: %s\n", mPath.c_str());
        }
    }
    // Host path. Only the result view reads the results (on CUDA resultHost downloads them once).
    const bool result = view == BufferView::Result;
    std::string note = tonemap(pl, view, result ? &pl.resultHost(0) : nullptr, d.exposure, d.level, 0, xs, mRgba);
    if (split) tonemap(pl, view, result ? &pl.resultHost(1) : nullptr, d.exposure, d.level, xs, w, mRgba);
    glBindTexture(GL_TEXTURE_2D, session.texture);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, mRgba.data());
    return note;
}

}  // namespace atrous::view

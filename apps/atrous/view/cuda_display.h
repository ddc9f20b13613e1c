// CUDA-OpenGL interop for the viewer's image (`atrous view --device cuda`): the display's pixel
// unpack buffer (PBO) is registered with CUDA once (cudaGraphicsGLRegisterBuffer); every frame a
// kernel tonemaps the filtered result, which is still on the GPU, straight into the mapped PBO,
// the PBO is unmapped and GL copies it into the display texture (glTexSubImage2D from the bound
// PBO: GPU to GPU). The filtered image never goes to the host and back.
//
// Isolated behind this interface: the CUDA half is cuda_display.cu (compiled only on CUDA builds),
// the stub in cuda_display_stub.cpp says why there is no interop. When registration fails (no CUDA
// build, no GPU, or the GL context is not on the CUDA device, e.g. Mesa under Xvfb) the viewer
// keeps the host path (tonemap on the CPU, glTexSubImage2D from host memory) and says so.
#pragma once
#include <memory>
#include <string>

#include "atrous/image.h"

namespace atrous::view {

class CudaGlDisplay {
public:
    virtual ~CudaGlDisplay() = default;
    // Tonemaps (exposure, then sRGB to 8 bits, NaN/Inf to black) columns [0, splitX) of `left` and
    // columns [splitX, width) of `right` (or of `left` when right is null) into the registered
    // PBO, rows top-down as the host path writes them. Both are 3-channel planar CUDA images of
    // the display's size. Returns when the PBO is unmapped (GL may then read it). Throws
    // RuntimeError when CUDA fails (the caller falls back to the host path).
    virtual void write(const Image& left, const Image* right, int splitX, float exposure) = 0;
};

// Registers the GL buffer `pbo` (name of a buffer of width * height * 4 bytes, RGBA8; the GL
// context must be current) for CUDA writes. Returns null and sets `why` when there is no interop.
std::unique_ptr<CudaGlDisplay> createCudaGlDisplay(unsigned pbo, int width, int height, std::string& why);

}  // namespace atrous::view

// The CUDA half of the viewer's CUDA-OpenGL interop (see cuda_display.h). Compiled only on CUDA
// builds (viewer.cmake).
#include <cuda_gl_interop.h>
#include <cuda_runtime.h>

#include <cstdint>
#include <string>

#include "atrous/cuda_check.cuh"
#include "view/cuda_display.h"

namespace atrous::view {

namespace {

// The host path's tonemapping (buffer_view.cpp, srgb3): v · exposure, sRGB-encoded, 8 bits. The host
// quantises through a 4096-entry table first, so the two paths may differ by one code value.
__device__ unsigned char encodeSrgb(float v) {
    if (!(v > 0.0f)) return 0;  // also NaN
    if (v >= 1.0f) return 255;
    const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (unsigned char)fminf(255.0f, fmaxf(0.0f, s * 255.0f + 0.5f));
}

__global__ void tonemapKernel(const float* left, const float* right, int width, int height, int splitX,
                              float exposure, uchar4* out) {
    const int x = blockIdx.x * blockDim.x + threadIdx.x;
    const int y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= width || y >= height) return;
    const size_t plane = size_t(width) * height;
    const size_t p = size_t(y) * width + x;
    const float* src = x < splitX ? left : right;
    out[p] = make_uchar4(encodeSrgb(src[p] * exposure), encodeSrgb(src[plane + p] * exposure),
                         encodeSrgb(src[2 * plane + p] * exposure), 255);
}

class CudaGlDisplayImpl final : public CudaGlDisplay {
public:
    CudaGlDisplayImpl(cudaGraphicsResource_t resource, int width, int height)
        : mResource(resource), mWidth(width), mHeight(height) {}
    ~CudaGlDisplayImpl() override { cudaGraphicsUnregisterResource(mResource); }  // no throw

    void write(const Image& left, const Image* right, int splitX, float exposure) override {
        const Image& r = right ? *right : left;
        for (const Image* img : {&left, &r})
            if (img->device() != Device::Cuda || img->width() != mWidth || img->height() != mHeight ||
                img->channels() < 3)
                throw RuntimeError("CUDA-OpenGL display: the image is not a " + std::to_string(mWidth) + "x" +
                                   std::to_string(mHeight) + " CUDA image");
        ATROUS_CUDA_CHECK(cudaGraphicsMapResources(1, &mResource, nullptr));
        void* ptr = nullptr;
        size_t bytes = 0;
        cudaError_t err = cudaGraphicsResourceGetMappedPointer(&ptr, &bytes, mResource);
        if (err == cudaSuccess && bytes < size_t(mWidth) * mHeight * 4) err = cudaErrorInvalidValue;
        if (err == cudaSuccess) {
            const dim3 block(32, 8);
            const dim3 grid((mWidth + block.x - 1) / block.x, (mHeight + block.y - 1) / block.y);
            tonemapKernel<<<grid, block>>>(left.data(), r.data(), mWidth, mHeight, splitX, exposure,
                                           static_cast<uchar4*>(ptr));
            err = cudaGetLastError();
        }
        // Unmapping orders the kernel before any GL use of the buffer (same stream, stream 0).
        const cudaError_t unmapErr = cudaGraphicsUnmapResources(1, &mResource, nullptr);
        ATROUS_CUDA_CHECK(err);
        ATROUS_CUDA_CHECK(unmapErr);
    }

private:
    cudaGraphicsResource_t mResource;
    int mWidth, mHeight;
};

}  // namespace

std::unique_ptr<CudaGlDisplay> createCudaGlDisplay(unsigned pbo, int width, int height, std::string& why) {
    int devices = 0;
    if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
        cudaGetLastError();  // clear it: CudaExec checks cudaGetLastError() after each launch
        why = "no CUDA device";
        return nullptr;
    }
    cudaGraphicsResource_t resource = nullptr;
    const cudaError_t err = cudaGraphicsGLRegisterBuffer(&resource, pbo, cudaGraphicsRegisterFlagsWriteDiscard);
    if (err != cudaSuccess) {
        cudaGetLastError();  // as above: a failed registration must not fail the next kernel launch
        // Typically cudaErrorOperatingSystem / cudaErrorInvalidGraphicsContext: the GL context is
        // not on an NVIDIA GPU (Mesa, Xvfb, a remote display).
        why = std::string("cudaGraphicsGLRegisterBuffer failed: ") + cudaGetErrorString(err);
        return nullptr;
    }
    return std::make_unique<CudaGlDisplayImpl>(resource, width, height);
}

}  // namespace atrous::view

// Images: planar float32, one owner (Image) and non-owning views (ImageView).
//
// Layout: channel planes of width*height floats each, rows top to bottom, pixels left to right.
// Planar storage keeps each per-row inner loop contiguous, which is what lets the CPU backend
// vectorise and what gives coalesced loads on the GPU.
#pragma once
#include <cstddef>
#include <cstdint>

#include "atrous/device.h"
#include "atrous/platform.h"

namespace atrous {

// A non-owning view of a planar float image. Trivially copyable, so it can be passed by value
// into CUDA kernels. Channel c of pixel (x, y) is data[c * plane() + y * width + x].
struct ImageView {
    float* data = nullptr;
    int width = 0;
    int height = 0;
    int channels = 0;

    ATROUS_INLINE size_t plane() const { return size_t(width) * size_t(height); }
    ATROUS_INLINE size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
    ATROUS_INLINE float* channel(int c) const { return data + size_t(c) * plane(); }
    ATROUS_INLINE float& operator()(int x, int y, int c) const { return data[size_t(c) * plane() + index(x, y)]; }
    ATROUS_INLINE bool valid() const { return data != nullptr; }
    ATROUS_INLINE bool sameSize(const ImageView& o) const { return width == o.width && height == o.height; }
};

// An owning planar float image on the host or on a CUDA device. Move-only; copy with clone().
class Image {
public:
    Image() = default;
    // Allocates width*height*channels floats on `device`, zero-filled. Throws InputError for
    // non-positive or absurd sizes (more than 2^31 floats) and RuntimeError when memory runs out.
    Image(int width, int height, int channels, Device device = Device::Cpu);
    // The same without the zero fill, for a caller that writes every pixel before anything reads
    // it (a reader decoding a whole file into the planes, a copy): the pages are first touched by
    // those writes, not by a fill that they then overwrite.
    static Image uninitialized(int width, int height, int channels, Device device = Device::Cpu);
    ~Image();
    Image(Image&& o) noexcept;
    Image& operator=(Image&& o) noexcept;
    Image(const Image&) = delete;
    Image& operator=(const Image&) = delete;

    Image clone() const;
    // A copy on `device` (a deep copy even when already there).
    Image to(Device device) const;
    // Copies all pixels from `src` (same size and channel count; any devices).
    void copyFrom(const Image& src);
    void fill(float v);  // host images only

    int width() const { return mWidth; }
    int height() const { return mHeight; }
    int channels() const { return mChannels; }
    Device device() const { return mDevice; }
    bool empty() const { return mData == nullptr; }
    size_t plane() const { return size_t(mWidth) * size_t(mHeight); }
    size_t size() const { return plane() * size_t(mChannels); }  // floats
    float* data() { return mData; }
    const float* data() const { return mData; }
    ImageView view() const { return ImageView{mData, mWidth, mHeight, mChannels}; }
    // Host images only (no check on the hot path beyond debug asserts).
    float& operator()(int x, int y, int c) { return mData[size_t(c) * plane() + size_t(y) * mWidth + x]; }
    float operator()(int x, int y, int c) const { return mData[size_t(c) * plane() + size_t(y) * mWidth + x]; }

private:
    struct NoFill {};
    Image(int width, int height, int channels, Device device, NoFill);
    void release();
    float* mData = nullptr;
    int mWidth = 0, mHeight = 0, mChannels = 0;
    Device mDevice = Device::Cpu;
};

// Largest accepted width or height (a 16K image); larger requests are rejected as absurd.
constexpr int kMaxImageDim = 16384;

}  // namespace atrous

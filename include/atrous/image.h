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

// The element types an image in the caller's memory may have (StridedImage).
enum class DataType : int { Float32 = 0, Float16 = 1 };  // Float16: IEEE 754 binary16 ("half")
constexpr int dataTypeBytes(DataType t) { return t == DataType::Float16 ? 2 : 4; }

// An image in the caller's memory and layout, borrowed (the memory must outlive its use): float32
// or float16, 1 to 4 channels, interleaved (channelStride = the element's size) or planar
// (channelStride = a plane's bytes), with byte strides of any sign. What the C API's
// atrousSetFilterImage and Python's numpy arrays hand over; an Image is one too (Image::strided():
// planar float32). Element (x, y, c) is at (const char*)data + y * rowStride + x * pixelStride +
// c * channelStride. The filters read it where it is; src/core/strided.h has the per-pixel access.
struct StridedImage {
    const void* data = nullptr;  // element (0, 0, 0); null = no image
    DataType type = DataType::Float32;
    int width = 0, height = 0, channels = 0;
    int64_t pixelStride = 0, rowStride = 0, channelStride = 0;  // in bytes
    Device device = Device::Cpu;

    ATROUS_INLINE bool valid() const { return data != nullptr; }
    // The layout of a planar float32 image of this size (an ImageView's): then view() is that view.
    ATROUS_INLINE bool planarFloat() const {
        return type == DataType::Float32 && pixelStride == 4 && rowStride == 4 * int64_t(width) &&
               (channels == 1 || channelStride == 4 * int64_t(width) * int64_t(height));
    }
    ATROUS_INLINE ImageView view() const {
        return planarFloat() ? ImageView{static_cast<float*>(const_cast<void*>(data)), width, height, channels} : ImageView{};
    }
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
    // The same pixels described as a StridedImage (planar float32; data null when empty).
    StridedImage strided() const {
        const int64_t p = int64_t(plane()) * 4;
        return StridedImage{mData, DataType::Float32, mWidth, mHeight, mChannels, 4, 4 * int64_t(mWidth), p, mDevice};
    }
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

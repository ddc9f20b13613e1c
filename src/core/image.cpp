#include "atrous/image.h"

#include <tbb/scalable_allocator.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>

#include "atrous/error.h"
#include "core/memory.h"

namespace atrous {

namespace detail {

// Host memory comes from TBB's scalable allocator: its large-object cache keeps released blocks
// for reuse, so the denoisers' per-call temporaries (~15 image-sized blocks) do not page-fault and
// get zeroed by the kernel on every call (that was ~10% of a 512x512 denoise with plain malloc).
//
// Under `make sanitize` (ATROUS_SANITIZE, scripts/sanitize.sh) images come from the C allocator
// instead, which AddressSanitizer intercepts: TBB's pools are invisible to it, so an overrun of an
// image buffer would go unreported.
#if defined(ATROUS_SANITIZE)
static void* hostAlloc(size_t bytes) { return std::aligned_alloc(64, (bytes + 63) / 64 * 64); }
static void hostFree(void* p) { std::free(p); }
#else
static void* hostAlloc(size_t bytes) { return scalable_aligned_malloc(bytes, 64); }
static void hostFree(void* p) { scalable_aligned_free(p); }
#endif

void* allocateBytes(size_t bytes, Device device) {
    if (device == Device::Cuda) return cudaAllocate(bytes);
    void* p = hostAlloc(bytes == 0 ? 64 : bytes);
    if (!p) throw RuntimeError("out of host memory allocating " + std::to_string(bytes) + " bytes");
    return p;
}

void freeBytes(void* p, Device device) {
    if (!p) return;
    if (device == Device::Cuda)
        cudaRelease(p);
    else
        hostFree(p);
}

void copyBytes(void* dst, Device dstDevice, const void* src, Device srcDevice, size_t bytes) {
    if (bytes == 0) return;
    if (dstDevice == Device::Cpu && srcDevice == Device::Cpu)
        std::memcpy(dst, src, bytes);
    else
        cudaCopy(dst, dstDevice, src, srcDevice, bytes);
}

void fillFloats(float* dst, Device device, float value, size_t count) {
    if (device == Device::Cuda) {
        cudaFillFloats(dst, value, count);
        return;
    }
    for (size_t i = 0; i < count; ++i) dst[i] = value;
}

}  // namespace detail

Image::Image(int width, int height, int channels, Device device) : Image(width, height, channels, device, NoFill{}) {
    detail::fillFloats(mData, device, 0.0f, size());
}

Image Image::uninitialized(int width, int height, int channels, Device device) {
    return Image(width, height, channels, device, NoFill{});
}

Image::Image(int width, int height, int channels, Device device, NoFill)
    : mWidth(width), mHeight(height), mChannels(channels), mDevice(device) {
    if (width <= 0 || height <= 0 || channels <= 0)
        throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) + "x" +
                         std::to_string(channels) + " is not positive");
    if (width > kMaxImageDim || height > kMaxImageDim)
        throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                         " exceeds the limit of " + std::to_string(kMaxImageDim) + " pixels per side");
    mData = static_cast<float*>(detail::allocateBytes(size() * sizeof(float), device));
}

Image::~Image() { release(); }

void Image::release() {
    detail::freeBytes(mData, mDevice);
    mData = nullptr;
}

Image::Image(Image&& o) noexcept
    : mData(o.mData), mWidth(o.mWidth), mHeight(o.mHeight), mChannels(o.mChannels), mDevice(o.mDevice) {
    o.mData = nullptr;
    o.mWidth = o.mHeight = o.mChannels = 0;
}

Image& Image::operator=(Image&& o) noexcept {
    if (this != &o) {
        release();
        mData = std::exchange(o.mData, nullptr);
        mWidth = std::exchange(o.mWidth, 0);
        mHeight = std::exchange(o.mHeight, 0);
        mChannels = std::exchange(o.mChannels, 0);
        mDevice = o.mDevice;
    }
    return *this;
}

Image Image::clone() const { return to(mDevice); }

Image Image::to(Device device) const {
    if (empty()) return Image();
    Image out = uninitialized(mWidth, mHeight, mChannels, device);
    detail::copyBytes(out.mData, device, mData, mDevice, size() * sizeof(float));
    return out;
}

void Image::copyFrom(const Image& src) {
    if (src.mWidth != mWidth || src.mHeight != mHeight || src.mChannels != mChannels)
        throw InputError("copyFrom: image sizes differ");
    detail::copyBytes(mData, mDevice, src.mData, src.mDevice, size() * sizeof(float));
}

void Image::fill(float v) { detail::fillFloats(mData, mDevice, v, size()); }

}  // namespace atrous

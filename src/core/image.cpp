#include "atrous/image.h"

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "atrous/error.h"
#include "core/memory.h"

namespace atrous {

namespace detail {

namespace {

// Host blocks of large images are kept after release and handed out again for the same size:
// the denoisers allocate ~15 image-sized temporaries per call, and fresh large blocks come from
// mmap, so every call paid a page fault per 4 KiB plus the kernel's zeroing (~10% of a 512×512
// denoise). Bounded, so a long-running process keeps at most kCacheLimit bytes idle.
constexpr size_t kCacheMinBytes = size_t(256) << 10;
constexpr size_t kCacheLimit = size_t(512) << 20;

struct HostBlockCache {
    std::mutex mutex;
    std::vector<std::pair<void*, size_t>> blocks;  // (pointer, rounded size), most recent last
    size_t bytes = 0;

    void* take(size_t rounded) {
        std::lock_guard<std::mutex> lock(mutex);
        for (size_t i = blocks.size(); i-- > 0;) {
            if (blocks[i].second != rounded) continue;
            void* p = blocks[i].first;
            blocks.erase(blocks.begin() + long(i));
            bytes -= rounded;
            return p;
        }
        return nullptr;
    }
    // Returns false when the block does not fit; the caller frees it then.
    bool give(void* p, size_t rounded) {
        std::lock_guard<std::mutex> lock(mutex);
        while (bytes + rounded > kCacheLimit && !blocks.empty()) {  // drop the oldest
            std::free(blocks.front().first);
            bytes -= blocks.front().second;
            blocks.erase(blocks.begin());
        }
        if (bytes + rounded > kCacheLimit) return false;
        blocks.emplace_back(p, rounded);
        bytes += rounded;
        return true;
    }
};

// Never destroyed: images in static storage may be released after it would have been.
HostBlockCache& hostCache() {
    static HostBlockCache* cache = new HostBlockCache;
    return *cache;
}

size_t roundedHostBytes(size_t bytes) {
    const size_t rounded = (bytes + 63) / 64 * 64;
    return rounded == 0 ? 64 : rounded;
}

}  // namespace

void* allocateBytes(size_t bytes, Device device) {
    if (device == Device::Cuda) return cudaAllocate(bytes);
    const size_t rounded = roundedHostBytes(bytes);
    if (rounded >= kCacheMinBytes) {
        if (void* p = hostCache().take(rounded)) return p;
    }
    void* p = std::aligned_alloc(64, rounded);
    if (!p) throw RuntimeError("out of host memory allocating " + std::to_string(bytes) + " bytes");
    return p;
}

void freeBytes(void* p, Device device) {
    if (!p) return;
    if (device == Device::Cuda)
        cudaRelease(p);
    else
        std::free(p);
}

// freeBytes that may keep a host block of `bytes` (the size it was allocated with) for reuse.
void releaseBytes(void* p, Device device, size_t bytes) {
    if (p && device == Device::Cpu) {
        const size_t rounded = roundedHostBytes(bytes);
        if (rounded >= kCacheMinBytes && hostCache().give(p, rounded)) return;
    }
    freeBytes(p, device);
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

Image::Image(int width, int height, int channels, Device device)
    : mWidth(width), mHeight(height), mChannels(channels), mDevice(device) {
    if (width <= 0 || height <= 0 || channels <= 0)
        throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) + "x" +
                         std::to_string(channels) + " is not positive");
    if (width > kMaxImageDim || height > kMaxImageDim)
        throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                         " exceeds the limit of " + std::to_string(kMaxImageDim) + " pixels per side");
    mData = static_cast<float*>(detail::allocateBytes(size() * sizeof(float), device));
    detail::fillFloats(mData, device, 0.0f, size());
}

Image::~Image() { release(); }

void Image::release() {
    detail::releaseBytes(mData, mDevice, size() * sizeof(float));
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
    Image out(mWidth, mHeight, mChannels, device);
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

// importImage / exportImage (include/atrous/interop.h): the host paths and the checks; the CUDA
// halves are src/cuda/cuda_strided.cu.
#include "core/strided.h"

#include <algorithm>
#include <cstdlib>
#include <string>

#include "atrous/error.h"
#include "atrous/interop.h"
#include "core/parallel.h"

namespace atrous {

namespace {

// A stride beyond 2^40 bytes (1 TiB) is no image's: rejected before any offset arithmetic could
// overflow.
constexpr int64_t kMaxStride = int64_t(1) << 40;

[[noreturn]] void fail(const char* what, const std::string& why) {
    throw InputError(std::string(what) + ": " + why);
}

// No two elements of `s` at the same address: with the dimensions sorted by |stride|, each stride
// clears everything the smaller ones span (a sufficient rule, exact for every layout a program
// makes: interleaved, planar, padded rows, flipped).
bool nonOverlapping(const StridedImage& s) {
    struct Dim {
        int64_t stride;
        int extent;
    } d[3] = {{std::llabs(s.pixelStride), s.width},
              {std::llabs(s.rowStride), s.height},
              {std::llabs(s.channelStride), s.channels}};
    std::sort(d, d + 3, [](const Dim& a, const Dim& b) { return a.stride < b.stride; });
    int64_t span = dataTypeBytes(s.type);
    for (const Dim& k : d) {
        if (k.extent == 1) continue;
        if (k.stride < span) return false;
        span = k.stride * (k.extent - 1) + span;
    }
    return true;
}

// What both directions need: data, a known type, a size and channel count in range, and elements
// aligned to their size (the typed loads of strided.h).
void checkStrided(const StridedImage& s, const char* what) {
    if (!s.data) fail(what, "no data");
    if (s.type != DataType::Float32 && s.type != DataType::Float16)
        fail(what, "unknown element type " + std::to_string(int(s.type)));
    if (s.width < 1 || s.height < 1 || s.width > kMaxImageDim || s.height > kMaxImageDim)
        fail(what, "size " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                       " out of range (1.." + std::to_string(kMaxImageDim) + " each)");
    if (s.channels < 1 || s.channels > 4)
        fail(what, "expected 1 to 4 channels, got " + std::to_string(s.channels));
    const int64_t e = dataTypeBytes(s.type);
    for (int64_t st : {s.pixelStride, s.rowStride, s.channelStride}) {
        if (st > kMaxStride || st < -kMaxStride)
            fail(what, "stride of " + std::to_string(st) + " bytes is out of range");
        if (st % e != 0)
            fail(what, "stride of " + std::to_string(st) +
                           " bytes is not a multiple of the element's " + std::to_string(e));
    }
    if (reinterpret_cast<uintptr_t>(s.data) % uintptr_t(e) != 0)
        fail(what, "data is not aligned to its " + std::to_string(e) + "-byte elements");
}

// Interleaved float32 RGB on the host: the vectorising row paths.
bool interleavedRgb32(const StridedImage& s) {
    return s.device == Device::Cpu && s.type == DataType::Float32 && s.channels == 3 &&
           s.pixelStride == 12 && s.channelStride == 4;
}

// Interleaved float32 on the host with pixels of K = 1..4 floats holding the channels read: K, or 0.
int interleavedFloats(const StridedImage& s) {
    if (s.device != Device::Cpu || s.type != DataType::Float32 || (s.channels > 1 && s.channelStride != 4)) return 0;
    const int64_t k = s.pixelStride / 4;
    return s.pixelStride % 4 == 0 && k >= 1 && k <= 4 && k >= s.channels ? int(k) : 0;
}

template <int K>
void gatherInterleaved(const StridedImage& s, const ImageView& v) {
    parallelForRowsCpu(s.height, detail::GatherInterleaved<K>{static_cast<const float*>(s.data), s.rowStride / 4,
                                                              s.channels, v});
}

}  // namespace

Image importImage(const StridedImage& src, int outChannels, const char* what) {
    checkStrided(src, what);
    if (outChannels < 1 || outChannels > 4)
        fail(what, "cannot make an image of " + std::to_string(outChannels) + " channels");
    if (src.channels != 1 && src.channels != outChannels)
        fail(what, "expected " + std::to_string(outChannels) + " channels (or 1), got " +
                       std::to_string(src.channels));
    // Every value is written below: no zero fill first.
    Image out = Image::uninitialized(src.width, src.height, outChannels, src.device);
    const ImageView v = out.view();
    if (src.device == Device::Cuda)
        detail::cudaImportStrided(src, v);
    else if (interleavedRgb32(src) && outChannels == 3)
        parallelForRowsCpu(
            src.height,
            detail::GatherInterleaved3{static_cast<const float*>(src.data), src.rowStride / 4, v});
    else if (const int k = interleavedFloats(src))  // a feature's first channels of an RGB array, grey
        k == 1 ? gatherInterleaved<1>(src, v)
               : k == 2 ? gatherInterleaved<2>(src, v) : k == 3 ? gatherInterleaved<3>(src, v) : gatherInterleaved<4>(src, v);
    else if (src.type == DataType::Float16)
        parallelFor2dCpu(src.width, src.height, detail::ImportStrided<DataType::Float16>{src, v});
    else
        parallelFor2dCpu(src.width, src.height, detail::ImportStrided<DataType::Float32>{src, v});
    return out;
}

void exportImage(const ImageView& src, const StridedImage& dst, const char* what) {
    checkStrided(dst, what);
    if (!src.valid()) fail(what, "no image to write");
    if (src.width != dst.width || src.height != dst.height)
        fail(what, "is " + std::to_string(dst.width) + "x" + std::to_string(dst.height) +
                       ", the image written is " + std::to_string(src.width) + "x" +
                       std::to_string(src.height));
    if (dst.channels > src.channels)
        fail(what, "has " + std::to_string(dst.channels) + " channels, the image written " +
                       std::to_string(src.channels));
    if (!nonOverlapping(dst)) fail(what, "its strides make pixels or channels overlap");
    if (dst.device == Device::Cuda)
        detail::cudaExportStrided(src, dst);
    else if (interleavedRgb32(dst))
        parallelForRowsCpu(src.height, detail::ScatterInterleaved3{
                                           src, static_cast<float*>(const_cast<void*>(dst.data)),
                                           dst.rowStride / 4});
    else if (dst.type == DataType::Float16)
        parallelFor2dCpu(src.width, src.height, detail::ExportStrided<DataType::Float16>{src, dst});
    else
        parallelFor2dCpu(src.width, src.height, detail::ExportStrided<DataType::Float32>{src, dst});
}

StridedImage interleavedImage(const void* data, DataType type, int width, int height, int channels,
                              Device device, int64_t rowBytes) {
    const int64_t pixel = int64_t(dataTypeBytes(type)) * channels;
    StridedImage s;
    s.data = data, s.type = type, s.width = width, s.height = height, s.channels = channels,
    s.device = device;
    s.pixelStride = pixel, s.channelStride = dataTypeBytes(type);
    s.rowStride = rowBytes ? rowBytes : pixel * width;
    return s;
}

}  // namespace atrous

// Per-pixel access to a StridedImage (include/atrous/image.h: float32 or float16, 1-4 channels,
// byte strides of any sign) and the functors behind importImage / exportImage
// (include/atrous/interop.h), shared by the CPU (src/core/strided.cpp) and CUDA
// (src/cuda/cuda_strided.cu) backends.
#pragma once
#include <Imath/half.h>

#include <cstdint>

#include "atrous/image.h"
#include "atrous/platform.h"

#if ATROUS_DEVICE_COMPILER
#include <cuda_fp16.h>
#endif

namespace atrous {

// half <-> float, round to nearest even: Imath's on the host (the library that reads EXR's
// halves), cuda_fp16's intrinsics on the device. Values beyond half's range are clamped to its
// largest finite value (65504) first, so that no Inf reaches an output; NaN stays NaN.
ATROUS_INLINE float halfToFloat(uint16_t bits) {
#if ATROUS_ON_DEVICE
    return __half2float(__ushort_as_half(bits));
#else
    return imath_half_to_float(bits);
#endif
}
ATROUS_INLINE uint16_t floatToHalf(float v) {
    constexpr float kHalfMax = 65504.0f;
    const float c =
        v > kHalfMax ? kHalfMax : (v < -kHalfMax ? -kHalfMax : v);  // NaN passes through
#if ATROUS_ON_DEVICE
    return __half_as_ushort(__float2half_rn(c));
#else
    return imath_float_to_half(c);
#endif
}

// The address of element (x, y, c). The caller has checked the image (checkStrided, strided.cpp):
// the data and the strides are multiples of the element's size, so the typed loads are aligned.
ATROUS_INLINE const char* stridedAddress(const StridedImage& s, int x, int y, int c) {
    return static_cast<const char*>(s.data) + int64_t(y) * s.rowStride +
           int64_t(x) * s.pixelStride + int64_t(c) * s.channelStride;
}

// Element (x, y, c) as a float, of an image whose type is T (the functors' hoisted branch).
template <DataType T>
ATROUS_INLINE float loadStridedAs(const StridedImage& s, int x, int y, int c) {
    const char* p = stridedAddress(s, x, y, c);
    if constexpr (T == DataType::Float16)
        return halfToFloat(*reinterpret_cast<const uint16_t*>(p));
    else
        return *reinterpret_cast<const float*>(p);
}
template <DataType T>
ATROUS_INLINE void storeStridedAs(const StridedImage& s, int x, int y, int c, float v) {
    char* p = const_cast<char*>(stridedAddress(s, x, y, c));  // the caller's output memory
    if constexpr (T == DataType::Float16)
        *reinterpret_cast<uint16_t*>(p) = floatToHalf(v);
    else
        *reinterpret_cast<float*>(p) = v;
}

// The same for any type.
ATROUS_INLINE float loadStrided(const StridedImage& s, int x, int y, int c) {
    return s.type == DataType::Float16 ? loadStridedAs<DataType::Float16>(s, x, y, c)
                                       : loadStridedAs<DataType::Float32>(s, x, y, c);
}
ATROUS_INLINE void storeStrided(const StridedImage& s, int x, int y, int c, float v) {
    if (s.type == DataType::Float16)
        storeStridedAs<DataType::Float16>(s, x, y, c, v);
    else
        storeStridedAs<DataType::Float32>(s, x, y, c, v);
}

namespace detail {

// The generic paths, one pixel at a time. Import: a 1-channel source repeats into every channel of
// dst. Export: dst.channels of src's (src.channels >= dst.channels).
template <DataType T>
struct ImportStrided {
    StridedImage src;
    ImageView dst;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int c = 0; c < dst.channels; ++c)
            dst(x, y, c) = loadStridedAs<T>(src, x, y, src.channels == 1 ? 0 : c);
    }
};
template <DataType T>
struct ExportStrided {
    ImageView src;
    StridedImage dst;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int c = 0; c < dst.channels; ++c) storeStridedAs<T>(dst, x, y, c, src(x, y, c));
    }
};

// The common host layout, interleaved float32 RGB (numpy's C-contiguous H x W x 3, a renderer's
// FLOAT3 buffer): a row at a time with the channel stride a constant, so the compiler vectorises
// the de-interleave. The same values as ImportStrided. `row0` is row 0's first element, `rowStride`
// in floats (any sign).
struct GatherInterleaved3 {
    const float* row0;
    int64_t rowStride;
    ImageView dst;
    void operator()(int y) const {
        const float* ATROUS_RESTRICT p = row0 + y * rowStride;
        float* ATROUS_RESTRICT r = dst.channel(0) + size_t(y) * size_t(dst.width);
        float* ATROUS_RESTRICT g = dst.channel(1) + size_t(y) * size_t(dst.width);
        float* ATROUS_RESTRICT b = dst.channel(2) + size_t(y) * size_t(dst.width);
        for (int x = 0; x < dst.width; ++x) {
            r[x] = p[3 * x];
            g[x] = p[3 * x + 1];
            b[x] = p[3 * x + 2];
        }
    }
};

// Interleaved float32 pixels of K floats of which the first src channels are read (a depth's
// first of three, the ids' two of three, a grey image's one, repeated into every channel of dst):
// a row and a channel at a time with the pixel stride a constant, so the compiler vectorises it.
// The same values as ImportStrided.
template <int K>
struct GatherInterleaved {
    const float* row0;
    int64_t rowStride;  // in floats (any sign)
    int srcChannels;
    ImageView dst;
    void operator()(int y) const {
        const float* p = row0 + y * rowStride;
        for (int c = 0; c < dst.channels; ++c) {
            const float* ATROUS_RESTRICT q = p + (srcChannels == 1 ? 0 : c);
            float* ATROUS_RESTRICT o = dst.channel(c) + size_t(y) * size_t(dst.width);
            for (int x = 0; x < dst.width; ++x) o[x] = q[K * x];
        }
    }
};

// The inverse (exportImage's host path for interleaved float32 RGB).
struct ScatterInterleaved3 {
    ImageView src;
    float* row0;
    int64_t rowStride;  // in floats
    void operator()(int y) const {
        const size_t w = size_t(src.width);
        const float* ATROUS_RESTRICT r = src.channel(0) + size_t(y) * w;
        const float* ATROUS_RESTRICT g = src.channel(1) + size_t(y) * w;
        const float* ATROUS_RESTRICT b = src.channel(2) + size_t(y) * w;
        float* ATROUS_RESTRICT p = row0 + y * rowStride;
        for (size_t x = 0; x < w; ++x) {
            p[3 * x] = r[x];
            p[3 * x + 1] = g[x];
            p[3 * x + 2] = b[x];
        }
    }
};

// CUDA halves (src/cuda/cuda_strided.cu; the no-CUDA build throws): src and dst on the GPU.
void cudaImportStrided(const StridedImage& src, const ImageView& dst);
void cudaExportStrided(const ImageView& src, const StridedImage& dst);

}  // namespace detail
}  // namespace atrous

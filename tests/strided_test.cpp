// Images in the caller's layout (StridedImage, include/atrous/image.h) to and from planar Images
// (importImage / exportImage, include/atrous/interop.h; per-pixel access src/core/strided.h): every
// element type x layout (interleaved, planar, flipped, padded, channels reversed) x channel count
// round-trips exactly and writes no byte outside its elements; halves convert exactly where a value
// is a half and round to nearest even where not; bad shapes are InputErrors naming the image, with
// nothing written. The same on the GPU when there is one.
#include "core/strided.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/interop.h"
#include "core/memory.h"

namespace atrous {
namespace {

enum class Layout { Interleaved, Planar, Flipped, Padded, ChannelsReversed };
const Layout kLayouts[] = {Layout::Interleaved, Layout::Planar, Layout::Flipped, Layout::Padded,
                           Layout::ChannelsReversed};
const char* layoutName(Layout l) {
    const char* names[] = {"interleaved", "planar", "flipped", "padded", "channels reversed"};
    return names[int(l)];
}

constexpr unsigned char kSentinel = 0xA5;

// A byte buffer holding one image of the layout, element (0, 0, 0) at `origin`; the bytes that
// belong to no element keep kSentinel.
struct Buffer {
    std::vector<float> storage;  // float-aligned bytes
    StridedImage image;
    std::vector<bool> element;  // per byte: part of an element

    unsigned char* bytes() { return reinterpret_cast<unsigned char*>(storage.data()); }
    size_t size() const { return storage.size() * sizeof(float); }
};

Buffer makeBuffer(int w, int h, int c, DataType t, Layout l) {
    const int64_t e = dataTypeBytes(t);
    StridedImage s;
    s.type = t, s.width = w, s.height = h, s.channels = c;
    s.channelStride = e, s.pixelStride = c * e, s.rowStride = int64_t(w) * c * e;
    if (l == Layout::Planar)
        s.pixelStride = e, s.rowStride = w * e, s.channelStride = int64_t(w) * h * e;
    if (l == Layout::Flipped) s.pixelStride = -s.pixelStride, s.rowStride = -s.rowStride;
    if (l == Layout::Padded)
        s.pixelStride = (c + 1) * e, s.rowStride = (int64_t(w) * (c + 1) + 3) * e;
    if (l == Layout::ChannelsReversed) s.channelStride = -e;
    int64_t origin = 0, span = e;
    const int64_t strides[3] = {s.pixelStride, s.rowStride, s.channelStride};
    const int extents[3] = {w, h, c};
    for (int k = 0; k < 3; ++k) {
        const int64_t reach = strides[k] * (extents[k] - 1);
        origin += reach < 0 ? -reach : 0;
        span += reach < 0 ? -reach : reach;
    }
    Buffer b;
    b.storage.resize(size_t(span + 16) / sizeof(float) + 1);
    std::memset(b.bytes(), kSentinel, b.size());
    s.data = b.bytes() + origin;
    b.image = s;
    b.element.assign(b.size(), false);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < c; ++k) {
                const size_t at =
                    size_t(stridedAddress(s, x, y, k) - reinterpret_cast<const char*>(b.bytes()));
                for (int64_t i = 0; i < e; ++i) b.element[at + size_t(i)] = true;
            }
    return b;
}

// Values that are exact halves: multiples of 1/8 in [-2.5, 3.625].
Image reference(int w, int h, int c) {
    Image img(w, h, c);
    for (int k = 0; k < c; ++k)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                img(x, y, k) = float((x * 7 + y * 13 + k * 5) % 50 - 20) / 8.0f;
    return img;
}

size_t firstDifference(const Image& a, const Image& b) {
    for (size_t i = 0; i < a.size(); ++i)
        if (!(a.data()[i] == b.data()[i])) return i;
    return SIZE_MAX;
}

bool sentinelsKept(Buffer& b) {
    for (size_t i = 0; i < b.size(); ++i)
        if (!b.element[i] && b.bytes()[i] != kSentinel) return false;
    return true;
}

// Runs f(type, layout, channels) for every element type, layout and channel count.
template <class F>
void forEachFormat(F&& f) {
    for (DataType t : {DataType::Float32, DataType::Float16})
        for (Layout l : kLayouts)
            for (int c = 1; c <= 4; ++c) {
                SCOPED_TRACE(std::string(t == DataType::Float16 ? "half " : "float ") +
                             layoutName(l) + " " + std::to_string(c));
                f(t, l, c);
            }
}

TEST(Strided, EveryFormatAndLayoutRoundTrips) {
    const int w = 13, h = 7;  // odd: no layout lines up with a vector width
    forEachFormat([&](DataType t, Layout l, int c) {
        const Image ref = reference(w, h, c);
        Buffer b = makeBuffer(w, h, c, t, l);
        exportImage(ref.view(), b.image, "out");
        EXPECT_TRUE(sentinelsKept(b)) << "a byte outside the elements was written";
        for (int k = 0; k < c; ++k)
            EXPECT_EQ(loadStrided(b.image, w - 1, h - 2, k), ref(w - 1, h - 2, k));
        const Image back = importImage(b.image, c, "in");
        ASSERT_EQ(back.channels(), c);
        EXPECT_EQ(firstDifference(back, ref), SIZE_MAX);
    });
}

// The element positions themselves, for the two layouts everyone knows (the fast paths of
// interleaved float32 RGB included).
TEST(Strided, InterleavedAndPlanarAreWhereTheirNamesSay) {
    const int w = 9, h = 4;
    const Image ref = reference(w, h, 3);
    Buffer inter = makeBuffer(w, h, 3, DataType::Float32, Layout::Interleaved);
    Buffer planar = makeBuffer(w, h, 3, DataType::Float32, Layout::Planar);
    exportImage(ref.view(), inter.image, "inter");
    exportImage(ref.view(), planar.image, "planar");
    const float* i = static_cast<const float*>(inter.image.data);
    const float* p = static_cast<const float*>(planar.image.data);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                EXPECT_EQ(i[(y * w + x) * 3 + c], ref(x, y, c));
                EXPECT_EQ(p[(c * h + y) * w + x], ref(x, y, c));
            }
    EXPECT_TRUE(planar.image.planarFloat());
    EXPECT_EQ(planar.image.view().data, p);
    EXPECT_TRUE(ref.strided().planarFloat());
    EXPECT_EQ(firstDifference(importImage(ref.strided(), 3, "self"), ref), SIZE_MAX);
}

TEST(Strided, AGreyImageRepeatsIntoEveryChannelAndExportTakesTheFirstChannels) {
    const Image grey = reference(5, 3, 1);
    const Image rgb = importImage(grey.strided(), 3, "grey");
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 5; ++x) EXPECT_EQ(rgb(x, y, c), grey(x, y, 0));
    // An RGBA buffer written as RGB (channels = 3, pixel stride of 4): alpha untouched.
    const Image ref = reference(5, 3, 3);
    std::vector<float> rgba(5 * 3 * 4, -9.0f);
    StridedImage s = interleavedImage(rgba.data(), DataType::Float32, 5, 3, 3);
    s.pixelStride = 16, s.rowStride = 5 * 16;
    exportImage(ref.view(), s, "rgba");
    for (int i = 0; i < 15; ++i) {
        EXPECT_EQ(rgba[size_t(i) * 4 + 3], -9.0f);
        EXPECT_EQ(rgba[size_t(i) * 4], ref.data()[i]);
    }
}

// The first channels of wider interleaved float32 pixels (a depth's first of three, the ids' two of
// three, RGB of RGBA, a grey array's one repeated), each pixel width, a padded row and a flipped
// one: importImage's row gather gives the values the element-wise definition gives.
TEST(Strided, TheFirstChannelsOfWiderInterleavedPixels) {
    const int w = 13, h = 5;
    for (int k = 1; k <= 4; ++k)
        for (int c = 1; c <= k; ++c)
            for (int64_t pad : {int64_t(0), int64_t(8)})
                for (bool flip : {false, true}) {
                    SCOPED_TRACE("pixel of " + std::to_string(k) + ", " + std::to_string(c) + " read, pad " +
                                 std::to_string(pad) + (flip ? ", flipped" : ""));
                    const int64_t row = int64_t(w) * k + pad / 4;
                    std::vector<float> data(size_t(row) * h);
                    for (size_t i = 0; i < data.size(); ++i) data[i] = float(int(i * 37 % 101) - 50) / 4.0f;
                    StridedImage s = interleavedImage(data.data(), DataType::Float32, w, h, c, Device::Cpu, row * 4);
                    s.pixelStride = 4 * k;
                    if (flip) s.data = data.data() + (h - 1) * row, s.rowStride = -row * 4;
                    for (int out : {c, c == 1 ? 3 : c}) {
                        const Image img = importImage(s, out, "in");
                        for (int ch = 0; ch < out; ++ch)
                            for (int y = 0; y < h; ++y)
                                for (int x = 0; x < w; ++x)
                                    ASSERT_EQ(img(x, y, ch), loadStrided(s, x, y, c == 1 ? 0 : ch));
                    }
                }
}

TEST(Strided, HalvesAreExactWhereRepresentableAndRoundToNearestEvenElsewhere) {
    const float exact[] = {0.0f,
                           -0.0f,
                           1.0f,
                           -2.5f,
                           65504.0f,
                           -65504.0f,
                           0.333251953125f,
                           2048.0f,
                           2050.0f,
                           std::ldexp(1.0f, -14) /* smallest normal */,
                           std::ldexp(1.0f, -24) /* smallest subnormal */,
                           std::ldexp(3.0f, -24)};
    uint16_t cell = 0;
    StridedImage s = interleavedImage(&cell, DataType::Float16, 1, 1, 1);
    for (float v : exact) {
        storeStrided(s, 0, 0, 0, v);
        EXPECT_EQ(loadStrided(s, 0, 0, 0), v) << v;
        EXPECT_EQ(std::signbit(loadStrided(s, 0, 0, 0)), std::signbit(v)) << v;
    }
    struct {
        float in, out;
    } rounded[] = {
        {0.1f, 0.0999755859375f},  // to nearest
        {2049.0f, 2048.0f},        // a tie: to the even mantissa
        {2051.0f, 2052.0f},        // a tie: to the even mantissa, upwards
        {1e6f, 65504.0f},          // beyond half's range: clamped, no Inf
        {-1e6f, -65504.0f},
        {std::numeric_limits<float>::infinity(), 65504.0f},
        {std::ldexp(1.0f, -26), 0.0f},  // below half the smallest subnormal
    };
    for (const auto& r : rounded) {
        storeStrided(s, 0, 0, 0, r.in);
        EXPECT_EQ(loadStrided(s, 0, 0, 0), r.out) << r.in;
    }
    storeStrided(s, 0, 0, 0, std::nanf(""));
    EXPECT_TRUE(std::isnan(loadStrided(s, 0, 0, 0)));
    // Every one of the 63488 finite halves converts to a float and back to itself.
    int bad = 0;
    for (uint32_t bits = 0; bits < 0x10000u; ++bits) {
        if ((bits & 0x7c00u) == 0x7c00u) continue;  // Inf and NaN
        cell = uint16_t(bits);
        const float f = loadStrided(s, 0, 0, 0);
        storeStrided(s, 0, 0, 0, f);
        bad += cell != uint16_t(bits);
    }
    EXPECT_EQ(bad, 0);
}

// An InputError whose message names `what` and says `why`.
template <class F>
void expectInputError(F&& f, const std::string& what, const std::string& why) {
    try {
        f();
        ADD_FAILURE() << "no error (" << why << ")";
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.rfind(what + ": ", 0), 0u) << m;
        EXPECT_NE(m.find(why), std::string::npos) << m;
    }
}

TEST(Strided, BadShapesAreInputErrorsAndWriteNothing) {
    const Image ref = reference(6, 4, 3);
    Buffer b = makeBuffer(6, 4, 3, DataType::Float32, Layout::Interleaved);
    auto import = [&](StridedImage s, int channels) {
        return [s, channels] { importImage(s, channels, "albedo"); };
    };
    StridedImage two = b.image;
    two.channels = 2;
    expectInputError(import(two, 3), "albedo", "expected 3 channels (or 1), got 2");
    StridedImage none = b.image;
    none.data = nullptr;
    expectInputError(import(none, 3), "albedo", "no data");
    StridedImage empty = b.image;
    empty.width = 0;
    expectInputError(import(empty, 3), "albedo", "size 0x4 out of range");
    StridedImage five = b.image;
    five.channels = 5;
    expectInputError(import(five, 5), "albedo", "1 to 4 channels, got 5");
    StridedImage odd = b.image;
    odd.data = b.bytes() + 2;
    expectInputError(import(odd, 3), "albedo", "not aligned");
    StridedImage oddStride = b.image;
    oddStride.pixelStride = 14;
    expectInputError(import(oddStride, 3), "albedo", "not a multiple of the element's 4");
    StridedImage huge = b.image;
    huge.rowStride = int64_t(1) << 50;
    expectInputError(import(huge, 3), "albedo", "out of range");
    StridedImage badType = b.image;
    badType.type = DataType(7);
    expectInputError(import(badType, 3), "albedo", "unknown element type");

    // Exports: checked before the first byte is written.
    auto exportTo = [&](StridedImage s, const ImageView& v) {
        return [s, v] { exportImage(v, s, "output"); };
    };
    StridedImage overlap = b.image;
    overlap.pixelStride = 4;  // each pixel's G on the next one's R
    expectInputError(exportTo(overlap, ref.view()), "output", "overlap");
    StridedImage broadcast = b.image;
    broadcast.rowStride = 0;
    expectInputError(exportTo(broadcast, ref.view()), "output", "overlap");
    const Image small = reference(5, 4, 3);
    expectInputError(exportTo(b.image, small.view()), "output", "is 6x4, the image written is 5x4");
    const Image grey = reference(6, 4, 1);
    expectInputError(exportTo(b.image, grey.view()), "output",
                     "has 3 channels, the image written 1");
    expectInputError(exportTo(b.image, ImageView{}), "output", "no image to write");
    for (size_t i = 0; i < b.size(); ++i)
        ASSERT_EQ(b.bytes()[i], kSentinel) << "byte " << i << " was written";
}

// The same round trips with the image and the buffer on the GPU (the kernels of
// src/cuda/cuda_strided.cu): the bytes written equal the host's, and the import its values.
TEST(Strided, OnTheGpuTheSameBytes) {
    if (!cudaAvailable()) GTEST_SKIP() << "no usable CUDA device";
    const int w = 37, h = 11;
    forEachFormat([&](DataType t, Layout l, int c) {
        const Image ref = reference(w, h, c);
        Buffer host = makeBuffer(w, h, c, t, l);
        exportImage(ref.view(), host.image, "host");
        // A device copy of the sentinel-filled buffer, written by the GPU export.
        Buffer blank = makeBuffer(w, h, c, t, l);
        const size_t origin =
            size_t(static_cast<const unsigned char*>(blank.image.data) - blank.bytes());
        void* dev = detail::allocateBytes(blank.size(), Device::Cuda);
        detail::copyBytes(dev, Device::Cuda, blank.bytes(), Device::Cpu, blank.size());
        StridedImage d = blank.image;
        d.data = static_cast<unsigned char*>(dev) + origin, d.device = Device::Cuda;
        const Image devRef = ref.to(Device::Cuda);
        exportImage(devRef.view(), d, "device");
        std::vector<unsigned char> back(blank.size());
        detail::copyBytes(back.data(), Device::Cpu, dev, Device::Cuda, back.size());
        EXPECT_EQ(std::memcmp(back.data(), host.bytes(), back.size()), 0);
        const Image imported = importImage(d, c, "device").to(Device::Cpu);
        EXPECT_EQ(firstDifference(imported, ref), SIZE_MAX);
        detail::freeBytes(dev, Device::Cuda);
    });
}

}  // namespace
}  // namespace atrous

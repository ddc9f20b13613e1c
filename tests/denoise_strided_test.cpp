// denoise() on buffers given as strided memory in the caller's layout (BufferRef, StridedImage:
// float32 or float16, interleaved or planar, byte strides): the colour, variance and emission are
// converted into the planes the filter works in (no copy of their own: DenoiseReport::copies does
// not name them), the features copied into planar storage (named there). The result is the one of
// the same values given as Images, bit for bit, for every built-in method.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <cstring>
#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "denoise_test_util.h"

using namespace atrous;

using test::firstBitDifference;

namespace {

// An image's values interleaved (H x W x C) as float32, with `pad` extra floats after each row.
std::vector<float> interleaved(const Image& img, int pad = 0) {
    const int w = img.width(), h = img.height(), n = img.channels();
    std::vector<float> out(size_t(h) * size_t(w * n + pad), -7.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < n; ++c) out[size_t(y) * size_t(w * n + pad) + size_t(x * n + c)] = img(x, y, c);
    return out;
}

StridedImage stridedOf(const void* data, DataType t, const Image& like, int64_t rowBytes) {
    StridedImage s;
    s.data = data, s.type = t, s.width = like.width(), s.height = like.height(), s.channels = like.channels();
    const int64_t e = dataTypeBytes(t);
    s.pixelStride = e * like.channels(), s.rowStride = rowBytes, s.channelStride = e;
    return s;
}

// The image rounded to float16 and back (what a float16 buffer holds).
Image halved(const Image& img) {
    Image out = img.clone();
    for (size_t i = 0; i < out.size(); ++i) out.data()[i] = float(Imath::half(out.data()[i]));
    return out;
}

std::vector<Imath::half> interleavedHalf(const Image& img) {
    const std::vector<float> f = interleaved(img);
    return std::vector<Imath::half>(f.begin(), f.end());
}

}  // namespace

TEST(DenoiseStrided, Float32InterleavedColourIsTheImagesResultWithNoCopy) {
    const test::SyntheticScene s = test::makeScene(47, 33, 0.2f, 5);
    for (DenoiseMethod m : {DenoiseMethod::Eaw, DenoiseMethod::Sure, DenoiseMethod::Learned, DenoiseMethod::Blend}) {
        for (bool variance : {true, false}) {
            DenoiseOptions o;
            o.method = m;
            Frame ref = s.inputs();
            if (!variance) ref.variance = nullptr;
            const DenoiseResult a = denoiseWithReport(ref, o);
            // Rows padded by 5 floats: the strides are the caller's, not a packed image's.
            const std::vector<float> c = interleaved(s.noisy, 5), v = interleaved(s.variance);
            Frame f = ref;
            f.color = stridedOf(c.data(), DataType::Float32, s.noisy, int64_t(47 * 3 + 5) * 4);
            if (variance) f.variance = stridedOf(v.data(), DataType::Float32, s.variance, 47 * 3 * 4);
            const DenoiseResult b = denoiseWithReport(f, o);
            EXPECT_EQ(firstBitDifference(a.image, b.image), -1) << denoiseMethodName(m) << " variance " << variance;
            EXPECT_TRUE(b.report.copies.empty()) << denoiseMethodName(m);
            EXPECT_EQ(a.report.buffersUsed, b.report.buffersUsed);
        }
    }
}

TEST(DenoiseStrided, Float16BuffersAreTheirValuesAndOnlyTheFeaturesAreCopied) {
    const test::SyntheticScene s = test::makeScene(40, 29, 0.2f, 9);
    const Image colorH = halved(s.noisy), albedoH = halved(s.albedo);
    Frame ref = s.inputs();
    ref.color = &colorH, ref.albedo = &albedoH;
    DenoiseOptions o;  // auto: blend with an albedo and a normal
    const DenoiseResult a = denoiseWithReport(ref, o);
    const std::vector<Imath::half> c = interleavedHalf(s.noisy), al = interleavedHalf(s.albedo);
    Frame f = s.inputs();
    f.color = stridedOf(c.data(), DataType::Float16, s.noisy, 40 * 3 * 2);
    f.albedo = stridedOf(al.data(), DataType::Float16, s.albedo, 40 * 3 * 2);
    const DenoiseResult b = denoiseWithReport(f, o);
    EXPECT_EQ(firstBitDifference(a.image, b.image), -1);
    ASSERT_EQ(b.report.copies.size(), 1u);
    EXPECT_EQ(b.report.copies[0], "albedo (float16, 3 channels)");
    EXPECT_EQ(b.report.methodUsed, DenoiseMethod::Blend);
}

TEST(DenoiseStrided, PlanarFloatStridedMemoryAndBadLayoutsAreHandled) {
    const test::SyntheticScene s = test::makeScene(31, 22, 0.2f, 2);
    DenoiseOptions o;
    o.method = DenoiseMethod::Sure;
    const Image a = denoise(s.inputs(), o);
    // The colour's own planes described as strided memory: the same as the Image.
    Frame f = s.inputs();
    f.color = s.noisy.strided();  // a StridedImage, not the Image
    EXPECT_FALSE(f.color.isImage());
    EXPECT_EQ(firstBitDifference(a, denoise(f, o)), -1);
    // A buffer of another size, a colour of two channels: InputErrors naming the buffer.
    const std::vector<float> c = interleaved(s.noisy);
    StridedImage small = stridedOf(c.data(), DataType::Float32, s.noisy, 31 * 3 * 4);
    small.width = 30;
    f.color = small;
    EXPECT_NE(test::inputErrorOf(f, o).find("30x22"), std::string::npos) << test::inputErrorOf(f, o);
    StridedImage two = stridedOf(c.data(), DataType::Float32, s.noisy, 31 * 3 * 4);
    two.channels = 2;
    f.color = two;
    EXPECT_NE(test::inputErrorOf(f, o).find("color"), std::string::npos) << test::inputErrorOf(f, o);
    // A filter that needs Images says so instead of reading a null pointer.
    const BufferRef r = StridedImage(s.noisy.strided());
    EXPECT_THROW((void)r.image(), InputError);
}

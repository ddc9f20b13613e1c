// Motion from the frames themselves (estimateMotion, include/atrous/temporal.h): a textured image
// moved by a known offset gives that offset (previous − current), exactly away from the border,
// at shifts up to the coarsest level's reach; a flat image and an unmoved one give zero; noise of a
// few samples per pixel does not throw the estimate off by more than a pixel; bad inputs throw; no
// previous frame gives NaN (no history).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "atrous/error.h"
#include "atrous/temporal.h"

namespace atrous {
namespace {

// A smooth random texture (sums of sines), sampled at (x + ox, y + oy), plus Gaussian noise.
Image texture(int w, int h, float ox, float oy, float noise = 0.0f, unsigned seed = 1) {
    Image img(w, h, 3);
    std::mt19937 rng(seed);
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float u = x + ox, v = y + oy;
            const float t = 0.5f + 0.2f * std::sin(0.31f * u + 0.7f) * std::cos(0.23f * v) + 0.15f * std::sin(0.11f * u - 0.17f * v) +
                            0.1f * std::cos(0.53f * v + 0.29f * u);
            for (int c = 0; c < 3; ++c) img(x, y, c) = std::max(0.0f, t * (1.0f + 0.2f * c) + noise * n(rng));
        }
    return img;
}

// The largest |estimate − want| over the pixels at least `margin` from the border.
float worstError(const Image& m, float wx, float wy, int margin) {
    float worst = 0;
    for (int y = margin; y < m.height() - margin; ++y)
        for (int x = margin; x < m.width() - margin; ++x)
            worst = std::max({worst, std::fabs(m(x, y, 0) - wx), std::fabs(m(x, y, 1) - wy)});
    return worst;
}

TEST(MotionEstimate, RecoversAKnownShift) {
    // previous(x + d) = current(x): the point now at x was at x + d, so the motion is d.
    for (const auto& d : {std::pair{3, -2}, std::pair{-7, 5}, std::pair{19, 11}, std::pair{0, 0}}) {
        const Image previous = texture(160, 120, 0, 0);
        const Image current = texture(160, 120, float(d.first), float(d.second));
        const Image m = estimateMotion(current, &previous);
        ASSERT_EQ(m.channels(), 2);
        EXPECT_LT(worstError(m, float(d.first), float(d.second), 32), 1e-4f) << d.first << "," << d.second;
    }
}

TEST(MotionEstimate, NoisyFramesStayWithinAPixel) {
    const Image previous = texture(160, 120, 0, 0, 0.15f, 1);
    const Image current = texture(160, 120, 4, -3, 0.15f, 2);
    EXPECT_LE(worstError(estimateMotion(current, &previous), 4, -3, 32), 1.0f);
}

TEST(MotionEstimate, FlatFramesGiveZero) {
    Image flat(64, 48, 3);
    for (size_t i = 0; i < flat.size(); ++i) flat.data()[i] = 0.5f;
    EXPECT_EQ(worstError(estimateMotion(flat, &flat), 0, 0, 0), 0.0f);
}

TEST(MotionEstimate, BadInputsThrow) {
    const Image a(32, 32, 3), b(32, 16, 3);
    EXPECT_THROW(estimateMotion(a, &b), InputError);
    EXPECT_THROW(estimateMotion(Image(), &a), InputError);
    MotionEstimateParams p;
    p.block = 1;
    EXPECT_THROW(estimateMotion(a, &a, p), InputError);
    // No previous frame: NaN, no history.
    const Image none = estimateMotion(a, nullptr);
    EXPECT_EQ(none.channels(), 2);
    EXPECT_TRUE(std::isnan(none(5, 7, 0)) && std::isnan(none(5, 7, 1)));
}

}  // namespace
}  // namespace atrous

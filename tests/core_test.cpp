#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <vector>

#include "atrous/error.h"
#include "atrous/image.h"
#include "core/parallel.h"
#include "core/rng.h"

using namespace atrous;

TEST(Image, AllocatesZeroedPlanarStorage) {
    Image img(7, 5, 3);
    EXPECT_EQ(img.width(), 7);
    EXPECT_EQ(img.height(), 5);
    EXPECT_EQ(img.size(), 7u * 5u * 3u);
    for (size_t i = 0; i < img.size(); ++i) EXPECT_EQ(img.data()[i], 0.0f);
    img(3, 2, 1) = 4.0f;
    EXPECT_EQ(img.data()[1 * 35 + 2 * 7 + 3], 4.0f);
    EXPECT_EQ(img.view()(3, 2, 1), 4.0f);
}

TEST(Image, RejectsBadSizes) {
    EXPECT_THROW(Image(0, 5, 3), InputError);
    EXPECT_THROW(Image(5, -1, 3), InputError);
    EXPECT_THROW(Image(kMaxImageDim + 1, 4, 3), InputError);
}

TEST(Image, CloneIsDeepAndMoveTransfersOwnership) {
    Image a(4, 4, 1);
    a.fill(2.0f);
    Image b = a.clone();
    b(0, 0, 0) = 9.0f;
    EXPECT_EQ(a(0, 0, 0), 2.0f);
    Image c = std::move(b);
    EXPECT_TRUE(b.empty());
    EXPECT_EQ(c(0, 0, 0), 9.0f);
}

TEST(Parallel, VisitsEveryPixelOnce) {
    const int w = 37, h = 23;
    std::vector<std::atomic<int>> hits(w * h);
    parallelFor2dCpu(w, h, [&](int x, int y) { hits[y * w + x]++; });
    for (auto& v : hits) EXPECT_EQ(v.load(), 1);
}

TEST(Rng, StreamsAreDeterministicAndDistinct) {
    Rng a(10, 3, 42), b(10, 3, 42), c(11, 3, 42), d(10, 4, 42), e(10, 3, 43);
    uint32_t va = a.nextU32();
    EXPECT_EQ(va, b.nextU32());
    std::set<uint32_t> firsts{va, c.nextU32(), d.nextU32(), e.nextU32()};
    EXPECT_EQ(firsts.size(), 4u);
}

TEST(Rng, UniformMeanAndVariance) {
    // Mean 1/2 and variance 1/12 of U[0,1); with n = 1e6 the standard errors are 2.9e-4 and
    // 8.3e-5, so bounds of 2e-3 are over 6 sigma.
    Rng r(1, 2, 3);
    const int n = 1000000;
    double s = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
        double v = r.next();
        ASSERT_GE(v, 0.0);
        ASSERT_LT(v, 1.0);
        s += v;
        s2 += v * v;
    }
    double mean = s / n, var = s2 / n - mean * mean;
    EXPECT_NEAR(mean, 0.5, 2e-3);
    EXPECT_NEAR(var, 1.0 / 12.0, 2e-3);
}

// The stratified pixel sampler (src/core/sampler.h): the (0,2)-net property of the scrambled
// Sobol points and their uniformity across pixels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/sampler.h"

namespace atrous {
namespace {

// True when the n = 2^m points put exactly one point in every elementary interval of area 1/n:
// every grid of 2^a x 2^(m-a) cells, a = 0..m (this includes the sqrt(n) x sqrt(n) strata for even
// m, and the n horizontal and n vertical strips).
::testing::AssertionResult isZeroMTwoNet(const std::vector<Vec2>& pts, int m) {
    const int n = 1 << m;
    if (int(pts.size()) != n) return ::testing::AssertionFailure() << "expected " << n << " points";
    for (int a = 0; a <= m; ++a) {
        const int nx = 1 << a, ny = 1 << (m - a);
        std::vector<int> count(size_t(n), 0);
        for (const Vec2& p : pts) {
            if (!(p.x >= 0.0f && p.x < 1.0f && p.y >= 0.0f && p.y < 1.0f))
                return ::testing::AssertionFailure() << "point (" << p.x << ", " << p.y << ") outside [0,1)^2";
            int cx = int(p.x * float(nx)), cy = int(p.y * float(ny));
            ++count[size_t(cy * nx + cx)];
        }
        for (int i = 0; i < n; ++i)
            if (count[size_t(i)] != 1)
                return ::testing::AssertionFailure()
                       << "grid " << nx << "x" << ny << ": cell " << i << " holds " << count[size_t(i)] << " points";
    }
    return ::testing::AssertionSuccess();
}

TEST(Sampler, ReverseBitsAndSobolDirectionNumbers) {
    EXPECT_EQ(reverseBits32(1u), 0x80000000u);
    EXPECT_EQ(reverseBits32(0x80000000u), 1u);
    EXPECT_EQ(reverseBits32(0x12345678u), 0x1e6a2c48u);
    // Sobol dimension 1 in index order: 0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8.
    const double expected[8] = {0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
    for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(double(sobolDim1(i)) / 4294967296.0, expected[i]) << "index " << i;
    // The bit-parallel form equals the direction-number loop for every bit pattern.
    uint32_t x = 12345u;
    for (int k = 0; k < 100000; ++k) {
        x = hash32(x + uint32_t(k));
        uint32_t index = k < 1024 ? uint32_t(k) : x;
        ASSERT_EQ(sobolDim1(index), sobolDim1Reference(index)) << "index " << index;
    }
    EXPECT_EQ(sobolDim1(0xffffffffu), sobolDim1Reference(0xffffffffu));
}

TEST(Sampler, UnscrambledSequenceIsAZeroTwoSequence) {
    // Every aligned block [k 2^m, (k+1) 2^m) of a (0,2)-sequence is a (0,m,2)-net.
    for (int m : {2, 4, 6, 8})
        for (uint32_t k : {0u, 1u, 5u}) {
            std::vector<Vec2> pts;
            for (uint32_t i = k << m; i < (k + 1) << m; ++i)
                pts.push_back(Vec2(fixedToUnitFloat(sobolDim0(i)), fixedToUnitFloat(sobolDim1(i))));
            EXPECT_TRUE(isZeroMTwoNet(pts, m)) << "m = " << m << ", block " << k;
        }
}

// n = 16 and 64 scrambled points are (0,4,2)- and (0,6,2)-nets: one point per 4x4 / 8x8 stratum
// and per elementary interval, for many pixels and seeds, for the first block (independent
// renders: index s) and later aligned blocks (progressive accumulation: index frame * spp + s).
TEST(Sampler, ScrambledPointsFormNetsForEveryPixelAndSeed) {
    for (int m : {4, 6})
        for (uint32_t seed : {1u, 2u, 4099u, 0xdeadbeefu})
            for (uint32_t pixel = 0; pixel < 200; pixel += 7)
                for (uint32_t block : {0u, 1u, 9u}) {
                    const uint32_t n = 1u << m, sSeed = pixelSamplerSeed(pixel, seed);
                    std::vector<Vec2> pts;
                    for (uint32_t s = 0; s < n; ++s) pts.push_back(sobol02Scrambled(block * n + s, sSeed));
                    ASSERT_TRUE(isZeroMTwoNet(pts, m))
                        << "n = " << n << ", seed " << seed << ", pixel " << pixel << ", block " << block;
                }
}

TEST(Sampler, ScramblingDependsOnPixelAndSeed) {
    Vec2 a = sobol02Scrambled(0, pixelSamplerSeed(10, 1));
    Vec2 b = sobol02Scrambled(0, pixelSamplerSeed(11, 1));
    Vec2 c = sobol02Scrambled(0, pixelSamplerSeed(10, 2));
    EXPECT_TRUE(a.x != b.x || a.y != b.y);
    EXPECT_TRUE(a.x != c.x || a.y != c.y);
}

// Owen scrambling makes every single point uniform on [0,1)^2, whatever its index: over P pixels
// the mean of point s must be 1/2 and its variance 1/12 in each coordinate. The standard error of
// the mean is sqrt(1/12 / P) = 0.0020 for P = 20000, so the bound 0.012 is 6 sigma (and an
// unscrambled point 0 at (0, 0), or a scramble that left the top bit fixed, would be off by
// >= 0.25); the variance's standard error is sqrt(1/180 / P) = 5.3e-4, bound 0.004 is 7.5 sigma.
TEST(Sampler, EveryIndexIsUniformOnAverageOverPixels) {
    const int kPixels = 20000;
    for (uint32_t seed : {1u, 77u})
        for (uint32_t s : {0u, 1u, 2u, 3u, 7u, 15u, 16u, 63u, 1000u}) {
            double sum[2] = {0, 0}, sq[2] = {0, 0};
            for (int p = 0; p < kPixels; ++p) {
                Vec2 v = sobol02Scrambled(s, pixelSamplerSeed(uint32_t(p), seed));
                sum[0] += v.x;
                sum[1] += v.y;
                sq[0] += double(v.x) * v.x;
                sq[1] += double(v.y) * v.y;
            }
            for (int d = 0; d < 2; ++d) {
                double mean = sum[d] / kPixels, var = sq[d] / kPixels - mean * mean;
                EXPECT_NEAR(mean, 0.5, 0.012) << "index " << s << ", dim " << d << ", seed " << seed;
                EXPECT_NEAR(var, 1.0 / 12.0, 0.004) << "index " << s << ", dim " << d << ", seed " << seed;
            }
        }
}

// Joint uniformity (x and y of one point are not correlated across pixels): a 16x16 histogram of
// point 0 over 65536 pixels. Chi-square with 255 degrees of freedom has mean 255 and standard
// deviation 22.6; the bound 400 is > 6 sigma.
TEST(Sampler, FirstPointIsJointlyUniformOverPixels) {
    const int kBins = 16, kPixels = 65536;
    std::vector<int> hist(kBins * kBins, 0);
    for (int p = 0; p < kPixels; ++p) {
        Vec2 v = sobol02Scrambled(0, pixelSamplerSeed(uint32_t(p), 3));
        ++hist[size_t(int(v.y * kBins) * kBins + int(v.x * kBins))];
    }
    const double expected = double(kPixels) / (kBins * kBins);
    double chi2 = 0.0;
    for (int h : hist) chi2 += (h - expected) * (h - expected) / expected;
    EXPECT_LT(chi2, 400.0);
}

// Non-powers of two use the sequence's prefix (here 12 spp): its first 8 points are a (0,3,2)-net
// and the next 4, an aligned block of 4 indices, a (0,2,2)-net (one point per 2x2 stratum).
TEST(Sampler, PrefixOfANonPowerOfTwoStartsWithANet) {
    const uint32_t seed = pixelSamplerSeed(5, 9);
    std::vector<Vec2> pts;
    for (uint32_t s = 0; s < 8; ++s) pts.push_back(sobol02Scrambled(s, seed));
    EXPECT_TRUE(isZeroMTwoNet(pts, 3));  // the first 8 of a 12-spp pixel
    // The next 4 (indices 8..11) are the first half of the next 8-block: one per 2x2 stratum.
    int cells[4] = {0, 0, 0, 0};
    for (uint32_t s = 8; s < 12; ++s) {
        Vec2 v = sobol02Scrambled(s, seed);
        ++cells[int(v.y * 2) * 2 + int(v.x * 2)];
    }
    for (int c : cells) EXPECT_EQ(c, 1);
}

}  // namespace
}  // namespace atrous

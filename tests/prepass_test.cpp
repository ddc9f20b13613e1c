// The CPU row loops of the pre-passes (src/cpu/prepass_cpu.cpp) against the shared per-pixel
// functors of src/filters/prepass.h that the CUDA backend runs: non-finite colour repair, the
// feature buffers used in place when clean, the colour scale S and the footprint 1/σ_x².
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/parallel.h"
#include "filters/prepass.h"
#include "test_util.h"

using namespace atrous;
using namespace atrous::filters;

namespace {

using test::randomImage;

// Largest |a - b| / max(|b|, 1e-30); identical non-finite values count as equal.
double maxRelDiff(const Image& a, const Image& b) {
    double m = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        const float x = a.data()[i], y = b.data()[i];
        if (x == y) continue;
        m = std::max(m, std::fabs(double(x) - double(y)) / std::max(std::fabs(double(y)), 1e-30));
    }
    return m;
}

// Sizes with a row loop interior, and degenerate ones that go through the functor.
const int kSizes[][2] = {{37, 23}, {3, 5}, {2, 4}, {1, 1}, {64, 1}};

}  // namespace

TEST(Prepass, SanitizeColorRowLoopEqualsFunctor) {
    for (auto& sz : kSizes) {
        const int w = sz[0], h = sz[1];
        Image c = randomImage(w, h, 3, 1, 0.0f, 2.0f), v = randomImage(w, h, 3, 2, 0.0f, 0.1f);
        // Non-finite samples in a few places, one at a corner.
        c(0, 0, 1) = NAN;
        c(w / 2, h / 2, 0) = INFINITY;
        v(w - 1, h - 1, 2) = -INFINITY;
        v(w / 3, 0, 0) = NAN;
        Image c1(w, h, 3), v1(w, h, 3), c2(w, h, 3), v2(w, h, 3);
        runSanitizeColor(CpuExec{}, SanitizeColor{c.view(), v.view(), c1.view(), v1.view()});
        CpuExec{}.forEachPixel(w, h, SanitizeColor{c.view(), v.view(), c2.view(), v2.view()});
        // Copies and the same repair code: bit-equal.
        EXPECT_EQ(maxRelDiff(c1, c2), 0.0) << w << "x" << h;
        EXPECT_EQ(maxRelDiff(v1, v2), 0.0) << w << "x" << h;
        for (size_t i = 0; i < c1.size(); ++i) ASSERT_TRUE(std::isfinite(c1.data()[i]) && std::isfinite(v1.data()[i]));
    }
}

TEST(Prepass, CleanFeatureIsUsedInPlaceAndDirtyOneIsSanitised) {
    const int w = 19, h = 7;
    Image clean = randomImage(w, h, 3, 3, -5.0f, 5.0f);
    Image storage;
    ImageView got = sanitizedFeature(CpuExec{}, clean.view(), w, h, 2, storage);
    EXPECT_EQ(got.data, clean.data());  // no copy
    EXPECT_TRUE(storage.empty());

    Image dirty = clean.clone();
    dirty(3, 2, 1) = NAN;  // channel 1 of 2: checked
    dirty(5, 6, 0) = 1e30f;  // beyond kFeatureClamp
    got = sanitizedFeature(CpuExec{}, dirty.view(), w, h, 2, storage);
    ASSERT_FALSE(storage.empty());
    EXPECT_EQ(got.data, storage.data());
    Image ref(w, h, 2);
    CpuExec{}.forEachPixel(w, h, SanitizeFeature{dirty.view(), ref.view()});
    EXPECT_EQ(maxRelDiff(storage, ref), 0.0);
    EXPECT_EQ(storage(3, 2, 1), 0.0f);
    EXPECT_EQ(storage(5, 6, 0), kFeatureClamp);

    // Only the channels asked for are checked: a NaN in channel 2 of a 1-channel feature is fine.
    Image third = clean.clone();
    third(1, 1, 2) = NAN;
    got = sanitizedFeature(CpuExec{}, third.view(), w, h, 1, storage);
    EXPECT_EQ(got.data, third.data());

    // Absent: zeros.
    got = sanitizedFeature(CpuExec{}, ImageView{}, w, h, 3, storage);
    ASSERT_FALSE(storage.empty());
    for (size_t i = 0; i < storage.size(); ++i) ASSERT_EQ(storage.data()[i], 0.0f);
}

TEST(Prepass, ColorScaleRowLoopEqualsFunctor) {
    for (auto& sz : kSizes) {
        const int w = sz[0], h = sz[1];
        Image v = randomImage(w, h, 3, 4, 0.0f, 0.2f);
        v(w / 2, h / 2, 1) = 50.0f;  // one very noisy pixel: excluded from its neighbours' scale
        Image s1(w, h, 1), s2(w, h, 1);
        ColorScale f{0.0f, 36.0f, v.view(), s1.view()};
        runColorScale(CpuExec{}, f);
        f.S = s2.view();
        CpuExec{}.forEachPixel(w, h, f);
        // Same operations in the same order; the vectorised loop may contract a·b + c into an
        // FMA where the scalar one did not: a few ulp, 1e-6 relative.
        EXPECT_LT(maxRelDiff(s1, s2), 1e-6) << w << "x" << h;
    }
}

TEST(Prepass, FootprintRowLoopEqualsFunctor) {
    for (auto& sz : kSizes) {
        const int w = sz[0], h = sz[1];
        Image pos = randomImage(w, h, 3, 5, -3.0f, 3.0f), depth = randomImage(w, h, 3, 6, -10.0f, 10.0f);
        // Equal neighbours (a zero distance) and a zero depth.
        if (w > 2) {
            for (int c = 0; c < 3; ++c) pos(1, 0, c) = pos(2, 0, c);
        }
        depth(0, 0, 0) = 0.0f;
        Image x1(w, h, 1), z1(w, h, 1), x2(w, h, 1), z2(w, h, 1);
        Footprint f{1, 0.0f, 4.0f, pos.view(), depth.view(), x1.view(), z1.view()};
        runFootprint(CpuExec{}, f);
        f.invX = x2.view();
        f.invZ = z2.view();
        CpuExec{}.forEachPixel(w, h, f);
        // Sums of three squares, possibly contracted to FMAs differently: 1e-6 relative.
        EXPECT_LT(maxRelDiff(x1, x2), 1e-6) << w << "x" << h;
        EXPECT_EQ(maxRelDiff(z1, z2), 0.0) << w << "x" << h;
    }
}

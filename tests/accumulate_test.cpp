// The viewer's accumulation and motion functors (src/render/accumulate.h) on the CPU: the same
// code CudaExec launches on the GPU.
#include "render/accumulate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "atrous/render.h"
#include "render/integrator.h"
#include "motion_test_util.h"

namespace atrous {
namespace {

// A 3-channel frame of the renderer's buffers plus the accumulator's outputs and state.
struct Buffers {
    Image color, variance, albedo, normal, position, depth, ids, emission;
};

Buffers makeBuffers(int w, int h) {
    Buffers b;
    for (Image* img : {&b.color, &b.variance, &b.albedo, &b.normal, &b.position, &b.depth, &b.ids, &b.emission})
        *img = Image(w, h, 3);
    return b;
}

struct Accumulator {
    Buffers out;
    Image moments, normalMean, counts;
    int frames = 0;

    Accumulator(int w, int h)
        : out(makeBuffers(w, h)), moments(w, h, kAccumMomentChannels), normalMean(w, h, kAccumNormalChannels),
          counts(w, h, kAccumCountChannels) {}

    void add(const Buffers& f, int spp, bool restart = false, bool seed = true) {
        if (restart || frames == 0) frames = 0;
        ++frames;
        AccumulateFrame a;
        a.p = makeAccumulateParams(frames == 1, seed, frames, spp, kBackgroundDepth);
        a.color = f.color.view(), a.variance = f.variance.view(), a.albedo = f.albedo.view();
        a.normal = f.normal.view(), a.position = f.position.view(), a.depth = f.depth.view();
        a.ids = f.ids.view(), a.emission = f.emission.view();
        a.outColor = out.color.view(), a.outVariance = out.variance.view(), a.outAlbedo = out.albedo.view();
        a.outNormal = out.normal.view(), a.outPosition = out.position.view(), a.outDepth = out.depth.view();
        a.outIds = out.ids.view(), a.outEmission = out.emission.view();
        a.moments = moments.view(), a.normalMean = normalMean.view(), a.counts = counts.view();
        runAccumulateFrame(Device::Cpu, a);
    }
};

double relErr(double got, double want) { return std::fabs(got - want) / std::max(std::fabs(want), 1e-30); }

// Mean and pooled variance of the mean after 256 frames against a double-precision reference.
// Pixels span dim to very bright means with relative noise from 1 to 1e-4: the bright, nearly
// noise-free ones are where E[x²] − E[x]² in float loses every digit.
void checkColourMoments(int spp) {
    const int w = 6, h = 4, frames = 256;
    const size_t plane = size_t(w) * h;
    std::mt19937 rng(1234 + spp);
    std::vector<double> mu(3 * plane), sigma(3 * plane);
    for (size_t i = 0; i < 3 * plane; ++i) {
        mu[i] = std::pow(10.0, -2.0 + 5.0 * double(i % 7) / 6.0);     // 0.01 .. 1000
        sigma[i] = mu[i] * std::pow(10.0, -4.0 * double(i % 5) / 4.0);  // 1 .. 1e-4 relative
    }
    Accumulator acc(w, h);
    std::vector<double> sx(3 * plane, 0.0), sx2(3 * plane, 0.0), sm2(3 * plane, 0.0);
    std::vector<float> fx(3 * plane, 0.0f), fx2(3 * plane, 0.0f);  // the float E[x²] − E[x]² form
    Buffers f = makeBuffers(w, h);
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::gamma_distribution<double> chi(2.0, 1.0);
    for (int k = 0; k < frames; ++k) {
        for (size_t i = 0; i < 3 * plane; ++i) {
            const float x = float(mu[i] + sigma[i] / std::sqrt(double(spp)) * gauss(rng));
            // The renderer's variance of the frame mean: σ²/s with its own sampling spread.
            const float v = spp > 1 ? float(sigma[i] * sigma[i] / spp * chi(rng) / 2.0) : 0.0f;
            f.color.data()[i] = x;
            f.variance.data()[i] = v;
            sx[i] += x;
            sx2[i] += double(x) * x;
            sm2[i] += double(v) * spp * (spp - 1.0);
            fx[i] += x;
            fx2[i] += x * x;
        }
        acc.add(f, spp);
    }
    const double n = double(frames) * spp;
    double worstMean = 0, worstVar = 0, worstNaive = 0;
    for (size_t i = 0; i < 3 * plane; ++i) {
        const double mean = sx[i] / frames;
        const double m2 = sm2[i] + spp * std::max(0.0, sx2[i] - sx[i] * mean);
        const double var = m2 / (n * (n - 1.0));
        worstMean = std::max(worstMean, relErr(acc.out.color.data()[i], mean));
        worstVar = std::max(worstVar, relErr(acc.out.variance.data()[i], var));
        const float fm = fx[i] / float(frames);
        const float naive = float(spp) * std::max(0.0f, fx2[i] - fx[i] * fm) / float(n * (n - 1.0)) +
                            float(sm2[i] / (n * (n - 1.0)));
        worstNaive = std::max(worstNaive, relErr(naive, var));
    }
    std::printf("spp %d, %d frames: worst relative error of the mean %.2e, of the variance %.2e "
                "(float E[x^2] - E[x]^2: %.2e)\n",
                spp, frames, worstMean, worstVar, worstNaive);
    // Tolerances: the compensated mean hi + lo is exact to ~2^-48 relative, so the output hi is
    // the double mean rounded once (≤ 2^-24 = 6e-8 relative): 1e-6. Each deviation x − x̄ is exact
    // to ~2^-24 σ, so M2 (and the pooled variance) carries a few 1e-7 relative whatever σ/x̄
    // (measured ≤ 1e-6 at σ/x̄ from 1 to 1e-4); 1e-5 leaves room and still separates it from
    // plain float Welford, which is off by 1e-3 at σ/x̄ = 1e-4.
    EXPECT_LT(worstMean, 1e-6) << "spp " << spp;
    EXPECT_LT(worstVar, 1e-5) << "spp " << spp;
    // The check can fail: the float E[x²] − E[x]² form misses it by orders of magnitude.
    EXPECT_GT(worstNaive, 1e-2) << "spp " << spp;
}

TEST(Accumulate, MeanAndPooledVarianceMatchDoublesAfter256FramesAt1Spp) { checkColourMoments(1); }
TEST(Accumulate, MeanAndPooledVarianceMatchDoublesAfter256FramesAt4Spp) { checkColourMoments(4); }

TEST(Accumulate, FeaturesAreMeansOverHitsAndIdsStayTheFirstFrames) {
    const int w = 5, h = 3, frames = 20;
    const size_t plane = size_t(w) * h;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Accumulator acc(w, h);
    Buffers f = makeBuffers(w, h);
    // Reference sums in double, per the old host code: normals and positions averaged over frames
    // whose primary hit exists (normal ≠ 0), depth over frames that hit (depth < 0.1 · background).
    std::vector<double> sa(3 * plane, 0), se(3 * plane, 0), sn(3 * plane, 0), sp(3 * plane, 0), sd(plane, 0);
    std::vector<int> fh(plane, 0), dh(plane, 0);
    std::vector<float> firstIds(3 * plane);
    for (int k = 0; k < frames; ++k) {
        for (size_t p = 0; p < plane; ++p) {
            // Pixel 0 never hits, pixel 1 hits only from frame 5 on, the rest hit 70% of frames.
            const bool hit = p == 0 ? false : p == 1 ? k >= 5 : u(rng) < 0.7f;
            const float z = hit ? 1.0f + 4.0f * u(rng) : kBackgroundDepth;
            Vec3 nrm = normalize(Vec3(u(rng) - 0.5f, u(rng) - 0.5f, 1.0f));
            if (!hit) nrm = Vec3(0.0f);
            for (int c = 0; c < 3; ++c) {
                const size_t i = c * plane + p;
                f.albedo.data()[i] = u(rng);
                f.emission.data()[i] = u(rng) < 0.2f ? 5.0f * u(rng) : 0.0f;
                f.normal.data()[i] = nrm[c];
                f.position.data()[i] = hit ? 10.0f * u(rng) - 5.0f : 0.0f;
                f.depth.data()[i] = z;
                f.ids.data()[i] = float(k * 100 + int(p));
                f.color.data()[i] = u(rng);
                sa[i] += f.albedo.data()[i];
                se[i] += f.emission.data()[i];
                if (hit) {
                    sn[i] += f.normal.data()[i];
                    sp[i] += f.position.data()[i];
                }
                if (k == 0) firstIds[i] = f.ids.data()[i];
            }
            fh[p] += hit;
            dh[p] += hit;
            if (hit) sd[p] += z;
        }
        acc.add(f, 1);
    }
    // Float running means of values in [−5, 10] over 20 frames: a few ulps; 1e-5 absolute.
    const float tol = 1e-5f;
    for (size_t p = 0; p < plane; ++p) {
        double nrm[3], len2 = 0;
        for (int c = 0; c < 3; ++c) {
            nrm[c] = fh[p] ? sn[c * plane + p] / fh[p] : 0.0;
            len2 += nrm[c] * nrm[c];
        }
        const double inv = len2 > 0 ? 1.0 / std::sqrt(len2) : 0.0;
        for (int c = 0; c < 3; ++c) {
            const size_t i = c * plane + p;
            EXPECT_NEAR(acc.out.albedo.data()[i], sa[i] / frames, tol) << i;
            EXPECT_NEAR(acc.out.emission.data()[i], se[i] / frames, tol) << i;
            EXPECT_NEAR(acc.out.position.data()[i], fh[p] ? sp[i] / fh[p] : 0.0, tol) << i;
            EXPECT_NEAR(acc.out.normal.data()[i], nrm[c] * inv, tol) << i;
            if (dh[p])
                EXPECT_NEAR(acc.out.depth.data()[i], sd[p] / dh[p], 1e-5 * 5) << i;
            else
                EXPECT_EQ(acc.out.depth.data()[i], kBackgroundDepth) << i;
            EXPECT_EQ(acc.out.ids.data()[i], firstIds[i]) << i;
        }
    }
    // Pixel 1's first hit (frame 5) sets its features outright: exactly the later mean of hits.
    EXPECT_EQ(acc.counts.data()[1], 15.0f);
    EXPECT_EQ(acc.counts.data()[0], 0.0f);
}

TEST(Accumulate, RestartCopiesTheFrameAndDropsTheOldMean) {
    const int w = 4, h = 2;
    Accumulator acc(w, h);
    Buffers a = makeBuffers(w, h), b = makeBuffers(w, h);
    for (Image* img : {&a.color, &a.variance, &a.albedo, &a.normal, &a.position, &a.depth, &a.ids, &a.emission})
        img->fill(3.0f);
    for (Image* img : {&b.color, &b.variance, &b.albedo, &b.normal, &b.position, &b.depth, &b.ids, &b.emission})
        img->fill(0.5f);
    acc.add(a, 4);
    acc.add(a, 4);
    acc.add(b, 4, /*restart=*/true, /*seed=*/false);  // --no-accumulate: the frame as it is
    for (size_t i = 0; i < acc.out.color.size(); ++i) {
        EXPECT_EQ(acc.out.color.data()[i], 0.5f);
        EXPECT_EQ(acc.out.variance.data()[i], 0.5f);  // the renderer's own variance of the frame
        EXPECT_EQ(acc.out.normal.data()[i], 0.5f);     // as rendered, not renormalised
        EXPECT_EQ(acc.out.ids.data()[i], 0.5f);
        EXPECT_EQ(acc.out.emission.data()[i], 0.5f);
    }
    // Seeded restart, then one more frame: the mean of the two, variance from both terms.
    acc.add(a, 4, /*restart=*/true);
    acc.add(b, 4);
    // n = 8 samples; M2 = Σ M2_k + s Σ (x_k − x̄)² = 2 · 4 · 3 · v̄ + 4 · 2 · 1.25², v̄ = 1.75.
    const double var = (2 * 4 * 3 * 1.75 + 4 * 2 * 1.25 * 1.25) / (8.0 * 7.0);
    for (size_t i = 0; i < acc.out.color.size(); ++i) {
        EXPECT_FLOAT_EQ(acc.out.color.data()[i], 1.75f);
        EXPECT_FLOAT_EQ(acc.out.variance.data()[i], float(var));
        EXPECT_EQ(acc.out.ids.data()[i], 3.0f);
    }
}

pt::Camera lookAt(Vec3 eye, Vec3 target) { return pt::makeLookAtCamera(eye, target, Vec3(0, 1, 0), 45.0f); }

TEST(MotionFromDepth, ReprojectsTheRebuiltHitIntoThePreviousCamera) {
    const int w = 32, h = 24;
    const pt::Camera cur = lookAt(Vec3(0.3f, 0.2f, 5.0f), Vec3(0, 0, 0));
    const pt::Camera prev = lookAt(Vec3(-0.4f, 0.0f, 5.5f), Vec3(0.1f, 0, 0));
    Image depth(w, h, 3), motion(w, h, 3);
    std::vector<Vec3> points(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const Vec3 dir = pt::cameraRayDirection(cur, x + 0.5f, y + 0.5f, w, h);
            const float t = 3.0f + 0.05f * float(x + y);  // a tilted surface
            points[i] = cur.position + dir * t;
            // The last row is background: it moves like a direction.
            depth.data()[i] = y == h - 1 ? kBackgroundDepth : dot(points[i] - cur.position, cur.forward);
        }
    MotionFromDepth m = test::motionFromDepth(cur, prev, depth, motion);
    runMotionFromDepth(Device::Cpu, m);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const Vec3 off = y == h - 1 ? pt::cameraRayDirection(cur, x + 0.5f, y + 0.5f, w, h)
                                        : points[i] - prev.position;
            float px = 0, py = 0;
            ASSERT_TRUE(pt::projectToImage(prev, off, w, h, px, py));
            // Float rebuild of a point ~5 units away, projected to a 32-pixel image: 1e-3 px.
            EXPECT_NEAR(motion(x, y, 0), px - (x + 0.5f), 1e-3f) << x << "," << y;
            EXPECT_NEAR(motion(x, y, 1), py - (y + 0.5f), 1e-3f) << x << "," << y;
            EXPECT_EQ(motion(x, y, 2), 0.0f);
        }
    // A point behind the previous camera has no history.
    m.p.previous = lookAt(Vec3(0, 0, -10.0f), Vec3(0, 0, -20.0f));
    runMotionFromDepth(Device::Cpu, m);
    EXPECT_EQ(motion(w / 2, h / 2, 0), pt::kMotionOffscreen);
    // No camera move: zero motion everywhere.
    m.p.moved = 0;
    runMotionFromDepth(Device::Cpu, m);
    for (size_t i = 0; i < motion.size(); ++i) EXPECT_EQ(motion.data()[i], 0.0f);
}

}  // namespace
}  // namespace atrous

// SVGF à-trous CPU fast path (src/cpu/svgf_atrous_cpu.cpp) against the generic functor
// svgf::Atrous run through plain per-pixel loops, on random inputs with every special case the
// functor has (empty pixels, background depth, missing and opposite normals, zero variance,
// depth edges), every level step, sizes that are not a multiple of the vector width and images
// smaller than the kernel's reach; for the AVX2 and (where the CPU has it) AVX-512 loops. Also
// the accuracy of fastLog, which the fast path and the GPU share.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "atrous/svgf.h"
#include "core/parallel.h"
#include "filters/svgf_atrous.h"
#include "filters/svgf_gbuffer.h"

using namespace atrous;

namespace {

// Buffers of one level with random content.
struct LevelInputs {
    int w, h;
    Image illum, variance, length, depth, normal, depthGrad;
    LevelInputs(int w_, int h_, unsigned seed)
        : w(w_),
          h(h_),
          illum(w_, h_, 3),
          variance(w_, h_, 1),
          length(w_, h_, 1),
          depth(w_, h_, 1),
          normal(w_, h_, 3),
          depthGrad(w_, h_, 2) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        std::exponential_distribution<float> heavy(1.0f);
        std::normal_distribution<float> g(0.0f, 1.0f);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                // Illumination: heavy-tailed (1-spp-like), occasionally negative (demodulated
                // colour minus emission can be) and occasionally 0.
                const float scale = u(rng) < 0.05f ? 20.0f : 1.0f;
                for (int c = 0; c < 3; ++c)
                    illum(x, y, c) = scale * heavy(rng) - (u(rng) < 0.05f ? 0.5f : 0.0f);
                // Variance: mostly ~0.1-1, some exactly 0 (then the luminance stop is ~exact).
                variance(x, y, 0) = u(rng) < 0.1f ? 0.0f : 0.05f + heavy(rng);
                // History length: ~10% empty pixels.
                length(x, y, 0) = u(rng) < 0.1f ? 0.0f : float(1 + int(u(rng) * 31.0f));
                // Depth: two planes split by a diagonal edge, a background region, and a few
                // isolated background pixels.
                const bool bg = (y < h / 5 && x > w / 2) || u(rng) < 0.03f;
                const bool near = x + y < (w + h) / 2;
                depth(x, y, 0) = bg ? svgf::kBackgroundDepthValue
                                    : (near ? 2.0f + 0.01f * float(x) : 6.0f + 0.05f * float(y)) +
                                          0.002f * g(rng);
                // Normals: unit, jittered around two directions; background ones zero; a few
                // missing (zero) on surfaces and a few pointing away (n_p·n_q <= 0).
                float n[3] = {0.0f, 0.0f, 0.0f};
                if (!bg && u(rng) > 0.03f) {
                    const float flip = u(rng) < 0.03f ? -1.0f : 1.0f;
                    n[0] = (near ? 0.1f : 0.6f) + 0.05f * g(rng);
                    n[1] = 0.3f + 0.05f * g(rng);
                    n[2] = flip * (near ? 0.9f : 0.7f);
                    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                    for (float& v : n) v /= len;
                }
                for (int c = 0; c < 3; ++c) normal(x, y, c) = n[c];
            }
        // The pipeline's own depth gradient (0 on background, the smaller one-sided difference).
        svgf::DepthGradient dg{depth.view(), depthGrad.view()};
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) dg(x, y);
    }

    svgf::Atrous functor(int step, float sigmaL, float sigmaN, float sigmaZ, Image& outIllum,
                         Image& outVar) const {
        svgf::Atrous a;
        a.sigmaL = sigmaL, a.sigmaN = sigmaN, a.sigmaZ = sigmaZ;
        a.step = step;
        a.illum = illum.view(), a.variance = variance.view(), a.length = length.view();
        a.depth = depth.view(), a.normal = normal.view(), a.depthGrad = depthGrad.view();
        a.outIllum = outIllum.view(), a.outVariance = outVar.view();
        return a;
    }
};

struct Diff {
    float maxRel = 0.0f;  // max |a - b| / (|b| + 1e-3 · scale)
    bool finite = true;
};

// Relative to the value, with a floor of 1e-3 of the image's typical magnitude: a tiny output
// next to large ones may come from cancelling (negative and positive) illumination.
Diff compare(const Image& got, const Image& ref) {
    double scale = 0.0;
    for (size_t i = 0; i < ref.size(); ++i) scale += std::fabs(ref.data()[i]);
    scale = ref.size() ? scale / double(ref.size()) : 1.0;
    Diff d;
    for (size_t i = 0; i < ref.size(); ++i) {
        const float a = got.data()[i], b = ref.data()[i];
        if (!std::isfinite(a) || !std::isfinite(b)) d.finite = false;
        d.maxRel = std::fmax(d.maxRel, std::fabs(a - b) / (std::fabs(b) + 1e-3f * float(scale)));
    }
    return d;
}

std::vector<bool> isas() {
    std::vector<bool> v = {false};
    if (svgf::svgfCpuAvx512()) v.push_back(true);
    return v;
}

}  // namespace

TEST(SvgfFastMath, FastLogIsAccurateOnTheUnitInterval) {
    // Bound 3e-7 relative: the series' truncation is 2e-9; the rest is float rounding of
    // s = (m - 1)/(m + 1) (two roundings, ~1.2e-7) and of the final sum, and in the binades below
    // √½ the rounding of e·ln2 (6e-8). Absolute 1e-12 only matters at d -> 1, where ln d -> 0 and
    // d - 1 itself is exact.
    double worst = 0.0;
    for (double ld = -87.0; ld <= 0.0; ld += 0.0037) {
        const float d = float(std::exp(ld));
        const double ref = std::log(double(d));
        const double err = std::fabs(double(svgf::fastLog(d)) - ref) / (std::fabs(ref) + 1e-12);
        worst = std::fmax(worst, err);
        ASSERT_LT(err, 3e-7) << "d = " << d;
    }
    for (int k = 1; k < 4000; ++k) {  // the last 4000 floats below 1
        const float d = 1.0f - float(k) * 5.9604645e-8f;
        const double ref = std::log(double(d));
        ASSERT_LT(std::fabs(double(svgf::fastLog(d)) - ref) / std::fabs(ref), 3e-7) << "d = " << d;
    }
    EXPECT_EQ(svgf::fastLog(1.0f), 0.0f);
    EXPECT_GT(worst, 1e-8);  // the measurement ran (a wrong loop would report 0)
    EXPECT_NEAR(svgf::fastLog(svgf::kMinNormalFloat), std::log(double(svgf::kMinNormalFloat)),
                1e-4);
}

// fastExp, shared with EAW and SURE (filters/atrous_math.h), is tested in eaw_test.cpp.

TEST(SvgfFastMath, NormalStopMatchesThePowerItStandsFor) {
    // σ_n log max(0, n_p·n_q) with the special cases of the functor.
    const Vec3 a(0.0f, 0.0f, 1.0f), zero(0.0f);
    for (float angle : {0.01f, 0.1f, 0.5f, 1.2f}) {
        const Vec3 b(std::sin(angle), 0.0f, std::cos(angle));
        const double ref = 128.0 * std::log(double(dot(a, b)));
        EXPECT_NEAR(svgf::normalLogWeight(a, b, 128.0f), ref, 3e-7 * std::fabs(ref) + 1e-6)
            << angle;
    }
    EXPECT_EQ(svgf::normalLogWeight(a, a, 128.0f), 0.0f);
    EXPECT_EQ(svgf::normalLogWeight(a, Vec3(0.0f, 1.0f, 0.0f), 128.0f), -1e30f);  // perpendicular
    EXPECT_EQ(svgf::normalLogWeight(a, Vec3(0.0f, 0.0f, -1.0f), 0.0f),
              -1e30f);                                           // opposite, even σ_n = 0
    EXPECT_EQ(svgf::normalLogWeight(zero, zero, 128.0f), 0.0f);  // background pair
    EXPECT_EQ(svgf::normalLogWeight(zero, a, 128.0f), -1e30f);
    EXPECT_EQ(svgf::normalLogWeight(a, zero, 128.0f), -1e30f);
}

// The scalar stops (with early returns, used by the variance functor) and their branch-free twins
// (used by the à-trous) must give the same value, bit for bit, in every case.
TEST(SvgfFastMath, ScalarAndSelectStopsAreEqual) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    auto randomNormal = [&](int kind) {
        if (kind == 0) return Vec3(0.0f);                       // missing / background
        if (kind == 1) return Vec3(0.0f, 0.0f, 1.0f);           // exactly equal pairs
        return normalize(Vec3(u(rng), u(rng), u(rng) + 2.0f));  // near +z, some pairs at d >= 1
    };
    int cases[4] = {0, 0, 0, 0};  // background pair, mismatch, d >= 1 or d <= 0, 0 < d < 1
    for (int i = 0; i < 20000; ++i) {
        const Vec3 a = randomNormal(i % 5 == 0 ? 0 : (i % 7 == 0 ? 1 : 2));
        const Vec3 b = randomNormal(i % 11 == 0 ? 0 : (i % 3 == 0 ? 1 : 2));
        const Vec3 bb = i % 13 == 0 ? -1.0f * b : b;  // some opposite pairs
        for (float sigmaN : {0.0f, 1.0f, 128.0f}) {
            const float s1 = svgf::normalLogWeight(a, bb, sigmaN),
                        s2 = svgf::normalLogWeightSel(a, bb, sigmaN);
            ASSERT_EQ(s1, s2) << i;
        }
        const bool ha = svgf::hasNormal(a), hb = svgf::hasNormal(bb);
        const float d = svgf::dotFma(a, bb);
        ++cases[!ha && !hb ? 0 : (ha != hb ? 1 : ((d >= 1.0f || d <= 0.0f) ? 2 : 3))];
    }
    for (int c = 0; c < 4; ++c) EXPECT_GT(cases[c], 100) << "case " << c << " not exercised";
    for (int i = 0; i < 2000; ++i) {
        const float zp = i % 9 == 0 ? 1e30f : 1.0f + 3.0f * (u(rng) + 1.0f);
        const float zq = i % 4 == 0 ? 1e30f : 1.0f + 3.0f * (u(rng) + 1.0f);
        const float gx = u(rng), gy = u(rng), dx = float(i % 5 - 2), dy = float(i % 7 - 3);
        ASSERT_EQ(svgf::depthLogWeight(zp, zq, gx, gy, dx, dy, 0.7f),
                  svgf::depthLogWeightSel(zp, zq, gx, gy, dx, dy, 0.7f))
            << i;
    }
}

// The core check: fast path == functor through plain loops, for every step, odd sizes, images
// smaller than the kernel's reach (4·step), and parameter sets that exercise each stop.
//
// Tolerance 1e-6 relative (see compare() for the floor). Both sides evaluate the same shared
// functions with every multiply-add spelled out as fmaf (nothing left for the compiler to
// contract differently), IEEE division and sqrt, and every pixel sums its taps in the same order:
// with GCC 12 the results are bit-equal (the test prints the measured maximum, 0). The bound only
// leaves room for a compiler that rounds some remaining product differently; it is not loose:
// without the explicit FMAs the two sides differed by up to 8.5e-4 here, because σ_n = 128
// multiplies the rounding of n_p·n_q and exp the rounding of its argument. A real difference in
// the math (a dropped or extra tap, a wrong border range, a wrong weight) is far larger.
TEST(SvgfAtrousCpu, FastPathEqualsTheGenericFunctor) {
    struct Size {
        int w, h;
    };
    const Size sizes[] = {{67, 45}, {33, 17}, {17, 70}, {9, 7},  {3, 2},
                          {1, 1},   {1, 9},   {11, 1},  {40, 40}};
    struct Sigmas {
        float l, n, z;
    };
    const Sigmas sigmas[] = {
        {4.0f, 128.0f, 1.0f}, {0.5f, 1.0f, 0.2f}, {40.0f, 0.0f, 5.0f}, {4.0f, 7.3f, 1.0f}};
    const bool hasAvx512 = svgf::svgfCpuAvx512();
    float worst = 0.0f;
    int cases = 0;
    for (bool avx512 : isas()) {
        for (const Size& sz : sizes) {
            LevelInputs in(sz.w, sz.h, unsigned(sz.w * 131 + sz.h));
            for (int step : {1, 2, 4, 8, 16}) {
                for (const Sigmas& sg : sigmas) {
                    Image refI(sz.w, sz.h, 3), refV(sz.w, sz.h, 1), gotI(sz.w, sz.h, 3),
                        gotV(sz.w, sz.h, 1);
                    // The reference: the luminance stop plane and the shared à-trous functor
                    // with the SVGF policy, through plain per-pixel loops.
                    Image lumStop(sz.w, sz.h, 1);
                    svgf::Atrous refLevel = in.functor(step, sg.l, sg.n, sg.z, refI, refV);
                    refLevel.lumStop = lumStop.view();
                    const svgf::AtrousLumStop ls{sg.l, in.variance.view(), lumStop.view()};
                    const filters::AtrousLevel<svgf::SvgfStop> ref{svgf::SvgfStop{refLevel}};
                    for (int y = 0; y < sz.h; ++y)
                        for (int x = 0; x < sz.w; ++x) ls(x, y);
                    for (int y = 0; y < sz.h; ++y)
                        for (int x = 0; x < sz.w; ++x) ref(x, y);
                    svgf::svgfCpuFastPath() = true;
                    svgf::svgfCpuAvx512() = avx512;
                    svgf::runSvgfAtrous(CpuExec{}, in.functor(step, sg.l, sg.n, sg.z, gotI, gotV));
                    svgf::svgfCpuAvx512() = hasAvx512;
                    const std::string what =
                        std::to_string(sz.w) + "x" + std::to_string(sz.h) + " step " +
                        std::to_string(step) + " sigmaL " + std::to_string(sg.l) + " sigmaN " +
                        std::to_string(sg.n) + " avx512 " + std::to_string(avx512);
                    const Diff di = compare(gotI, refI), dv = compare(gotV, refV);
                    EXPECT_TRUE(di.finite && dv.finite) << what;
                    EXPECT_LT(di.maxRel, 1e-6f) << "illumination, " << what;
                    EXPECT_LT(dv.maxRel, 1e-6f) << "variance, " << what;
                    worst = std::fmax(worst, std::fmax(di.maxRel, dv.maxRel));
                    ++cases;
                }
            }
        }
    }
    std::printf("fast path vs functor: %d cases, max relative difference %.3g\n", cases,
                double(worst));
}

// The inputs must exercise what they claim to: the filter changes the image, and the special
// pixels behave as the functor says (an empty pixel next to others takes their mean; with every
// pixel empty the input comes back unchanged).
TEST(SvgfAtrousCpu, SpecialPixelsBehaveAsTheFunctorSays) {
    LevelInputs in(37, 23, 5);
    Image outI(37, 23, 3), outV(37, 23, 1);
    svgf::runSvgfAtrous(CpuExec{}, in.functor(1, 4.0f, 128.0f, 1.0f, outI, outV));
    int changed = 0;
    for (size_t i = 0; i < outI.size(); ++i) changed += outI.data()[i] != in.illum.data()[i];
    EXPECT_GT(changed, int(outI.size()) / 2);

    in.length.fill(0.0f);
    svgf::runSvgfAtrous(CpuExec{}, in.functor(2, 4.0f, 128.0f, 1.0f, outI, outV));
    for (size_t i = 0; i < outI.size(); ++i) ASSERT_EQ(outI.data()[i], in.illum.data()[i]);
    for (size_t i = 0; i < outV.size(); ++i) ASSERT_EQ(outV.data()[i], in.variance.data()[i]);
}

// End to end: the pipeline with the fast path on and off gives the same frames (the fast path is
// the only difference; a few frames so the histories, variance and feedback tap take part).
TEST(SvgfAtrousCpu, PipelineWithAndWithoutTheFastPathAgree) {
    const int w = 45, h = 31;
    LevelInputs scene(w, h, 77);
    SvgfParams p;
    Image outs[2];
    for (int fast = 0; fast < 2; ++fast) {
        svgf::svgfCpuFastPath() = fast == 1;
        SvgfDenoiser d(p, Device::Cpu);
        std::mt19937 rng(3);
        std::exponential_distribution<float> noise(1.0f);
        for (int t = 0; t < 4; ++t) {
            Image color(w, h, 3), motion(w, h, 2);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    for (int c = 0; c < 3; ++c)
                        color(x, y, c) = (0.5f + 0.1f * float(c)) * noise(rng);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) motion(x, y, 0) = 1.0f;
            Frame f;
            f.color = &color, f.normal = &scene.normal, f.depth = &scene.depth, f.motion = &motion;
            outs[fast] = d.denoiseFrame(f);
        }
    }
    svgf::svgfCpuFastPath() = true;
    // Five levels of the 1e-6 above, each feeding the next and the next frame: 1e-5 (measured: 0).
    const Diff d = compare(outs[1], outs[0]);
    EXPECT_TRUE(d.finite);
    EXPECT_LT(d.maxRel, 1e-5f);
}

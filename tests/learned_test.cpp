// The learned filter v3 (docs/learned.md): the C++ inference equals the JAX forward pass
// (python/atrous/learn/model.py, features.py) on tests/learned_fixture.bin (written by
// scripts/train/make_fixture.py: prepared planes with an edge, a black-albedo patch, sky depth 1e30,
// a firefly-ish pixel, a black pixel, random non-trivial weights), through the functors and through
// the CPU row engine (AVX-512 and AVX2 loops); the math helpers against libm; bad weight files and
// bad planes are clear errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <vector>

#include "atrous/error.h"
#include "atrous/learned.h"
#include "core/parallel.h"
#include "core/cpu_isa.h"
#include "filters/learned.h"
#include "learned_fixture.h"

using namespace atrous;
using namespace atrous::filters;
using atrous::test::Fixture;
using atrous::test::fixture;

namespace {

LearnedWeights fixtureWeights() {
    const Fixture& fx = fixture();
    return LearnedWeights::parse(fx.weights.data(), fx.weights.size(), "fixture weights");
}

// The cascade on the CPU: the row engine (fast) or the functors, AVX-512 loops or not.
Image run(const PreparedView& p, const LearnedWeights& w, bool fast, bool avx512 = filters::atrousCpuAvx512()) {
    Image out(p.color.width, p.color.height, 3);
    const bool savedFast = atrousCpuFastPath(), savedAvx = atrousCpuAvx512();
    atrousCpuFastPath() = fast, atrousCpuAvx512() = avx512;
    runLearned(CpuExec{}, w, p, out.view());
    atrousCpuFastPath() = savedFast, atrousCpuAvx512() = savedAvx;
    return out;
}

double worstRel(const Image& a, const Image& b) {
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i)
        worst = std::max(worst, double(std::fabs(a.data()[i] - b.data()[i])) / std::max(1.0f, std::fabs(b.data()[i])));
    return worst;
}

// Tolerance against JAX: both float32; the orders of the dot products and tap sums differ, the C++
// uses fastExp for the taps and softmax and its own log (each <= 3e-7 relative here) where XLA uses
// its own approximations, and 5 levels compound them through exponents a|Δf|^2 + (b kappa + c nu)
// |Δd|^2 of O(10). Measured 4.9e-7 of max(1, |expected|) on the v3 fixture (d_out up to ~60 here);
// the bound 2e-5 leaves 40x for another XLA build, and a real mismatch (a wrong term, tap, level or
// input) is > 1e-2 (scripts/train/make_fixture.py prints what dropping the relative colour term,
// the noise-relative one, the blend or the box inputs, or reading 4 v, changes: 1.3%, 5.9%, 2.5%,
// 1.5%, 1.2% of max |d_out|; dropping the c nu term in C++ measured 0.32 here).
constexpr double kJaxTol = 2e-5;

void expectJax(const Image& out, const char* what) {
    const Fixture& fx = fixture();
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < fx.h; ++y)
            for (int x = 0; x < fx.w; ++x) {
                const float e = fx.expect(x, y, c), g = out(x, y, c);
                ASSERT_TRUE(std::isfinite(g)) << what << " " << x << "," << y;
                EXPECT_LE(std::fabs(g - e) / std::max(1.0f, std::fabs(e)), kJaxTol)
                    << what << ": pixel " << x << "," << y << " channel " << c << ": " << g << " vs " << e;
            }
    std::printf("%s: worst relative difference vs JAX %.3g\n", what, worstRel(out, fx.expect));
}

}  // namespace

TEST(Learned, FunctorsEqualJax) { expectJax(run(fixture().planes(), fixtureWeights(), false), "functors"); }

TEST(Learned, RowEngineEqualsJax) {
    expectJax(run(fixture().planes(), fixtureWeights(), true), "row engine");
    if (cpu::activeIsa() == cpu::Isa::Avx512)
        expectJax(run(fixture().planes(), fixtureWeights(), true, false), "row engine, AVX2 loops");
}

// The row engine and the functors compute the same terms in the same order; only the compiler's
// multiply-add contraction may differ between the vector and the scalar loops: 2e-6 relative
// (measured: bit-identical), 10x below the JAX tolerance.
TEST(Learned, RowEngineEqualsFunctors) {
    const LearnedWeights w = fixtureWeights();
    const Image fast = run(fixture().planes(), w, true), ref = run(fixture().planes(), w, false);
    const double worst = worstRel(fast, ref);
    std::printf("row engine vs functors: %.3g\n", worst);
    EXPECT_LE(worst, 2e-6);
}

// Absent albedo, normal and depth (their inputs read 1, 0, log 1): finite, both paths agree, and
// the output differs from the full one (the inputs are used).
TEST(Learned, AbsentFeaturePlanes) {
    const LearnedWeights w = fixtureWeights();
    PreparedView p = fixture().planes();
    p.albedo = p.normal = p.depth = ImageView{};
    const Image fast = run(p, w, true), ref = run(p, w, false);
    for (size_t i = 0; i < fast.size(); ++i) ASSERT_TRUE(std::isfinite(fast.data()[i]));
    EXPECT_LE(worstRel(fast, ref), 2e-6);
    EXPECT_GT(worstRel(fast, fixture().expect), 1e-2);
}

// The row-wise pass B handles every tail width (16 pixels per MLP call): a 1-pixel-wide, a
// 17-wide and a 3x1 crop equal the functors.
TEST(Learned, OddSizesRowEngineEqualsFunctors) {
    const Fixture& fx = fixture();
    const LearnedWeights w = fixtureWeights();
    for (const auto [cw, ch] : {std::pair{1, 7}, std::pair{17, 5}, std::pair{3, 1}, std::pair{fx.w, 1}}) {
        Image d(cw, ch, 3), var(cw, ch, 3);
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < ch; ++y)
                for (int x = 0; x < cw; ++x) d(x, y, c) = fx.d(x + 3, y + 2, c), var(x, y, c) = fx.var(x + 3, y + 2, c);
        const PreparedView p = preparedView(d.view(), var.view(), {}, {}, {});
        EXPECT_LE(worstRel(run(p, w, true), run(p, w, false)), 2e-6) << cw << "x" << ch;
    }
}

// The math helpers against libm (double): learnedLog and learnedLog1p within 4 float ulps
// (Cephes' polynomial is < 1e-7 relative, plus the roundings of its last steps), softplus within
// 1e-6 (1 + |x| / 8) relative (fastExp: 3e-7, plus the rounding of t = x log2 e, which grows with
// |x|: measured 9.6e-7 unscaled at x = -60, where softplus is e^-60 and irrelevant).
TEST(Learned, MathAgainstLibm) {
    double worstLog = 0, worstLog1p = 0, worstSp = 0;
    for (double v = 1e-3; v < 1e5; v *= 1.0007) {
        const float x = float(v);
        worstLog = std::max(worstLog, std::fabs(learnedLog(x) - std::log(double(x))) /
                                          std::max(std::fabs(std::log(double(x))), 1e-30) * (std::log(double(x)) != 0));
    }
    for (double v = 1e-9; v < 1e6; v *= 1.0007) {
        const float x = float(v);
        const double e = std::log1p(double(x));
        worstLog1p = std::max(worstLog1p, std::fabs(learnedLog1p(x) - e) / e);
    }
    for (double v = -60; v < 60; v += 0.013) {
        const float x = float(v);
        const double e = std::max(double(x), 0.0) + std::log1p(std::exp(-std::fabs(double(x))));
        worstSp = std::max(worstSp, std::fabs(learnedSoftplus(x) - e) / e / (1.0 + std::fabs(double(x)) / 8));
    }
    EXPECT_EQ(learnedLog1p(0.0f), 0.0f);
    std::printf("worst relative: log %.3g, log1p %.3g, softplus %.3g\n", worstLog, worstLog1p, worstSp);
    EXPECT_LE(worstLog, 4 * 6e-8);
    EXPECT_LE(worstLog1p, 4 * 6e-8);
    EXPECT_LE(worstSp, 1e-6);
}

// Absurd weights (huge finite values) overflow the network's outputs: the output stays finite.
TEST(Learned, HugeWeightsGiveFiniteOutput) {
    const Fixture& fx = fixture();
    std::vector<std::uint8_t> b = fx.weights;
    const float big = 3e38f;
    for (size_t o = 36; o + 8 <= b.size(); o += 4 * 7) std::memcpy(&b[o], &big, 4);
    std::uint32_t hsh = 0x811C9DC5u;
    for (size_t i = 0; i + 4 < b.size(); ++i) hsh = (hsh ^ b[i]) * 0x01000193u;
    std::memcpy(&b[b.size() - 4], &hsh, 4);
    const LearnedWeights w = LearnedWeights::parse(b.data(), b.size(), "huge");
    for (bool fast : {true, false}) {
        const Image out = run(fx.planes(), w, fast);
        for (size_t i = 0; i < out.size(); ++i) ASSERT_TRUE(std::isfinite(out.data()[i])) << fast << " " << i;
    }
}

// Non-finite plane values (the driver sanitises them; the filter guards anyway): NaN and Inf in d,
// var, albedo, normal and depth give a finite output on both paths.
TEST(Learned, NonFinitePlanesGiveFiniteOutput) {
    const Fixture& fx = fixture();
    Image d = fx.d.clone(), var = fx.var.clone(), albedo = fx.albedo.clone(), normal = fx.normal.clone(),
          depth = fx.depth.clone();
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    d(5, 5, 0) = nan, d(6, 5, 1) = inf, d(0, 0, 2) = -inf, var(7, 7, 0) = nan, var(8, 7, 2) = inf;
    // Finite variances whose channel sum overflows: the noise plane v reads +inf there (nu = 0).
    var(9, 9, 0) = var(9, 9, 1) = var(9, 9, 2) = 3e38f;
    albedo(3, 9, 1) = nan, normal(10, 10, 0) = inf, depth(11, 3, 0) = nan, depth(12, 3, 0) = inf;
    const PreparedView p = preparedView(d.view(), var.view(), albedo.view(), normal.view(), depth.view());
    for (bool fast : {true, false}) {
        const Image out = run(p, fixtureWeights(), fast);
        for (size_t i = 0; i < out.size(); ++i) ASSERT_TRUE(std::isfinite(out.data()[i])) << fast << " " << i;
    }
}

// The built-in weights (src/filters/learned_weights_default.cpp) parse and give finite output.
TEST(Learned, BuiltinWeightsLoadAndRun) {
    const Image out = run(fixture().planes(), LearnedWeights::builtin(), true);
    for (size_t i = 0; i < out.size(); ++i) ASSERT_TRUE(std::isfinite(out.data()[i]));
}

namespace {

std::string parseError(std::vector<std::uint8_t> b, bool fixChecksum = false) {
    if (fixChecksum && b.size() >= 4) {
        std::uint32_t h = 0x811C9DC5u;
        for (size_t i = 0; i + 4 < b.size(); ++i) h = (h ^ b[i]) * 0x01000193u;
        std::memcpy(&b[b.size() - 4], &h, 4);
    }
    try {
        LearnedWeights::parse(b.data(), b.size(), "w.bin");
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST(Learned, BadWeightsAreClearErrors) {
    const std::vector<std::uint8_t> good = fixture().weights;
    EXPECT_EQ(parseError(good), "no error");
    constexpr size_t kHead = 36, kFloats = 13394;  // a v4 file: the MLP's 1834 floats, the context's 11560
    EXPECT_EQ(good.size(), kHead + 4 * kFloats + 4u);
    auto expectMsg = [](const std::string& msg, const char* want) {
        EXPECT_NE(msg.find(want), std::string::npos) << "got: " << msg << "\nwanted: " << want;
    };
    std::vector<std::uint8_t> b = good;
    b[0] = 'X';
    expectMsg(parseError(b), "w.bin: not an atrous learned-filter weight file (no ATRL header)");
    b = good;
    b[4] = 1;
    expectMsg(parseError(b, true), "w.bin: version 1 (the first network, retired); retrain with make train");
    // Version 2 (15 -> 24 -> 24 -> 29, 1709 floats): refused by its version, with the words
    // python/atrous/learn/weights.py uses, whatever its shape fields say.
    b[4] = 2;
    expectMsg(parseError(b, true),
              "w.bin: version 2 (the network without the noise-relative colour term, retired); "
              "retrain with make train");
    std::vector<std::uint8_t> v2(good.begin(), good.begin() + 28);
    v2[4] = 2;
    const std::uint32_t n2 = 1709;
    std::memcpy(&v2[24], &n2, 4);
    v2.resize(28 + 4 * 1709 + 4, 0);
    expectMsg(parseError(v2, true), "w.bin: version 2 (the network without the noise-relative colour term, retired)");
    b[4] = 5;
    expectMsg(parseError(b, true), "w.bin: weight file version 5, this build reads versions 3 and 4");
    // A version-4 body under a version-3 header: the v3 header's n_floats field is n_ctx_in (13).
    b = good;
    b[4] = 3;
    expectMsg(parseError(b, true), "w.bin: network shape n_in/n_hidden/n_feat/n_levels 15/24/8/5 (13 floats) is not");
    b = good;
    b[8] = 11;  // n_in
    expectMsg(parseError(b, true),
              "w.bin: network shape n_in/n_hidden/n_feat/n_levels/n_ctx_in/n_ctx 11/24/8/5/13/16 (13394 floats) is not");
    b = good;
    b[24] = 12;  // n_ctx_in
    expectMsg(parseError(b, true), "12/16 (13394 floats) is not this build's 15/24/8/5/13/16 (13394 floats)");
    b = good;
    b[32] = 0;  // n_floats
    expectMsg(parseError(b, true), "w.bin: network shape");
    b = good;
    b.resize(b.size() - 8);
    expectMsg(parseError(b), "w.bin: truncated weight file");
    b = good;
    b.resize(12);
    expectMsg(parseError(b), "w.bin: truncated weight file (12 bytes)");
    b = good;
    b.insert(b.end() - 4, {0, 0, 0, 0});
    expectMsg(parseError(b, true), "w.bin: over-long weight file");
    b = good;
    b[40] ^= 1;
    expectMsg(parseError(b), "w.bin: weight file checksum mismatch (corrupt)");
    b = good;
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    std::memcpy(&b[kHead + 4 * 100], &nan, 4);
    expectMsg(parseError(b, true), "w.bin: weight 100 is not finite");
    b = good;
    std::memcpy(&b[kHead + 4 * (kFloats - 1)], &inf, 4);
    expectMsg(parseError(b, true), "w.bin: weight 13393 is not finite");  // the context's last bias
    try {
        LearnedWeights::load("/nonexistent/learned.bin");
        FAIL() << "no error";
    } catch (const InputError& e) {
        expectMsg(e.what(), "/nonexistent/learned.bin: cannot open the learned-filter weight file");
    }
}

namespace {

// The fixture's weight file with its context's last layer (kz, kbz: the last 408 floats) zeroed, and
// the same MLP as a version-3 file (header of 28 bytes, the MLP's 1834 floats).
std::vector<std::uint8_t> withChecksum(std::vector<std::uint8_t> b) {
    std::uint32_t h = 0x811C9DC5u;
    for (size_t i = 0; i + 4 < b.size(); ++i) h = (h ^ b[i]) * 0x01000193u;
    std::memcpy(&b[b.size() - 4], &h, 4);
    return b;
}

}  // namespace

// A version-3 file (no context) is read as version 4 with the context zero: it gives exactly what a
// version-4 file with the same MLP and a zero last context layer gives, and that differs from the
// fixture's (the context is used).
TEST(Learned, Version3FilesReadWithoutContext) {
    const std::vector<std::uint8_t> good = fixture().weights;
    std::vector<std::uint8_t> v4 = good;
    std::fill(v4.end() - 4 - 4 * (16 * 24 + 24), v4.end() - 4, std::uint8_t(0));
    v4 = withChecksum(v4);
    std::vector<std::uint8_t> v3(good.begin(), good.begin() + 28);
    v3[4] = 3;
    const std::uint32_t n = 1834;
    std::memcpy(&v3[24], &n, 4);
    v3.insert(v3.end(), good.begin() + 36, good.begin() + 36 + 4 * 1834);
    v3.resize(v3.size() + 4);
    v3 = withChecksum(v3);
    const LearnedWeights w3 = LearnedWeights::parse(v3.data(), v3.size(), "v3.bin");
    const LearnedWeights w4 = LearnedWeights::parse(v4.data(), v4.size(), "v4.bin");
    for (bool fast : {true, false}) {
        const Image a = run(fixture().planes(), w3, fast), b = run(fixture().planes(), w4, fast);
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0) << "fast " << fast;
        EXPECT_GT(worstRel(a, fixture().expect), 1e-2) << "fast " << fast;
    }
}

TEST(Learned, BadPlanesAreClearErrors) {
    const LearnedWeights w = fixtureWeights();
    const Fixture& fx = fixture();
    Image small(4, 4, 3), out(fx.w, fx.h, 3), one(fx.w, fx.h, 1);
    auto msg = [&](const PreparedView& p, const ImageView& o) {
        try {
            runLearned(CpuExec{}, w, p, o);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    PreparedView p = fx.planes();
    EXPECT_EQ(msg(p, out.view()), "no error");
    p.albedo = small.view();
    EXPECT_NE(msg(p, out.view()).find("learned filter: albedo: size 4x4 differs from the colour's 42x37"), std::string::npos)
        << msg(p, out.view());
    p = fx.planes();
    p.variance = ImageView{};
    EXPECT_NE(msg(p, out.view()).find("learned filter: variance: missing"), std::string::npos);
    p = fx.planes();
    p.normal = one.view();
    EXPECT_NE(msg(p, out.view()).find("learned filter: normal: 1 channels, 3 needed"), std::string::npos);
    EXPECT_NE(msg(fx.planes(), small.view()).find("learned filter: out: size"), std::string::npos);
    EXPECT_NE(msg(fx.planes(), out.view()).find("no error"), std::string::npos);
    EXPECT_THROW(runLearned(CpuExec{}, LearnedWeights{}, fx.planes(), out.view()), InputError);
}

// Bands of rows (the CPU's way at large sizes, learnedCpuBandRows): every band's rows are computed
// from its halo of 63 rows, so the output equals the whole image's bit for bit; bands shorter and
// longer than the halo, and a last band of a few rows.
TEST(Learned, BandsOfRowsEqualTheWholeImage) {
    const int w = 45, h = 301;
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Image d(w, h, 3), var(w, h, 3), albedo(w, h, 3), normal(w, h, 3), depth(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool edge = (x + y / 3) % 17 < 8;
            for (int c = 0; c < 3; ++c) {
                d(x, y, c) = (edge ? 0.8f : 0.2f) + 0.3f * u(rng);
                var(x, y, c) = 0.01f * u(rng);
                albedo(x, y, c) = edge ? 0.7f : 0.3f;
                normal(x, y, c) = c == 2 ? 1.0f : 0.0f;
            }
            depth(x, y, 0) = edge ? 2.0f : 5.0f;
        }
    const PreparedView p = preparedView(d.view(), var.view(), albedo.view(), normal.view(), depth.view());
    const LearnedWeights wts = LearnedWeights::builtin();
    const int saved = learnedCpuBandRows();
    learnedCpuBandRows() = -1;
    const Image whole = run(p, wts, true);
    for (int rows : {5, 40, 64, 120, 200, 296}) {
        learnedCpuBandRows() = rows;
        const Image banded = run(p, wts, true);
        size_t differ = 0;
        for (size_t i = 0; i < whole.size(); ++i) differ += std::memcmp(whole.data() + i, banded.data() + i, 4) != 0;
        EXPECT_EQ(differ, 0u) << "bands of " << rows << " rows";
    }
    learnedCpuBandRows() = saved;
}

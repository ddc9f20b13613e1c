// The learned filter (docs/learned.md): the C++ inference equals the JAX forward pass
// (python/atrous/learn/model.py) on tests/learned_fixture.bin (written by
// scripts/train/make_fixture.py: inputs with a black-albedo patch, sky depth, a NaN, a firefly and
// emission, random weights); the row engine equals the functor; bad weight files are clear errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "atrous/error.h"
#include "atrous/learned.h"
#include "filters/atrous_level.h"

using namespace atrous;

namespace {

struct Fixture {
    int w = 0, h = 0;
    std::vector<std::uint8_t> weights;
    Image in[6], expect;
};

std::uint32_t rd32(const std::uint8_t* p) {
    std::uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

Fixture loadFixture() {
    const std::string path = std::string(ATROUS_SOURCE_DIR) + "/tests/learned_fixture.bin";
    std::ifstream f(path, std::ios::binary);
    EXPECT_TRUE(bool(f)) << path;
    const std::vector<std::uint8_t> b((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    Fixture fx;
    EXPECT_GE(b.size(), 16u);
    EXPECT_EQ(std::memcmp(b.data(), "ATRF", 4), 0);
    fx.w = int(rd32(&b[4])), fx.h = int(rd32(&b[8]));
    const size_t nw = rd32(&b[12]);
    fx.weights.assign(b.begin() + 16, b.begin() + 16 + nw);
    size_t o = 16 + nw;
    const size_t plane = size_t(fx.w) * fx.h * 3;
    EXPECT_EQ(b.size(), o + 7 * plane * 4);
    for (int k = 0; k < 7; ++k) {
        Image img(fx.w, fx.h, 3);
        std::memcpy(img.data(), &b[o], plane * 4);
        o += plane * 4;
        if (k < 6) fx.in[k] = std::move(img);
        else fx.expect = std::move(img);
    }
    return fx;
}

LearnedInputs inputsOf(const Fixture& fx) {
    return LearnedInputs{fx.in[0].view(), fx.in[1].view(), fx.in[2].view(),
                         fx.in[3].view(), fx.in[4].view(), fx.in[5].view()};
}

}  // namespace

// Tolerance: both sides are float32, but they sum the network's dot products and the 8-feature
// distances in different orders and the C++ taps use fastExp (< 1.2e-7 relative against exp): a
// relative error ~1e-6 in an exponent a|Δf|² of up to ~50 moves a weight by ~5e-5, so 3e-4 of
// max(1, |expected|) holds with margin (measured: 5.9e-7); a real mismatch (a wrong term, tap or level)
// is > 1e-2.
TEST(Learned, CppEqualsJaxForwardPass) {
    const Fixture fx = loadFixture();
    const LearnedWeights w = LearnedWeights::parse(fx.weights.data(), fx.weights.size(), "fixture weights");
    const Image out = learnedDenoise(inputsOf(fx), w);
    double worst = 0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < fx.h; ++y)
            for (int x = 0; x < fx.w; ++x) {
                const float e = fx.expect(x, y, c), g = out(x, y, c);
                ASSERT_TRUE(std::isfinite(g)) << x << "," << y;
                const double err = std::fabs(g - e) / std::max(1.0f, std::fabs(e));
                worst = std::max(worst, err);
                EXPECT_LE(err, 3e-4) << "pixel " << x << "," << y << " channel " << c << ": " << g << " vs " << e;
            }
    std::printf("worst relative difference C++ vs JAX: %.3g\n", worst);
}

// The row engine and the functor sum the same taps in the same order: equal to 1e-6 relative
// (the compiler may contract a multiply-add differently in the vectorised loop).
TEST(Learned, RowEngineEqualsFunctor) {
    const Fixture fx = loadFixture();
    const LearnedWeights w = LearnedWeights::parse(fx.weights.data(), fx.weights.size(), "fixture weights");
    const Image fast = learnedDenoise(inputsOf(fx), w);
    filters::atrousCpuFastPath() = false;
    const Image ref = learnedDenoise(inputsOf(fx), w);
    filters::atrousCpuFastPath() = true;
    for (size_t i = 0; i < fast.size(); ++i)
        EXPECT_NEAR(fast.data()[i], ref.data()[i], 1e-6f * std::max(1.0f, std::fabs(ref.data()[i]))) << i;
}

// The built-in weights (src/filters/learned_weights_default.cpp) parse, and give finite output on
// the fixture (NaN colour, sky depth, black albedo included).
TEST(Learned, BuiltinWeightsLoadAndRun) {
    const Fixture fx = loadFixture();
    const Image out = learnedDenoise(inputsOf(fx), LearnedWeights::builtin());
    for (size_t i = 0; i < out.size(); ++i) ASSERT_TRUE(std::isfinite(out.data()[i]));
}

TEST(Learned, BadWeightsAreClearErrors) {
    const Fixture fx = loadFixture();
    auto msg = [](const std::vector<std::uint8_t>& b) {
        try {
            LearnedWeights::parse(b.data(), b.size(), "w.bin");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    std::vector<std::uint8_t> b = fx.weights;
    b[40] ^= 1;
    EXPECT_NE(msg(b).find("w.bin: weight file checksum"), std::string::npos) << msg(b);
    b = fx.weights;
    b.resize(b.size() - 8);
    EXPECT_NE(msg(b).find("w.bin: truncated"), std::string::npos) << msg(b);
    b = fx.weights;
    b[0] = 'X';
    EXPECT_NE(msg(b).find("w.bin: not an atrous learned-filter weight file"), std::string::npos) << msg(b);
    b = fx.weights;
    b[8] = 12;  // n_in
    EXPECT_NE(msg(b).find("w.bin: network shape 12/"), std::string::npos) << msg(b);
    try {
        LearnedWeights::load("/nonexistent/learned.bin");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/learned.bin: cannot open"), std::string::npos);
    }
    LearnedInputs in = inputsOf(fx);
    Image small(4, 4, 3);
    in.albedo = small.view();
    EXPECT_THROW(learnedDenoise(in, LearnedWeights::builtin()), InputError);
}

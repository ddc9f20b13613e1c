// The learned method through atrous::denoise (DenoiseMethod::Learned / Auto, the still driver's
// third policy): it adds nothing to runLearned on the prepared planes but the remodulation, it runs
// on a rendered and a synthetic scene with finite output whatever the input, Auto picks by the
// buffers, a bad weight file is an InputError naming it, and the CLI's --method learned|auto and
// --learned-weights behave. The weights are tests/learned_fixture.bin's (random, non-trivial:
// every term of the network matters), written to a file, so these tests do not depend on the
// built-in weights' training; one test checks the built-in weights load and run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/learned.h"
#include "atrous/render.h"
#include "core/parallel.h"
#include "denoise_test_util.h"
#include "filters/denoise_internal.h"
#include "filters/learned.h"
#include "atrous/io/image_io.h"
#include "learned_fixture.h"
#include "render_test_util.h"
#include "test_util.h"

namespace atrous {
namespace {

// The fixture's weight file (tests/learned_fixture.h), written where a path is wanted.
std::string writeFixtureWeights(const test::TempDir& dir) {
    const std::vector<std::uint8_t>& b = test::fixture().weights;
    const std::string path = dir / "fixture.atrl";
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
    return path;
}

struct Synth {
    test::SyntheticScene s = test::makeScene(40, 32, 0.3f, 7);
    Image emission = Image(40, 32, 3);
    Synth() {
        for (int y = 4; y < 9; ++y)
            for (int x = 30; x < 37; ++x)
                for (int c = 0; c < 3; ++c) emission(x, y, c) = 2.0f, s.noisy(x, y, c) += 2.0f;
        // A firefly: a rare huge sample, which raises its pixel's variance too (prepass.h).
        for (int c = 0; c < 3; ++c) s.noisy(12, 20, c) += 40.0f, s.variance(12, 20, c) = 1600.0f;
    }
    Frame inputs(bool variance = true) const {
        Frame in = s.inputs();
        in.emission = &emission;
        if (!variance) in.variance = nullptr;
        return in;
    }
};

// The learned method with a weight file's network ("" = the built-in weights), loaded once.
DenoiseOptions learnedOptions(const std::string& weights) {
    DenoiseOptions o;
    o.method = DenoiseMethod::Learned;
    if (!weights.empty()) o.weights = LearnedWeights::load(weights);
    return o;
}

bool allFinite(const Image& img) {
    for (size_t i = 0; i < img.plane() * size_t(img.channels()); ++i)
        if (!std::isfinite(img.data()[i])) return false;
    return true;
}

// Exact equality (== on floats: -0 equals 0) of two 3-channel images; the first differing index.
long firstDifference(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height()) return 0;
    for (size_t i = 0; i < 3 * a.plane(); ++i)
        if (!(a.data()[i] == b.data()[i])) return long(i);
    return -1;
}

// cornell-point at 8 spp, every buffer the filter reads.
struct Rendered : test::RenderedInputs {
    Rendered() : RenderedInputs("cornell-point", 48, 40, 8, 3) {}
};

double mse(const Image& a, const Image& ref) {
    double s = 0;
    for (size_t i = 0; i < 3 * a.plane(); ++i) s += double(a.data()[i] - ref.data()[i]) * (a.data()[i] - ref.data()[i]);
    return s / double(3 * a.plane());
}

TEST(LearnedMethod, IsRunLearnedOnThePreparedPlanesThenRemodulate) {
    // denoise(Learned) must be runLearned on preparePlanes' planes, then d_out * modulation + emission:
    // the same code on the same floats, so equal bit for bit (no tolerance). Covers a given and an
    // estimated variance, the emission filter and the firefly pass; a driver that passed other
    // planes (a zero plane for an absent albedo or depth, the colour before demodulation) or
    // added a step fails it.
    test::TempDir dir;
    const std::string wpath = writeFixtureWeights(dir);
    const LearnedWeights w = LearnedWeights::load(wpath);
    const Synth sc;
    // Each buffer left out once: an absent albedo or depth read from a zero plane instead of as
    // absent (albedo 1, depth 1) changes the network's inputs, so it fails here.
    struct Case {
        bool variance, albedo, normal, depth;
    };
    for (const Case& k : {Case{true, true, true, true}, Case{false, true, true, true}, Case{true, false, true, true},
                          Case{true, true, false, true}, Case{true, true, true, false}}) {
        Frame in = sc.inputs(k.variance);
        if (!k.albedo) in.albedo = nullptr;
        if (!k.normal) in.normal = nullptr;
        if (!k.depth) in.depth = nullptr;
        const DenoiseOptions o = learnedOptions(wpath);
        const Image out = denoise(in, o);
        PreparedPlanes p = preparePlanes(in, o);
        ASSERT_EQ(p.albedo.empty(), !k.albedo);
        ASSERT_EQ(p.normal.empty(), !k.normal);
        ASSERT_EQ(p.depth.empty(), !k.depth);
        const PreparedView P = p.view();
        Image dOut(40, 32, 3);
        filters::runLearned(CpuExec{}, w, P, dOut.view());
        Image expect(40, 32, 3);
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 40; ++x)
                for (int c = 0; c < 3; ++c) expect(x, y, c) = dOut(x, y, c) * p.modulation(x, y, c) + p.emission(x, y, c);
        const std::string what = std::string("variance ") + char('0' + k.variance) + " albedo " + char('0' + k.albedo) +
                                 " normal " + char('0' + k.normal) + " depth " + char('0' + k.depth);
        EXPECT_EQ(firstDifference(out, expect), -1) << what;
        // And it filtered: not the input.
        EXPECT_GT(firstDifference(out, sc.s.noisy), -1) << what;
    }
}

// The fixture's weights in a file, the synthetic scene and a report to fill.
class LearnedSynth : public ::testing::Test {
protected:
    test::TempDir dir;
    const std::string wpath = writeFixtureWeights(dir);
    Synth sc;
    DenoiseReport rep;
};

TEST_F(LearnedSynth, IgnoresLevelsAndTheEawParametersButNotTheSafetyNet) {
    DenoiseOptions o = learnedOptions(wpath);
    const Image base = test::denoiseReporting(sc.inputs(), o, rep);
    std::vector<std::string> names;
    for (const StageTime& t : rep.stages) names.push_back(t.name);
    EXPECT_EQ(names, (std::vector<std::string>{"sanitize", "fireflies", "demodulate", "learned", "remodulate"}));
    EXPECT_EQ(rep.methodUsed, DenoiseMethod::Learned);
    DenoiseOptions other = learnedOptions(wpath);
    other.eaw.levels = 2, other.eaw.sigmaNormal = 0.1f, other.sure.windowRadius = 1;
    EXPECT_EQ(firstDifference(denoise(sc.inputs(), other), base), -1);
    // The parameters that do apply change the output: the firefly pass, the albedo rule, the
    // safety net.
    DenoiseOptions noFirefly = learnedOptions(wpath);
    noFirefly.firefly.enabled = false;
    EXPECT_GT(firstDifference(denoise(sc.inputs(), noFirefly), base), -1);
    DenoiseOptions noDemod = learnedOptions(wpath);
    noDemod.demodulate = false;
    EXPECT_GT(firstDifference(denoise(sc.inputs(), noDemod), base), -1);
    // The safety net on the rendered scene (on the synthetic one it gives nothing back).
    const Rendered r;
    DenoiseOptions safety = learnedOptions(wpath);
    safety.safety.enabled = true;
    EXPECT_GT(firstDifference(test::denoiseReporting(r.inputs(), safety, rep), denoise(r.inputs(), learnedOptions(wpath))), -1);
    EXPECT_EQ(rep.stages[rep.stages.size() - 2].name, "safety net");
}

TEST(LearnedMethod, RunsOnARenderedSceneWithinTheRangeOfItsPlanes) {
    // Whatever the weights (the fixture's are random), every level is a normalised average with
    // positive weights and the blend a convex combination, so d_out = (out - e) / mod stays within
    // [min d, max d] of each channel. Tolerance 1e-5 of the range: the back-computation's rounding
    // (a few ulp of out). A missing or doubled remodulation leaves the range (albedos < 0.73).
    test::TempDir dir;
    const std::string wpath = writeFixtureWeights(dir);
    const Rendered r;
    const DenoiseOptions o = learnedOptions(wpath);
    const Image out = denoise(r.inputs(), o);
    ASSERT_TRUE(allFinite(out));
    const PreparedPlanes p = preparePlanes(r.inputs(), o);
    for (int c = 0; c < 3; ++c) {
        float lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < p.color.plane(); ++i) lo = std::fmin(lo, p.color.view().channel(c)[i]), hi = std::fmax(hi, p.color.view().channel(c)[i]);
        const float tol = 1e-5f * (hi - lo);
        for (size_t i = 0; i < p.color.plane(); ++i) {
            const float d = (out.data()[c * out.plane() + i] - p.emission.view().channel(c)[i]) / p.modulation.view().channel(c)[i];
            ASSERT_GE(d, lo - tol) << c << " " << i;
            ASSERT_LE(d, hi + tol) << c << " " << i;
        }
    }
}

TEST_F(LearnedSynth, OutputIsFiniteWithNanAndInfInEveryBuffer) {
    sc.s.noisy(3, 3, 0) = NAN, sc.s.noisy(5, 9, 1) = INFINITY, sc.s.noisy(20, 20, 2) = -INFINITY;
    sc.s.albedo(7, 7, 0) = NAN, sc.s.normal(8, 8, 1) = INFINITY, sc.s.depth(9, 9, 0) = NAN;
    sc.s.depth(10, 10, 0) = 1e30f, sc.emission(11, 11, 0) = INFINITY, sc.s.variance(12, 12, 0) = NAN;
    for (bool variance : {true, false}) {
        const Image out = denoise(sc.inputs(variance), learnedOptions(wpath));
        EXPECT_TRUE(allFinite(out)) << variance;
    }
}

TEST_F(LearnedSynth, AutoPicksBlendWithAlbedoAndNormalElseSure) {
    DenoiseOptions autoO = learnedOptions(wpath);
    autoO.method = DenoiseMethod::Auto;
    DenoiseOptions sure;
    sure.method = DenoiseMethod::Sure;
    DenoiseOptions blend = learnedOptions(wpath);
    blend.method = DenoiseMethod::Blend;
    struct Case {
        bool albedo, normal;
        DenoiseMethod expect;
    };
    for (const Case& c : {Case{true, true, DenoiseMethod::Blend}, Case{true, false, DenoiseMethod::Sure},
                          Case{false, true, DenoiseMethod::Sure}, Case{false, false, DenoiseMethod::Sure}}) {
        Frame in = sc.inputs();
        if (!c.albedo) in.albedo = nullptr;
        if (!c.normal) in.normal = nullptr;
        const Image got = test::denoiseReporting(in, autoO, rep);
        EXPECT_EQ(rep.methodUsed, c.expect) << c.albedo << c.normal;
        EXPECT_EQ(resolveDenoiseMethod(DenoiseMethod::Auto, in), c.expect);
        const Image want = denoise(in, c.expect == DenoiseMethod::Blend ? blend : sure);
        EXPECT_EQ(firstDifference(got, want), -1) << c.albedo << c.normal;
    }
    EXPECT_EQ(resolveDenoiseMethod(DenoiseMethod::Eaw, sc.inputs()), DenoiseMethod::Eaw);
    EXPECT_EQ(parseDenoiseMethod("learned"), DenoiseMethod::Learned);
    EXPECT_EQ(parseDenoiseMethod("auto"), DenoiseMethod::Auto);
    EXPECT_EQ(parseDenoiseMethod("blend"), DenoiseMethod::Blend);
    EXPECT_STREQ(denoiseMethodName(DenoiseMethod::Learned), "learned");
    EXPECT_STREQ(denoiseMethodName(DenoiseMethod::Auto), "auto");
    EXPECT_STREQ(denoiseMethodName(DenoiseMethod::Blend), "blend");
    EXPECT_EQ(DenoiseOptions{}.method, DenoiseMethod::Auto);  // the default
}

// The one list of still methods (denoiseMethods()): names unique and round-tripping, the weighted
// ones those that run the learned cascade, and the CLI's --help and unknown-method message built
// from it (so a new row reaches them without another edit).
TEST(LearnedMethod, TheMethodListIsWhatTheCliAndTheParserRead) {
    std::vector<std::string> names;
    for (const DenoiseMethodInfo& m : denoiseMethods()) {
        EXPECT_EQ(parseDenoiseMethod(m.name), m.method) << m.name;
        EXPECT_STREQ(denoiseMethodName(m.method), m.name);
        EXPECT_EQ(findDenoiseMethod(m.name), &m);
        const bool network = m.method == DenoiseMethod::Learned || m.method == DenoiseMethod::Blend || m.method == DenoiseMethod::Auto;
        EXPECT_EQ(readsWeights(m), network) << m.name;
        EXPECT_EQ(std::count(names.begin(), names.end(), m.name), 0) << m.name;
        names.push_back(m.name);
    }
    EXPECT_EQ(findDenoiseMethod("svgf"), nullptr);  // temporal: not a still method
    const test::CliResult help = test::runCli("denoise --help");
    const test::CliResult bad = test::runCli("denoise --in nowhere --out x.exr --method nope");
    EXPECT_EQ(bad.exitCode, 2) << bad.output;
    for (const std::string& n : names) {
        EXPECT_NE(help.output.find(n + ": "), std::string::npos) << n;
        EXPECT_NE(bad.output.find(n), std::string::npos) << n;
    }
}

// Blend = (learned + SURE) / 2 from one preparation: the mean of the two methods' own outputs up to
// float rounding (the mean is taken before remodulation, c·a' + e, instead of after: a relative
// 1e-5 bounds the difference of those two orders of operations on these values, which are
// O(1)). Checked with and without a variance and an emission, and with demodulation off.
TEST(LearnedMethod, BlendIsTheMeanOfLearnedAndSure) {
    test::TempDir dir;
    const std::string wpath = writeFixtureWeights(dir);
    const Synth sc;
    for (int k = 0; k < 3; ++k) {
        Frame in = sc.inputs(k != 1);
        DenoiseOptions l = learnedOptions(wpath), su = learnedOptions(wpath), b = learnedOptions(wpath);
        su.method = DenoiseMethod::Sure;
        b.method = DenoiseMethod::Blend;
        if (k == 2) l.demodulate = su.demodulate = b.demodulate = false, in.emission = nullptr;
        DenoiseReport rep;
        const Image L = denoise(in, l), S = denoise(in, su), B = test::denoiseReporting(in, b, rep);
        EXPECT_EQ(rep.methodUsed, DenoiseMethod::Blend);
        double worst = 0, moved = 0;
        for (size_t i = 0; i < B.size(); ++i) {
            const double mean = 0.5 * (double(L.data()[i]) + double(S.data()[i]));
            worst = std::max(worst, std::fabs(double(B.data()[i]) - mean) / (1.0 + std::fabs(mean)));
            moved = std::max(moved, std::fabs(double(L.data()[i]) - double(S.data()[i])));
        }
        EXPECT_LT(worst, 1e-5) << k;
        EXPECT_GT(moved, 1e-3) << k << ": the two methods must differ for the test to mean anything";
        bool learnedStage = false, blendStage = false;
        for (const StageTime& st : rep.stages) learnedStage |= st.name == "learned", blendStage |= st.name == "blend";
        EXPECT_TRUE(learnedStage && blendStage) << k;
    }
}

using test::inputErrorOf;

// A bad weight file is an InputError naming it, from the loader (the filter never reads files).
TEST(LearnedMethod, ABadWeightFileIsAnInputErrorNamingIt) {
    test::TempDir dir;
    const std::string missing = dir / "no_such.atrl";
    const std::string junk = dir / "junk.atrl";
    std::ofstream(junk) << "not a weight file";
    for (const std::string& path : {missing, junk}) {
        try {
            LearnedWeights::load(path);
            ADD_FAILURE() << path << " loaded";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        }
    }
}

TEST(LearnedMethod, BuiltInWeightsBeatTheNoisyInput) {
    // The default (empty path) is the built-in weights (trained, docs/learned.md): on cornell-point
    // at 8 spp against 256 spp they must at least cut the MSE by 1.25x (EAW: 1.6x, SURE 1.9x at
    // this size, 2026-12-02).
    const Rendered r;
    const Image ref = render(Scene::builtin("cornell-point"), test::smallRender(48, 40, 256, 9)).color;
    const Image out = denoise(r.inputs(), learnedOptions(""));
    ASSERT_TRUE(allFinite(out));
    EXPECT_LT(1.25 * mse(out, ref), mse(r.b.color, ref)) << mse(out, ref) << " vs " << mse(r.b.color, ref);
}

TEST(LearnedMethodCli, MethodsWeightsAndExitCodes) {
    test::TempDir dir;
    const std::string wpath = writeFixtureWeights(dir);
    const Scene scene = Scene::builtin("cornell");
    const RenderBuffers b = render(scene, test::smallRender(32, 24, 4, 3));
    const std::string in = dir / "r";
    std::filesystem::create_directories(in);
    atrous::writeImage(in + "/color.exr", b.color);
    atrous::writeImage(in + "/albedo.exr", b.albedo);
    atrous::writeImage(in + "/normal.exr", b.normal);
    const std::string out = dir / "o.exr";
    test::CliResult r = test::runCli("denoise --in " + in + " --out " + out + " --method learned --learned-weights " + wpath);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("method learned on cpu"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("learned "), std::string::npos) << r.output;  // the stage
    r = test::runCli("denoise --in " + in + " --out " + out + " --method auto --learned-weights " + wpath);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("method auto -> blend"), std::string::npos) << r.output;
    // No --method: auto, and the line says what it ran.
    r = test::runCli("denoise --in " + in + " --out " + out + " --learned-weights " + wpath);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("method auto -> blend (albedo and normal given)"), std::string::npos) << r.output;
    std::filesystem::remove(in + "/normal.exr");
    r = test::runCli("denoise --in " + in + " --out " + out + " --method auto");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("method auto -> sure"), std::string::npos) << r.output;
    std::filesystem::remove(out);
    // A missing or corrupt weight file: exit 2, one line naming the file, nothing written.
    // Missing, not a weight file, and a retired version-2 file (tests/learned_fixture.h).
    const std::vector<std::string> bads = test::badWeightFiles(dir.path().string());
    const std::string v2 = bads[2];
    for (const std::string& bad : bads) {
        r = test::runCli("denoise --in " + in + " --out " + out + " --method learned --learned-weights " + bad);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(bad), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("--learned-weights"), std::string::npos) << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
        EXPECT_FALSE(std::filesystem::exists(out));
    }
    r = test::runCli("denoise --in " + in + " --out " + out + " --method learned --learned-weights " + v2);
    EXPECT_NE(r.output.find("version 2 (the network without the noise-relative colour term, retired); retrain with "
                            "make train"),
              std::string::npos)
        << r.output;
    r = test::runCli("denoise --in " + in + " --out " + out + " --method learnt");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    // --levels is noted as ignored by learned; --learned-weights as ignored by eaw.
    r = test::runCli("denoise --in " + in + " --out " + out + " --method learned --levels 3 --learned-weights " + wpath);
    EXPECT_NE(r.output.find("ignored with --method learned: --levels"), std::string::npos) << r.output;
    r = test::runCli("denoise --in " + in + " --out " + out + " --method eaw --learned-weights " + wpath);
    EXPECT_NE(r.output.find("ignored with --method eaw: --learned-weights"), std::string::npos) << r.output;
}

TEST(LearnedMethodCli, SequenceDenoisesEveryFrameAndChecksTheWeightsFirst) {
    test::TempDir dir;
    const std::string wpath = writeFixtureWeights(dir);
    const std::string seq = dir / "seq";
    test::CliResult r = test::runCli("render --scene cornell-moving --frames 2 --width 24 --height 16 --spp 2 --out " + seq);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string out = dir / "out";
    r = test::runCli("denoise --sequence " + seq + " --out " + out + " --method learned --learned-weights " + wpath);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(std::filesystem::exists(out + "/frame_0001.exr")) << r.output;
    r = test::runCli("denoise --sequence " + seq + " --out " + out + " --method auto --learned-weights " + wpath);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("auto -> blend"), std::string::npos) << r.output;
    const std::string out2 = dir / "out2";
    r = test::runCli("denoise --sequence " + seq + " --out " + out2 + " --method learned --learned-weights " + dir / "nope");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find(dir / "nope"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out2));
}

// DenoiseOptions::weights, the network loaded once: a weight file's network is used (not the
// built-in one), and the built-in weights by object equal the default (none given).
TEST(LearnedMethod, LoadedWeightsAreUsed) {
    test::TempDir dir;
    const std::string wpath = writeFixtureWeights(dir);
    const Synth sc;
    const Frame in = sc.inputs(true);
    const DenoiseOptions byPath = learnedOptions(wpath);
    DenoiseOptions builtin = learnedOptions("");
    DenoiseOptions builtinObject = learnedOptions("");
    builtinObject.weights = LearnedWeights::builtin();
    EXPECT_TRUE(test::sameImages(denoise(in, builtin), denoise(in, builtinObject)));
    EXPECT_FALSE(test::sameImages(denoise(in, builtin), denoise(in, byPath)));  // the fixture's are other weights
}

}  // namespace
}  // namespace atrous

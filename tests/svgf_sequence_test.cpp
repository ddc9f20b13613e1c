// SVGF sequences on disk: sequence I/O (listing, loading, the errors of a bad sequence) and the
// sequence denoise command, on the synthetic sequences of svgf_test_util.h.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/params.h"
#include "atrous/svgf.h"
#include "core/parallel.h"
#include "filters/svgf_pipeline.h"
#include "atrous/io/image_io.h"
#include "atrous/io/sequence.h"
#include "learned_fixture.h"
#include "svgf_test_util.h"
#include "test_util.h"

// The sequence command's flags live in the CLI's sources, which are not part of atrous_lib;
// compile its translation unit into this test so they can be tested as functions. The session
// itself is the library's (include/atrous/sequence.h).
#include "../apps/atrous/denoise_sequence.cpp"
#include "atrous/io/staged_dir.h"

using namespace atrous;
using namespace atrous::svgf_test;

// ---- sequence I/O -------------------------------------------------------------------------------

namespace {

// Writes frames [first, first + count) of the scene as a sequence directory.
void writeSequence(const std::string& dir, const SceneOptions& o, int count, int first = 0, bool reference = true) {
    for (int t = 0; t < count; ++t) {
        SynthFrame f = makeFrame(o, t);
        std::string fd = dir + "/" + io::sequenceFrameName(first + t);
        std::filesystem::create_directories(fd);
        Image position(o.width, o.height, 3);
        atrous::writeImage(fd + "/color.exr", f.color);
        atrous::writeImage(fd + "/albedo.exr", f.albedo);
        atrous::writeImage(fd + "/normal.exr", f.normal);
        atrous::writeImage(fd + "/position.exr", position);
        atrous::writeImage(fd + "/depth.exr", f.depth);
        atrous::writeImage(fd + "/ids.exr", f.ids);
        atrous::writeImage(fd + "/motion.exr", f.motion);
        if (reference) atrous::writeImage(fd + "/reference.exr", f.truth);
    }
}

// Writes `count` frames of a w x h scene (noise σ `noise`) to dir/seq; returns the arguments
// that denoise it into dir/out, the CLI set quiet.
cli::SequenceDenoiseArgs sequenceArgs(const test::TempDir& dir, int w, int h, float noise, int count) {
    SceneOptions o;
    o.width = w, o.height = h;
    o.noiseSigma = noise;
    writeSequence(dir / "seq", o, count);
    cli::SequenceDenoiseArgs args;
    args.sequenceDir = dir / "seq";
    args.outDir = dir / "out";
    cli::verbosity() = cli::Verbosity::Quiet;  // the CLI's --quiet (progress.h)
    return args;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

}  // namespace

TEST(SvgfSequence, ListsAndLoadsFramesInOrder) {
    test::TempDir dir;
    SceneOptions o;
    o.width = 24, o.height = 16;
    writeSequence(dir.str(), o, 3, 8);
    std::filesystem::create_directories(dir / "not_a_frame");
    auto frames = io::listSequenceFrames(dir.str());
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_NE(frames[0].find("frame_0008"), std::string::npos);
    EXPECT_NE(frames[2].find("frame_0010"), std::string::npos);
    int w = 0, h = 0;
    io::validateSequence(frames, w, h);
    EXPECT_EQ(w, 24);
    EXPECT_EQ(h, 16);
    io::SequenceFrame f = io::loadSequenceFrame(frames[1]);
    EXPECT_EQ(f.index, 9);
    SynthFrame truth = makeFrame(o, 1);
    EXPECT_EQ(maxAbsDiff(f.color, truth.color), 0.0f);
    EXPECT_EQ(f.depth(0, 0, 0), 1e30f);
    EXPECT_EQ(f.motion(boxX0(o, 1) + 1, boxY0(o) + 1, 0), -o.boxSpeed);
    EXPECT_FALSE(f.reference.empty());
    EXPECT_TRUE(f.emission.empty());
}

TEST(SvgfSequence, GapsMissingBuffersAndSizeMismatchesAreNamed) {
    SceneOptions o;
    o.width = 16, o.height = 12;
    {
        test::TempDir dir;
        writeSequence(dir.str(), o, 1, 0);
        writeSequence(dir.str(), o, 1, 2);
        std::string msg = errorOf([&] { io::listSequenceFrames(dir.str()); });
        EXPECT_NE(msg.find("frame_0001"), std::string::npos) << msg;
    }
    {
        test::TempDir dir;
        EXPECT_NE(errorOf([&] { io::listSequenceFrames(dir.str()); }).find("no frame"), std::string::npos);
        EXPECT_NE(errorOf([&] { io::listSequenceFrames(dir / "absent"); }).find("absent"), std::string::npos);
    }
    {
        test::TempDir dir;
        writeSequence(dir.str(), o, 2);
        std::filesystem::remove(dir / "frame_0001/motion.exr");
        auto frames = io::listSequenceFrames(dir.str());
        int w, h;
        // A buffer in some frames only: named in the check of the whole sequence and, given the
        // sequence's buffer list, when the frame is loaded.
        std::string msg = errorOf([&] { io::validateSequence(frames, w, h); });
        EXPECT_NE(msg.find("frame_0001/motion.exr"), std::string::npos) << msg;
        const std::vector<std::string> all(io::kSequenceBuffers, io::kSequenceBuffers + 7);
        msg = errorOf([&] { io::loadSequenceFrame(frames[1], all); });
        EXPECT_NE(msg.find("frame_0001/motion.exr"), std::string::npos) << msg;
    }
    {
        test::TempDir dir;
        writeSequence(dir.str(), o, 1, 0);
        SceneOptions big = o;
        big.width = 20;
        writeSequence(dir.str(), big, 1, 1);
        auto frames = io::listSequenceFrames(dir.str());
        int w, h;
        std::string msg = errorOf([&] { io::validateSequence(frames, w, h); });
        EXPECT_NE(msg.find("frame_0001/color.exr"), std::string::npos) << msg;
        EXPECT_NE(msg.find("frame_0000/color.exr"), std::string::npos) << msg;
        // Within one frame as well.
        atrous::writeImage(dir / "frame_0000/ids.exr", Image(20, 12, 3));
        msg = errorOf([&] { io::loadSequenceFrame(frames[0]); });
        EXPECT_NE(msg.find("ids.exr"), std::string::npos) << msg;
        EXPECT_NE(msg.find("color.exr"), std::string::npos) << msg;
    }
}

// Runs `denoise --sequence` (SVGF, or SVGF with the learned spatial filter) on a 4-frame noisy
// sequence: every frame written (EXR and PNG), finite, and closer to the truth than the noisy
// input (measured ~5-20x; bound 2x).
static void checkSequenceCommand(const test::TempDir& dir, bool learnedSpatial) {
    cli::SequenceDenoiseArgs args = sequenceArgs(dir, 48, 32, 0.2f, 4);
    args.options.method = kSvgfMethod;
    SvgfParams p;
    p.learnedSpatial = learnedSpatial;
    args.options.params = ParamSet(svgfParams(), p);
    SceneOptions o;
    o.width = 48, o.height = 32;
    o.noiseSigma = 0.2f;
    EXPECT_EQ(cli::runSequenceDenoise(args), 0);
    for (int t = 0; t < 4; ++t) {
        std::string name = io::sequenceFrameName(t);
        ASSERT_TRUE(std::filesystem::exists(dir / ("out/" + name + ".png"))) << name;
        Image out = atrous::readImage(dir / ("out/" + name + ".exr"));
        SynthFrame f = makeFrame(o, t);
        ASSERT_TRUE(allFinite(out)) << name;
        EXPECT_LT(mse(out, f.truth), 0.5 * mse(f.color, f.truth)) << name << (learnedSpatial ? " learned" : "");
    }
}

TEST(SvgfSequence, DenoiseCommandWritesEveryFrameAndBeatsTheInput) {
    test::TempDir dir;
    checkSequenceCommand(dir, false);
    if (io::findOnPath("ffmpeg").empty())
        EXPECT_FALSE(std::filesystem::exists(dir / "out/preview.mp4"));
    else
        EXPECT_TRUE(std::filesystem::exists(dir / "out/preview.mp4"));
}

TEST(SvgfSequence, EveryParamHasAFlag) {
    CLI::App app;
    std::deque<ParamSet> sets;  // one per sequence method, in the registry's order
    cli::addSequenceOptions(app, sets);
    const char* argv[] = {"x", "--svgf-sigma-l", "2", "--svgf-sigma-n", "64", "--svgf-sigma-z", "3", "--svgf-alpha", "0.3",
                          "--svgf-moments-alpha", "0.4", "--svgf-history-cap", "16", "--svgf-levels", "4",
                          "--svgf-feedback-tap", "1", "--svgf-spatial-variance-frames", "2", "--svgf-depth-tolerance", "5",
                          "--svgf-normal-cos", "0.5", "--taa", "--taa-alpha", "0.25", "--svgf-emission-alpha", "0.5",
                          "--svgf-emission-motion-alpha", "0.75", "--svgf-learned-spatial"};
    app.parse(int(sizeof(argv) / sizeof(argv[0])), argv);
    const SvgfParams* found = nullptr;
    for (const ParamSet& set : sets) found = found ? found : set.get<SvgfParams>();
    ASSERT_NE(found, nullptr);
    const SvgfParams& p = *found;
    EXPECT_EQ(p.sigmaL, 2.0f);
    EXPECT_EQ(p.sigmaN, 64.0f);
    EXPECT_EQ(p.sigmaZ, 3.0f);
    EXPECT_EQ(p.alpha, 0.3f);
    EXPECT_EQ(p.momentsAlpha, 0.4f);
    EXPECT_EQ(p.historyCap, 16);
    EXPECT_EQ(p.levels, 4);
    EXPECT_EQ(p.feedbackTap, 1);
    EXPECT_EQ(p.spatialVarianceFrames, 2);
    EXPECT_EQ(p.depthTolerance, 5.0f);
    EXPECT_EQ(p.normalCos, 0.5f);
    EXPECT_TRUE(p.taa);
    EXPECT_EQ(p.taaAlpha, 0.25f);
    EXPECT_EQ(p.emissionAlpha, 0.5f);
    EXPECT_EQ(p.emissionMotionAlpha, 0.75f);
    EXPECT_TRUE(p.learnedSpatial);
}

// The command with the learned spatial filter (--svgf-learned-spatial): every frame written,
// finite, and closer to the truth than the input, with the same bound as the SVGF case above.
TEST(SvgfSequence, DenoiseCommandWithTheLearnedSpatialFilter) {
    test::TempDir dir;
    checkSequenceCommand(dir, true);
}

// --learned-weights reaches the learned spatial filter: another valid file (the parity fixture's
// random weights) changes every frame after the first few; a missing, corrupt or retired
// version-2 file is refused before anything is written (exit 2, one line naming the flag and the
// file); without --svgf-learned-spatial the flag is noted as ignored.
TEST(SvgfSequence, LearnedWeightsReachTheLearnedSpatialFilter) {
    test::TempDir dir;
    sequenceArgs(dir, 32, 24, 0.2f, 3);  // writes dir/seq
    const std::string seq = dir / "seq";
    const std::string wpath = dir / "fixture.atrl";
    const std::vector<std::uint8_t>& w = test::fixture().weights;
    std::ofstream(wpath, std::ios::binary).write(reinterpret_cast<const char*>(w.data()), std::streamsize(w.size()));
    const std::string base = "denoise --sequence " + seq + " --method svgf --svgf-learned-spatial --out ";
    test::CliResult r = test::runCli(base + dir / "builtin");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    r = test::runCli(base + dir / "fixture" + " --learned-weights " + wpath);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(r.output.find("ignored"), std::string::npos) << r.output;
    for (int t = 0; t < 3; ++t) {
        const std::string name = io::sequenceFrameName(t) + ".exr";
        const Image a = atrous::readImage(dir / ("builtin/" + name)), b = atrous::readImage(dir / ("fixture/" + name));
        ASSERT_TRUE(allFinite(b)) << name;
        // Outputs are O(1); random weights against trained ones differ far above rounding.
        EXPECT_GT(maxAbsDiff(a, b), 1e-2f) << name;
    }
    // Missing, not a weight file, the fixture relabelled version 2 (tests/learned_fixture.h).
    const std::vector<std::string> bads = test::badWeightFiles(dir.path().string());
    const std::string junk = bads[1];
    for (const std::string& bad : bads) {
        r = test::runCli(base + dir / "bad" + " --learned-weights " + bad);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(bad), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("--learned-weights"), std::string::npos) << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
        EXPECT_FALSE(std::filesystem::exists(dir / "bad")) << bad;
    }
    EXPECT_NE(r.output.find("version 2"), std::string::npos) << r.output;  // the last one, v2
    // Without the learned spatial filter the file is not read: noted, and SVGF's à-trous runs.
    r = test::runCli("denoise --sequence " + seq + " --method svgf --out " + dir / "plain" + " --learned-weights " + junk);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("ignored with --method svgf: --learned-weights"), std::string::npos) << r.output;
}

TEST(SvgfSequence, PerFrameEawAlsoRuns) {
    test::TempDir dir;
    cli::SequenceDenoiseArgs args = sequenceArgs(dir, 32, 24, 0.2f, 2);
    args.options.method = "eaw";
    args.options.preview = false;
    EXPECT_EQ(cli::runSequenceDenoise(args), 0);
    EXPECT_TRUE(std::filesystem::exists(dir / "out/frame_0001.exr"));
}

TEST(SvgfSequence, BadSequencesWriteNothing) {
    test::TempDir dir;
    cli::SequenceDenoiseArgs args = sequenceArgs(dir, 16, 12, SceneOptions{}.noiseSigma, 3);
    std::filesystem::remove(dir / "seq/frame_0002/albedo.exr");
    std::string msg = errorOf([&] { cli::runSequenceDenoise(args); });
    EXPECT_NE(msg.find("frame_0002/albedo.exr"), std::string::npos) << msg;
    EXPECT_FALSE(std::filesystem::exists(dir / "out"));
    args.options.method = "median";
    EXPECT_NE(errorOf([&] { cli::runSequenceDenoise(args); }).find("median"), std::string::npos);
}

// `atrous denoise --sequence`: the CLI wiring of the sequence denoiser (SVGF, per-frame EAW/SURE).
#include <gtest/gtest.h>

#include <filesystem>

#include "io/image_io.h"
#include "test_util.h"

using atrous::test::countEntries;
using atrous::test::runCli;
using atrous::test::TempDir;
namespace fs = std::filesystem;

namespace {

std::string renderSequence(const TempDir& dir) {
    const std::string seq = dir / "seq";
    auto r = runCli("render --scene cornell --frames 3 --spp 1 --width 32 --height 24 --reference-spp 4 --out " + seq);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return seq;
}

}  // namespace

TEST(SequenceCli, SvgfEawAndSureDenoiseEveryFrame) {
    TempDir dir;
    const std::string seq = renderSequence(dir);
    for (const char* method : {"svgf", "eaw", "sure"}) {
        const std::string out = dir / (std::string("out_") + method);
        auto r = runCli(std::string("denoise --method ") + method + " --sequence " + seq + " --out " + out);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        for (int f = 0; f < 3; ++f) {
            const std::string exr = out + "/frame_000" + std::to_string(f) + ".exr";
            ASSERT_TRUE(fs::exists(exr)) << exr;
            atrous::Image img = atrous::io::readImage(exr);
            EXPECT_EQ(img.width(), 32);
            EXPECT_EQ(img.height(), 24);
        }
    }
}

TEST(SequenceCli, BadSequencesExitTwoAndWriteNothing) {
    TempDir dir;
    const std::string seq = renderSequence(dir);
    // svgf needs a sequence.
    auto r = runCli("denoise --method svgf --color " + seq + "/frame_0000/color.exr --out " + (dir / "x.exr"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("--sequence"), std::string::npos) << r.output;
    // A missing frame in the middle: the error names it, nothing is written.
    fs::remove_all(seq + "/frame_0001");
    const std::string out = dir / "out";
    r = runCli("denoise --method svgf --sequence " + seq + " --out " + out);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("frame_0001"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out) && countEntries(out) > 0);
    // A missing buffer.
    fs::remove(seq + "/frame_0002/motion.exr");
    r = runCli("denoise --method svgf --sequence " + seq + " --out " + out);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    // Not a directory.
    r = runCli("denoise --method svgf --sequence " + (dir / "nope") + " --out " + out);
    EXPECT_EQ(r.exitCode, 2) << r.output;
}

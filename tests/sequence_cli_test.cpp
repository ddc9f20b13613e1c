// `atrous denoise --sequence`: the CLI wiring of the sequence denoiser (SVGF, per-frame EAW/SURE).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "atrous/io/image_io.h"
#include "test_util.h"

using atrous::test::countEntries;
using atrous::test::runCli;
using atrous::test::sameImages;
using atrous::test::renderSequence;
using atrous::test::TempDir;
namespace fs = std::filesystem;

TEST(SequenceCli, SvgfEawAndSureDenoiseEveryFrame) {
    TempDir dir;
    const std::string seq = renderSequence(dir);
    for (const char* method : {"temporal", "svgf", "eaw", "sure"}) {
        const std::string out = dir / (std::string("out_") + method);
        auto r = runCli(std::string("denoise --method ") + method + " --sequence " + seq + " --out " + out);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        for (int f = 0; f < 3; ++f) {
            const std::string exr = out + "/frame_000" + std::to_string(f) + ".exr";
            ASSERT_TRUE(fs::exists(exr)) << exr;
            atrous::Image img = atrous::readImage(exr);
            EXPECT_EQ(img.width(), 32);
            EXPECT_EQ(img.height(), 24);
        }
    }
}

// Per-frame EAW/SURE of a sequence uses every buffer of each frame, emission included, through the
// same input assembly as `denoise --in FRAME_DIR` (Frame). Same buffers, deterministic
// CPU filters: equal bit for bit. A frame without its emission.exr denoises differently, so the
// equality shows the emission was read.
TEST(SequenceCli, PerFrameMethodsEqualDenoiseOfEachFrame) {
    TempDir dir;
    const std::string seq = renderSequence(dir);
    for (const char* method : {"eaw", "sure"}) {
        const std::string out = dir / (std::string("seq_") + method);
        auto r = runCli(std::string("denoise --method ") + method + " --device cpu --sequence " + seq + " --out " + out);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        for (int f = 0; f < 3; ++f) {
            const std::string frame = seq + "/frame_000" + std::to_string(f);
            ASSERT_TRUE(fs::exists(frame + "/emission.exr")) << frame;
            const std::string one = dir / "one.exr";
            r = runCli(std::string("denoise --method ") + method + " --device cpu --in " + frame + " --out " + one);
            ASSERT_EQ(r.exitCode, 0) << r.output;
            const atrous::Image fromSequence = atrous::readImage(out + "/frame_000" + std::to_string(f) + ".exr");
            EXPECT_TRUE(sameImages(fromSequence, atrous::readImage(one))) << method << " frame " << f;
            const std::string bare = dir / "bare";
            fs::remove_all(bare);
            fs::create_directories(bare);
            for (const auto& e : fs::directory_iterator(frame))
                if (e.path().filename() != "emission.exr") fs::copy_file(e.path(), fs::path(bare) / e.path().filename());
            r = runCli(std::string("denoise --method ") + method + " --device cpu --in " + bare + " --out " + one);
            ASSERT_EQ(r.exitCode, 0) << r.output;
            EXPECT_FALSE(sameImages(fromSequence, atrous::readImage(one))) << method << " frame " << f;
        }
    }
}

TEST(SequenceCli, BadSequencesExitTwoAndWriteNothing) {
    TempDir dir;
    const std::string seq = renderSequence(dir);
    // svgf needs a sequence.
    auto r = atrous::test::expectCli("denoise --method svgf --color " + seq + "/frame_0000/color.exr --out " + (dir / "x.exr"), 2,
                             {"--sequence"});
    // A missing frame in the middle: the error names it, nothing is written.
    fs::remove_all(seq + "/frame_0001");
    const std::string out = dir / "out";
    r = atrous::test::expectCli("denoise --method svgf --sequence " + seq + " --out " + out, 2, {"frame_0001"});
    EXPECT_FALSE(fs::exists(out) && countEntries(out) > 0);
    // A missing buffer.
    fs::remove(seq + "/frame_0002/motion.exr");
    r = runCli("denoise --method svgf --sequence " + seq + " --out " + out);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    // Not a directory.
    r = runCli("denoise --method svgf --sequence " + (dir / "nope") + " --out " + out);
    EXPECT_EQ(r.exitCode, 2) << r.output;
}

namespace {

std::string readFile(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

// Names of the entries of `dir`, sorted.
std::vector<std::string> entries(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace

// A frame that only decoding finds broken (header fine, pixels cut off) fails after earlier frames
// were denoised: OUTDIR must still be as it was (absent, or with its old files), and no staging
// directory may be left next to it.
TEST(SequenceCli, TruncatedFrameLeavesTheOutputUntouched) {
    TempDir dir;
    const std::string seq = renderSequence(dir);
    const std::string color = seq + "/frame_0002/color.exr";
    fs::resize_file(color, fs::file_size(color) * 2 / 3);
    fs::create_directories(dir / "old");
    std::ofstream(dir / "old/frame_0000.exr") << "old result";
    for (const char* method : {"temporal", "svgf", "eaw", "sure"}) {
        for (const std::string out : {dir / "fresh", dir / "old"}) {
            auto r = runCli(std::string("denoise --method ") + method + " --sequence " + seq + " --out " + out);
            EXPECT_EQ(r.exitCode, 2) << r.output;
            EXPECT_NE(r.output.find("frame_0002/color.exr"), std::string::npos) << r.output;
        }
        EXPECT_FALSE(fs::exists(dir / "fresh")) << method;
        EXPECT_EQ(entries(dir / "old"), std::vector<std::string>{"frame_0000.exr"}) << method;
        EXPECT_EQ(readFile(dir / "old/frame_0000.exr"), "old result");
        EXPECT_EQ(entries(dir.str()), (std::vector<std::string>{"old", "seq"})) << method;  // no staging left
    }
}

// Re-using directories: a shorter render removes the old sequence's extra frames (and the old
// frames' reference.exr when this run writes none), and a shorter denoise run removes the old
// frame_NNNN.exr/png it does not write; both say so in one line. Other files stay.
TEST(SequenceCli, ReusedDirectoriesHoldOnlyThisRunsFrames) {
    TempDir dir;
    const std::string seq = renderSequence(dir);  // 3 frames with reference.exr
    const std::string out = dir / "out";
    auto r = runCli("denoise --method eaw --sequence " + seq + " --out " + out);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    std::ofstream(out + "/notes.txt") << "mine";

    r = runCli("render --scene cornell --frames 2 --spp 1 --width 32 --height 24 --out " + seq);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("removed 1 frame directory of an earlier run"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("frame_0002"), std::string::npos) << r.output;
    EXPECT_EQ(entries(seq), (std::vector<std::string>{"frame_0000", "frame_0001"}));
    EXPECT_FALSE(fs::exists(seq + "/frame_0001/reference.exr"));  // the old run's, not this one's

    r = runCli("denoise --method eaw --sequence " + seq + " --out " + out);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("removed 2 files of an earlier run"), std::string::npos) << r.output;
    std::vector<std::string> want = {"frame_0000.exr", "frame_0000.png", "frame_0001.exr", "frame_0001.png", "notes.txt"};
    std::vector<std::string> got = entries(out);
    got.erase(std::remove(got.begin(), got.end(), "preview.mp4"), got.end());  // when ffmpeg is on PATH
    EXPECT_EQ(got, want);
    EXPECT_EQ(readFile(out + "/notes.txt"), "mine");
    EXPECT_EQ(entries(dir.str()), (std::vector<std::string>{"out", "seq"}));  // no staging left
}

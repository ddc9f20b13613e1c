// Other renderers' folder layouts (docs/inputs.md, "Render directories"; issue 28): a LuxCore
// render folder (RGB.exr, ALBEDO.exr, AVG_SHADING_NORMAL.exr, POSITION.exr, DEPTH.exr,
// EMISSION.exr) is read by `--in DIR` as atrous's own folder is, and a sequence of numbered frame
// folders with those names by `--sequence`, without renaming anything. The inputs are made here:
// an atrous render whose files are copied under LuxCore's names.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "atrous/io/image_io.h"
#include "test_util.h"

using atrous::test::runCli;
using atrous::test::sameImages;
using atrous::test::TempDir;
namespace fs = std::filesystem;

namespace {

// atrous's file name -> LuxCore's film output name for the same buffer.
const std::vector<std::pair<std::string, std::string>> kLuxNames = {
    {"color.exr", "RGB.exr"},       {"albedo.exr", "ALBEDO.exr"}, {"normal.exr", "AVG_SHADING_NORMAL.exr"},
    {"position.exr", "POSITION.exr"}, {"depth.exr", "DEPTH.exr"}, {"emission.exr", "EMISSION.exr"}};

// Copies the buffers of atrous render folder `from` into `to` under LuxCore's names (lux) or
// atrous's own (the same buffers, for the comparison).
void copyBuffers(const std::string& from, const std::string& to, bool lux) {
    fs::create_directories(to);
    for (const auto& [ours, theirs] : kLuxNames) fs::copy_file(fs::path(from) / ours, fs::path(to) / (lux ? theirs : ours));
}

// An atrous render of `frames` frames of `scene` at 24x16, 1 spp: DIR/seq/frame_NNNN/.
std::string renderFrames(const TempDir& dir, const std::string& scene, int frames) {
    const std::string seq = dir / "seq";
    auto r = runCli("render --scene " + scene + " --frames " + std::to_string(frames) + " --spp 1 --width 24 --height 16 --out " + seq);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return seq;
}

// Copies `buffer`.exr of each of the first `frames` frames of `seq` (frame_000F/) into the folder
// `dst` (created) as name(F + 1): the layouts other tools leave.
void copyFrames(const std::string& seq, int frames, const std::string& buffer, const std::string& dst,
                const std::function<std::string(int)>& name) {
    fs::create_directories(dst);
    for (int f = 0; f < frames; ++f)
        fs::copy_file(seq + "/frame_000" + std::to_string(f) + "/" + buffer + ".exr", dst + "/" + name(f + 1));
}

}  // namespace

TEST(RendererLayouts, LuxCoreStillFolderIsReadUnderItsOwnNames) {
    TempDir dir;
    const std::string render = dir / "render";
    auto r = runCli("render --scene cornell --spp 2 --width 32 --height 24 --out " + render);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string lux = dir / "lux", ours = dir / "ours";
    copyBuffers(render, lux, true);
    copyBuffers(render, ours, false);
    for (const char* method : {"sure", "blend"}) {
        const std::string a = dir / (std::string("lux_") + method + ".exr"), b = dir / (std::string("ours_") + method + ".exr");
        r = runCli("denoise --in " + lux + " --method " + method + " --out " + a);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        EXPECT_NE(r.output.find("buffers used: color,albedo,normal,position,depth"), std::string::npos) << r.output;
        auto r2 = runCli("denoise --in " + ours + " --method " + method + " --out " + b);
        ASSERT_EQ(r2.exitCode, 0) << r2.output;
        EXPECT_TRUE(sameImages(atrous::readImage(a), atrous::readImage(b))) << method;
    }
    // atrous's own name wins where a folder has both: a black color.exr beside RGB.exr gives what the
    // black colour gives with atrous's names.
    const atrous::Image black(32, 24, 3);
    atrous::writeImage(lux + "/color.exr", black);
    atrous::writeImage(ours + "/color.exr", black);
    r = runCli("denoise --in " + lux + " --method eaw --out " + dir / "both.exr");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    r = runCli("denoise --in " + ours + " --method eaw --out " + dir / "black.exr");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(sameImages(atrous::readImage(dir / "both.exr"), atrous::readImage(dir / "black.exr")));
    EXPECT_FALSE(sameImages(atrous::readImage(dir / "both.exr"), atrous::readImage(dir / "lux_sure.exr")));
    // The output may not overwrite any of LuxCore's inputs either.
    r = runCli("denoise --in " + lux + " --method eaw --out " + lux + "/ALBEDO.exr");
    EXPECT_EQ(r.exitCode, 2) << r.output;
}

TEST(RendererLayouts, NumberedFrameFoldersWithLuxCoreNamesAreASequence) {
    TempDir dir;
    const std::string seq = renderFrames(dir, "cornell-moving", 3);
    atrous::test::CliResult r;
    const std::string lux = dir / "lux";
    for (int f = 0; f < 3; ++f)  // LuxCore renders one folder per frame; here 0001/, 0002/, 0003/
        copyBuffers(seq + "/frame_000" + std::to_string(f), lux + "/000" + std::to_string(f + 1), true);
    const std::string out = dir / "out";
    r = runCli("denoise --sequence " + lux + " --method eaw --out " + out);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (int f = 1; f <= 3; ++f) {
        const std::string got = out + "/000" + std::to_string(f) + ".exr";  // the frame folder's name
        ASSERT_TRUE(fs::exists(got)) << r.output;
        // Each frame as `--in FOLDER` denoises it.
        const std::string want = dir / ("one_" + std::to_string(f) + ".exr");
        auto r1 = runCli("denoise --in " + lux + "/000" + std::to_string(f) + " --method eaw --out " + want);
        ASSERT_EQ(r1.exitCode, 0) << r1.output;
        EXPECT_TRUE(sameImages(atrous::readImage(got), atrous::readImage(want))) << f;
    }
    // `inspect` shows what the sequence gives per buffer, from the renderer's own files.
    r = runCli("inspect " + lux);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("sequence of 3 frames (0001 ... 0003), 24x16"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("0001/AVG_SHADING_NORMAL.exr"), std::string::npos) << r.output;
    // A buffer in only some frames: one line naming the frame's file, exit 2, nothing written.
    fs::remove(lux + "/0002/ALBEDO.exr");
    r = runCli("inspect " + lux);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    const std::string out2 = dir / "out2";
    r = runCli("denoise --sequence " + lux + " --method eaw --out " + out2);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("0002/ALBEDO.exr: missing"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out2));
    // A gap in the numbering: the missing frame is named.
    fs::remove_all(lux + "/0002");
    r = runCli("denoise --sequence " + lux + " --method eaw --out " + out2);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("0002 (a numbered frame folder) is missing"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out2));
    // Numbered folders without a colour file are not frames.
    fs::remove_all(lux);
    fs::create_directories(lux + "/0001");
    r = runCli("denoise --sequence " + lux + " --method eaw --out " + out2);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("no frame_NNNN directories"), std::string::npos) << r.output;
}

TEST(RendererLayouts, NumberedFilesPerBufferAreASequence) {
    TempDir dir;
    const std::string seq = renderFrames(dir, "cornell-moving", 3);
    atrous::test::CliResult r;
    // One folder, one file per buffer and frame, as compositors and some renderers write them.
    const std::string per = dir / "per";
    for (const std::string b : {"color", "albedo", "normal", "depth"})
        copyFrames(seq, 3, b, per, [&](int n) { return b + "_000" + std::to_string(n) + ".exr"; });
    const std::string out = dir / "out";
    r = runCli("denoise --sequence " + per + " --method sure --out " + out);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (int f = 1; f <= 3; ++f) {
        // The same buffers as a frame folder, denoised with --in.
        const std::string one = dir / ("one_" + std::to_string(f));
        fs::create_directories(one);
        for (const char* b : {"color", "albedo", "normal", "depth"})
            fs::copy_file(per + "/" + b + "_000" + std::to_string(f) + ".exr", one + "/" + b + ".exr");
        auto r1 = runCli("denoise --in " + one + " --method sure --out " + one + ".exr");
        ASSERT_EQ(r1.exitCode, 0) << r1.output;
        const std::string got = out + "/color_000" + std::to_string(f) + ".exr";  // the colour file's name
        ASSERT_TRUE(fs::exists(got)) << r.output;
        EXPECT_TRUE(sameImages(atrous::readImage(got), atrous::readImage(one + ".exr"))) << f;
    }
    // --add-pass copies layered frames only; a buffer missing in one frame is named.
    r = runCli("denoise --sequence " + per + " --method sure --add-pass denoised --out " + dir / "out3");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    fs::remove(per + "/normal_0002.exr");
    r = runCli("denoise --sequence " + per + " --method sure --out " + dir / "out2");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("normal_0002.exr: missing, but"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out2"));
}

TEST(RendererLayouts, PatternsWithStartEndAndStep) {
    TempDir dir;
    const std::string seq = renderFrames(dir, "cornell", 5);
    atrous::test::CliResult r;
    // Two sequences in one folder, as a compositor leaves them: a pattern picks one.
    const std::string src = dir / "src";
    for (const std::string stem : {"render", "other"})
        copyFrames(seq, 5, "color", src, [&](int n) { return stem + "000" + std::to_string(n) + ".exr"; });
    r = runCli("denoise --sequence " + src + " --method eaw --out " + dir / "all");
    EXPECT_EQ(r.exitCode, 2) << r.output;  // two prefixes in the folder: refused without a pattern
    struct Case {
        std::string flags;
        std::vector<int> frames;
        std::string stem;  // the outputs keep the inputs' names
    };
    for (const Case& c : {Case{"'" + src + "/render####.exr' --start 2 --end 4", {2, 3, 4}, "render"},
                          Case{"'" + src + "/render%04d.exr' --step 2", {1, 3, 5}, "render"},
                          Case{"'" + src + "/other%04d.exr' --start 4", {4, 5}, "other"}}) {
        const std::string out = dir / "out";
        fs::remove_all(out);
        r = runCli("denoise --method eaw --out " + out + " --sequence " + c.flags);
        ASSERT_EQ(r.exitCode, 0) << c.flags << r.output;
        std::vector<std::string> got;
        for (const auto& e : fs::directory_iterator(out))
            if (e.path().extension() == ".exr") got.push_back(e.path().filename().string());
        std::sort(got.begin(), got.end());
        std::vector<std::string> want;
        for (int f : c.frames) want.push_back(c.stem + "000" + std::to_string(f) + ".exr");
        EXPECT_EQ(got, want) << c.flags;
    }
    // Bad ranges and gaps: one line, exit 2, nothing written.
    fs::remove(src + "/render0003.exr");
    const std::string bad = dir / "bad";
    for (const std::string& flags : {"'" + src + "/render####.exr'", "'" + src + "/render####.exr' --step 0",
                                     "'" + src + "/render####.exr' --start 4 --end 2", "'" + src + "/none####.exr'",
                                     "'" + src + "/render####.exr' --start 9"}) {
        r = runCli("denoise --method eaw --out " + bad + " --sequence " + flags);
        EXPECT_EQ(r.exitCode, 2) << flags << r.output;
        EXPECT_FALSE(fs::exists(bad)) << flags;
    }
    r = runCli("denoise --method eaw --out " + bad + " --sequence '" + src + "/render####.exr' --start 1 --step 2");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("render0003.exr (the pattern's file) is missing"), std::string::npos) << r.output;
    r = runCli("denoise --method svgf --out " + bad + " --sequence '" + src + "/render####.exr' --start 4 --step 2");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    r = runCli("denoise --in " + seq + "/frame_0000 --out " + dir / "x.exr --start 1");
    EXPECT_EQ(r.exitCode, 2) << r.output;
}

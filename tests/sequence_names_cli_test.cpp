// `atrous denoise --sequence IN --out OUT` (issue 49): the outputs keep their input's names or
// follow a pattern (OUT/####.exr), an RGBA frame's alpha comes back bit for bit, and entries named
// like frames that are not files, or a gap in the numbering, are refused in one line naming them.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "atrous/image.h"
#include "atrous/io/alpha.h"
#include "atrous/io/image_io.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace atrous::test;  // TempDir, expectCli, randomImage, runShell, sameImages

namespace {

// DIR/NAME0001.exr ... DIR/NAME000n.exr (first .. first+n-1): noisy 24x16 frames of `channels`
// channels (4: an alpha in [0, 1) that differs per pixel).
std::string writeFrames(const TempDir& dir, const std::string& sub, const std::string& name, int first, int n,
                        int channels = 3) {
    const std::string seq = dir / sub;
    fs::create_directories(seq);
    for (int i = first; i < first + n; ++i) {
        atrous::Image img = randomImage(24, 16, channels, unsigned(100 + i), 0.0f, 1.0f);
        char file[64];
        std::snprintf(file, sizeof file, "%s%04d.exr", name.c_str(), i);
        atrous::writeImage(seq + "/" + file, img);
    }
    return seq;
}

std::vector<std::string> entries(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename() != "preview.mp4") names.push_back(e.path().filename().string());  // with ffmpeg on PATH
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace

// render0001.exr ... -> OUT/render0001.exr ... (and .png previews of the same names).
TEST(SequenceNames, OutputsKeepTheInputsNames) {
    TempDir dir;
    const std::string seq = writeFrames(dir, "renders", "render", 1, 3);
    const std::string out = dir / "clean";
    expectCli("denoise --method eaw --sequence " + seq + " --out " + out, 0, {"render0003"});
    EXPECT_EQ(entries(out), (std::vector<std::string>{"render0001.exr", "render0001.png", "render0002.exr",
                                                      "render0002.png", "render0003.exr", "render0003.png"}));
    // A folder per frame (LuxCore's 0001/ with RGB.exr): the folder's name + .exr.
    const std::string lux = dir / "lux";
    for (int i = 1; i <= 2; ++i) {
        fs::create_directories(lux + "/000" + std::to_string(i));
        atrous::writeImage(lux + "/000" + std::to_string(i) + "/RGB.exr", randomImage(24, 16, 3, unsigned(i), 0.0f, 1.0f));
    }
    expectCli("denoise --method eaw --sequence " + lux + " --out " + (dir / "luxout"), 0);
    EXPECT_EQ(entries(dir / "luxout"), (std::vector<std::string>{"0001.exr", "0001.png", "0002.exr", "0002.png"}));
}

// --out DIR/####.exr and DIR/f_%03d.exr: the frame number zero-padded to the width.
TEST(SequenceNames, PatternsNameTheOutputs) {
    TempDir dir;
    const std::string seq = writeFrames(dir, "renders", "render", 8, 3);
    expectCli("denoise --method eaw --sequence " + seq + " --out '" + (dir / "a/####.exr") + "'", 0);
    EXPECT_EQ(entries(dir / "a"), (std::vector<std::string>{"0008.exr", "0008.png", "0009.exr", "0009.png", "0010.exr",
                                                            "0010.png"}));
    expectCli("denoise --method eaw --sequence " + seq + " --out '" + (dir / "b/f_%03d_clean.exr") + "'", 0);
    EXPECT_EQ(entries(dir / "b"), (std::vector<std::string>{"f_008_clean.exr", "f_008_clean.png", "f_009_clean.exr",
                                                            "f_009_clean.png", "f_010_clean.exr", "f_010_clean.png"}));
    // The same pixels whatever the names.
    EXPECT_TRUE(atrous::test::sameImages(atrous::readImage(dir / "a/0009.exr"), atrous::readImage(dir / "b/f_009_clean.exr")));
}

// A bad pattern or an output over the inputs: one line, exit 2, nothing written.
TEST(SequenceNames, BadPatternsAndOverwritesAreRefused) {
    TempDir dir;
    const std::string seq = writeFrames(dir, "renders", "render", 1, 2);
    const std::string base = "denoise --method eaw --sequence " + seq + " --out ";
    struct Case {
        std::string out, needle;
    } cases[] = {
        {dir / "x/clean.exr", "this names one file"},
        {dir / "x/##_##.exr", "two groups"},
        {dir / "x/####.jpg", "must end in .exr"},
        {dir / "x/%4x.exr", "%0Nd"},
        {dir / "x/#%04d.exr", "both"},
        {seq, "input directory"},
        {seq + "/####.exr", "input directory"},
    };
    for (const Case& c : cases) {
        const auto r = expectCli(base + "'" + c.out + "'", 2, {c.needle});
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "x"));
    EXPECT_EQ(entries(seq), (std::vector<std::string>{"render0001.exr", "render0002.exr"}));
}

// An RGBA EXR frame's alpha comes back bit for bit in its output frame (as the still path does:
// io/alpha.h), for a per-frame and a sequence method; the colour is denoised as without it.
TEST(SequenceNames, AlphaPassesThroughBitForBit) {
    TempDir dir;
    const std::string seq = writeFrames(dir, "rgba", "render", 1, 3, 4);
    for (const char* method : {"eaw", "temporal"}) {
        const std::string out = dir / (std::string("out_") + method);
        expectCli(std::string("denoise --method ") + method + " --device cpu --sequence " + seq + " --out " + out, 0);
        for (int f = 1; f <= 3; ++f) {
            const std::string name = "/render000" + std::to_string(f) + ".exr";
            const atrous::Image in = atrous::io::readAlpha(seq + name), got = atrous::io::readAlpha(out + name);
            ASSERT_FALSE(in.empty());
            ASSERT_EQ(got.size(), in.size()) << method << name;
            EXPECT_TRUE(std::equal(in.data(), in.data() + in.size(), got.data())) << method << name;
        }
    }
}

// An entry named like a frame that is not one (render0002.exr a directory) used to cut the
// sequence short without a word (frame 1 only, "1 frames", exit 0): refused, naming it.
TEST(SequenceNames, EntriesNamedLikeFramesMustBeFiles) {
    TempDir dir;
    const std::string seq = writeFrames(dir, "renders", "render", 1, 1);
    fs::create_directories(seq + "/render0002.exr");
    const std::string out = dir / "out";
    auto r = expectCli("denoise --method eaw --sequence " + seq + " --out " + out, 2, {"render0002.exr", "a directory"});
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    r = expectCli("denoise --method eaw --sequence '" + seq + "/render####.exr' --out " + out, 2,
                  {"render0002.exr", "not a regular file"});
    EXPECT_FALSE(fs::exists(out));
}

// A gap in the numbering names the file expected as the others are named (render0002.exr, not
// render2) and says how to denoise a range.
TEST(SequenceNames, AGapNamesTheFileExpected) {
    TempDir dir;
    const std::string seq = writeFrames(dir, "renders", "render", 1, 3);
    fs::remove(seq + "/render0002.exr");
    const std::string out = dir / "out";
    expectCli("denoise --method eaw --sequence " + seq + " --out " + out, 2, {"render0002.exr is missing", "--start and --end pick a range"});
    const std::string per = writeFrames(dir, "per", "color_", 1, 3);
    fs::remove(per + "/color_0002.exr");
    expectCli("denoise --method eaw --sequence " + per + " --out " + out, 2, {"color_0002.exr is missing"});
    // --start/--end pick the frames present.
    expectCli("denoise --method eaw --sequence " + seq + " --start 3 --end 3 --out " + out, 0);
    EXPECT_TRUE(fs::exists(out + "/render0003.exr"));
}

// The command line's habits (issue 49): `atrous denoise IN OUT` beside the flags, -i/-o, --quiet
// and -v, --threads, --method none, --exposure.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "atrous/image.h"
#include "atrous/io/image_io.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace atrous::test;  // TempDir, expectCli, randomImage, runShell, sameImages

namespace {

// DIR/noisy.exr: a 32 x 24 noisy colour.
std::string noisyExr(const TempDir& dir) {
    const std::string path = dir / "noisy.exr";
    atrous::writeImage(path, randomImage(32, 24, 3, 11u, 0.0f, 1.0f));
    return path;
}

}  // namespace

// IN OUT as positionals, as flags, mixed: the same output; conflicts and extras are one line, exit 2.
TEST(DenoiseHabits, PositionalInAndOut) {
    TempDir dir;
    const std::string in = noisyExr(dir);
    expectCli("denoise --method eaw " + in + " " + (dir / "a.exr"), 0);
    expectCli("denoise --method eaw --in " + in + " --out " + (dir / "b.exr"), 0);
    expectCli("denoise --method eaw -i " + in + " " + (dir / "c.exr"), 0);
    expectCli("denoise --method eaw " + in + " -o " + (dir / "d.exr"), 0);
    for (const char* f : {"b.exr", "c.exr", "d.exr"})
        EXPECT_TRUE(sameImages(atrous::readImage(dir / "a.exr"), atrous::readImage(dir / f))) << f;
    expectCli("denoise --method eaw --color " + in + " " + (dir / "e.exr"), 0);  // one positional: OUT
    EXPECT_TRUE(fs::exists(dir / "e.exr"));
    expectCli("denoise --method eaw --in " + (dir / "other.exr") + " " + in + " " + (dir / "x.exr"), 2, {"differ", "--in"});
    expectCli("denoise --method eaw " + in + " " + (dir / "x.exr") + " --out " + (dir / "y.exr"), 2, {"differ", "--out"});
    expectCli("denoise --method eaw " + in + " " + (dir / "x.exr") + " " + (dir / "z.exr"), 2, {"too many"});
    expectCli("denoise --method eaw --in " + in, 2, {"--out is required"});
    EXPECT_FALSE(fs::exists(dir / "x.exr") || fs::exists(dir / "y.exr") || fs::exists(dir / "z.exr"));
}

namespace {

std::string stdoutOf(const std::string& args) {
    return runShell("(" + atrous::test::cliPath() + " " + args + " 2>/dev/null)").output;
}
std::string stderrOf(const std::string& args) {
    return runShell("(" + atrous::test::cliPath() + " " + args + " 2>&1 >/dev/null)").output;
}
int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

// Results (the method that ran, the file written) on stdout; notes on stderr; --quiet: nothing on
// success and one line on error; -v: the stage times on stderr.
TEST(DenoiseHabits, QuietVerboseAndStreams) {
    TempDir dir;
    const std::string in = noisyExr(dir);
    const std::string still = "denoise --method sure " + in + " " + (dir / "a.exr");
    const std::string out = stdoutOf(still);
    EXPECT_EQ(lineCount(out), 2) << out;
    EXPECT_NE(out.find("denoise: method sure"), std::string::npos) << out;
    EXPECT_NE(out.find("wrote " + (dir / "a.exr")), std::string::npos) << out;
    const std::string err = stderrOf(still);
    EXPECT_NE(err.find("noise estimated"), std::string::npos) << err;  // no variance: a note
    EXPECT_EQ(err.find("stages ms"), std::string::npos) << err;
    EXPECT_NE(stderrOf(still + " -v").find("stages ms"), std::string::npos);
    EXPECT_EQ(runShell(atrous::test::cliPath() + " " + still + " --quiet").output, "");
    const auto bad = expectCli(still + " --quiet --levels 0", 2);
    EXPECT_EQ(lineCount(bad.output), 1) << bad.output;

    // A sequence: a line per frame and the summary on stdout; the k/N counter on stderr.
    const std::string seq = dir / "seq";
    fs::create_directories(seq);
    for (int i = 1; i <= 3; ++i)
        atrous::writeImage(seq + "/r000" + std::to_string(i) + ".exr", randomImage(16, 8, 3, unsigned(i), 0.0f, 1.0f));
    const std::string run = "denoise --method eaw --sequence " + seq + " " + (dir / "s");
    const std::string seqOut = stdoutOf(run);
    EXPECT_NE(seqOut.find("r0003: eaw"), std::string::npos) << seqOut;
    EXPECT_NE(seqOut.find("sequence: 3 frames"), std::string::npos) << seqOut;
    const std::string seqErr = stderrOf(run);
    EXPECT_NE(seqErr.find("denoise: frame 1/3 ("), std::string::npos) << seqErr;
    EXPECT_NE(seqErr.find("ETA"), std::string::npos) << seqErr;
    EXPECT_NE(seqErr.find("denoise: frame 3/3 ("), std::string::npos) << seqErr;
    EXPECT_EQ(runShell(atrous::test::cliPath() + " " + run + " --quiet").output, "");
}

// --threads N limits TBB for the run; the CPU filters are deterministic, so the output is the same
// bit for bit. Out of range: one line naming the flag.
TEST(DenoiseHabits, ThreadsKeepsTheOutput) {
    TempDir dir;
    const std::string in = noisyExr(dir);
    expectCli("denoise --method sure --device cpu " + in + " " + (dir / "all.exr"), 0);
    expectCli("denoise --method sure --device cpu --threads 1 " + in + " " + (dir / "one.exr"), 0);
    EXPECT_TRUE(sameImages(atrous::readImage(dir / "all.exr"), atrous::readImage(dir / "one.exr")));
    expectCli("denoise --method sure --threads -1 " + in + " " + (dir / "x.exr"), 2, {"--threads"});
    expectCli("bench --what eaw --sizes 16x16 --runs 1 --warmup 0 --device cpu --threads 1", 0);
    expectCli("render --scene cornell --width 8 --height 8 --spp 1 --threads 1 --denoise eaw --out " + (dir / "r"), 0);
}

// --method none writes the colour as read: an EXR copy is the same pixels, a PNG a preview; the
// line says so. --exposure scales a PNG (and a sequence's previews), never an EXR.
TEST(DenoiseHabits, MethodNoneAndExposure) {
    TempDir dir;
    const std::string in = noisyExr(dir);
    expectCli("denoise --method none " + in + " " + (dir / "copy.exr"), 0, {"method none (no filter"});
    EXPECT_TRUE(sameImages(atrous::readImage(in), atrous::readImage(dir / "copy.exr")));
    expectCli("denoise --method none " + in + " " + (dir / "a.png"), 0, {"wrote " + (dir / "a.png")});
    expectCli("denoise --method none --exposure 0.25 " + in + " " + (dir / "b.png"), 0);
    const atrous::Image a = atrous::readImage(dir / "a.png"), b = atrous::readImage(dir / "b.png");
    double sa = 0, sb = 0;
    for (size_t i = 0; i < a.size(); ++i) sa += a.data()[i], sb += b.data()[i];
    EXPECT_LT(sb, 0.5 * sa);  // a quarter of the light: darker
    expectCli("denoise --method none --exposure 2 " + in + " " + (dir / "x.exr"), 2, {"--exposure"});
    expectCli("denoise --method sure --exposure 0 " + in + " " + (dir / "x.png"), 2, {"--exposure"});
    EXPECT_FALSE(fs::exists(dir / "x.exr") || fs::exists(dir / "x.png"));
    // A sequence's previews.
    const std::string seq = dir / "seq";
    fs::create_directories(seq);
    for (int i = 1; i <= 2; ++i) fs::copy_file(in, seq + "/r000" + std::to_string(i) + ".exr");
    expectCli("denoise --method eaw --sequence " + seq + " " + (dir / "s1"), 0);
    expectCli("denoise --method eaw --exposure 0.25 --sequence " + seq + " " + (dir / "s2"), 0);
    const atrous::Image p1 = atrous::readImage(dir / "s1/r0001.png"), p2 = atrous::readImage(dir / "s2/r0001.png");
    double s1 = 0, s2 = 0;
    for (size_t i = 0; i < p1.size(); ++i) s1 += p1.data()[i], s2 += p2.data()[i];
    EXPECT_LT(s2, 0.5 * s1);
    EXPECT_TRUE(sameImages(atrous::readImage(dir / "s1/r0001.exr"), atrous::readImage(dir / "s2/r0001.exr")));
}

// The command line's habits (issue 49): `atrous denoise IN OUT` beside the flags, -i/-o, --quiet
// and -v, --threads, --method none, --exposure.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "atrous/image.h"
#include "atrous/io/image_io.h"
#include "test_util.h"

using atrous::test::expectCli;
using atrous::test::randomImage;
using atrous::test::runShell;
using atrous::test::sameImages;
using atrous::test::TempDir;
namespace fs = std::filesystem;

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

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

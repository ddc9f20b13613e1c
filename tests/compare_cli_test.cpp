// `atrous compare` on broken inputs: NaN/Inf pixels are counted as 0 in the figures but reported
// (a note line and JSON fields), so a denoiser output full of NaNs cannot pass for a good one; an
// 8-bit PNG is compared with a note that it is not HDR radiance.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "atrous/image.h"
#include "atrous/io/image_io.h"
#include "test_util.h"

using namespace atrous;
using atrous::test::CliResult;
using atrous::test::runCli;
using atrous::test::TempDir;

namespace {

Image ramp(int w, int h) {
    Image img(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) img(x, y, c) = 0.1f + 0.01f * float(x + y + c);
    return img;
}

// `atrous compare [--json] --ref REF IMG` on files in `dir`.
CliResult compare(const TempDir& dir, const std::string& ref, const std::string& img, bool json = false) {
    return runCli(std::string("compare ") + (json ? "--json " : "") + "--ref " + (dir / ref) + " " + (dir / img));
}

}  // namespace

TEST(CompareCli, ReportsNonFinitePixels) {
    TempDir dir;
    Image ref = ramp(16, 16), bad = ramp(16, 16);
    bad(2, 3, 0) = NAN;
    bad(2, 3, 2) = INFINITY;  // the same pixel: one pixel
    bad(9, 9, 1) = -INFINITY;
    atrous::writeImage(dir / "ref.exr", ref);
    atrous::writeImage(dir / "bad.exr", bad);
    CliResult text = compare(dir, "ref.exr", "bad.exr");
    ASSERT_EQ(text.exitCode, 0) << text.output;
    EXPECT_NE(text.output.find("bad.exr has 2 non-finite"), std::string::npos) << text.output;
    CliResult json = compare(dir, "ref.exr", "bad.exr", true);
    ASSERT_EQ(json.exitCode, 0) << json.output;
    EXPECT_NE(json.output.find("\"non_finite_pixels\": 2"), std::string::npos) << json.output;
    EXPECT_NE(json.output.find("\"reference_non_finite_pixels\": 0"), std::string::npos) << json.output;
    // A clean image gets no note.
    CliResult clean = compare(dir, "ref.exr", "ref.exr");
    EXPECT_EQ(clean.output.find("non-finite"), std::string::npos) << clean.output;
    // A broken reference is named.
    CliResult badRef = compare(dir, "bad.exr", "ref.exr");
    EXPECT_NE(badRef.output.find("reference " + (dir / "bad.exr") + " has 2 non-finite"), std::string::npos)
        << badRef.output;
}

TEST(CompareCli, NotesThatAPngIsNotHdr) {
    TempDir dir;
    Image ref = ramp(8, 8);
    atrous::writeImage(dir / "ref.exr", ref);
    atrous::writeImage(dir / "ref.png", ref);
    CliResult r = compare(dir, "ref.exr", "ref.png");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("ref.png is an 8-bit PNG"), std::string::npos) << r.output;
    CliResult exr = compare(dir, "ref.exr", "ref.exr");
    EXPECT_EQ(exr.output.find("8-bit"), std::string::npos) << exr.output;
}

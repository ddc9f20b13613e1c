// include/atrous/io.h: the image I/O that installed C++ users get (docs/cpp.md). The formats
// themselves are tested in io_test.cpp; this checks the public entry points keep their promises.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "atrous/error.h"
#include "atrous/io.h"
#include "test_util.h"

using namespace atrous;
using atrous::test::TempDir;

static Image ramp(int w, int h) { return test::rampImage(w, h, 0.25f, -3.0f, 1000.0f); }

TEST(PublicIo, ExrAndPfmRoundTripsAreExact) {
    // Both formats store 32-bit floats, so the values come back bit for bit (no tolerance).
    TempDir dir;
    const Image img = ramp(11, 5);
    for (const char* name : {"a.exr", "a.pfm"}) {
        writeImage(dir / name, img);
        const Image back = readImage(dir / name);
        ASSERT_EQ(back.width(), 11);
        ASSERT_EQ(back.height(), 5);
        ASSERT_EQ(back.channels(), 3);
        for (size_t i = 0; i < img.size(); ++i)
            ASSERT_EQ(back.data()[i], img.data()[i]) << name << " at " << i;
    }
}

TEST(PublicIo, ErrorsNameTheFileAndAFailedWriteLeavesNothing) {
    TempDir dir;
    try {
        readImage(dir / "missing.exr");
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("missing.exr"), std::string::npos) << e.what();
    }
    try {
        writeImage(dir / "out.tiff", ramp(4, 4));
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("out.tiff"), std::string::npos) << e.what();
    }
    EXPECT_EQ(atrous::test::countEntries(dir.str()), 0);
    // An existing file survives a write that fails (a 2-channel image: no format takes it).
    writeImage(dir / "keep.exr", ramp(4, 4));
    EXPECT_THROW(writeImage(dir / "keep.exr", Image(4, 4, 2)), InputError);
    EXPECT_EQ(readImage(dir / "keep.exr")(3, 3, 2), ramp(4, 4)(3, 3, 2));
    EXPECT_EQ(atrous::test::countEntries(dir.str()), 1);  // no temporary left behind
}

// readRenderFiles: a render folder as `atrous render` writes it, each buffer by name in the
// filters' conventions (depth 1 channel, ids 2, the rest 3), the colour equal to color.exr; a
// missing folder and a bad --pass request are InputErrors naming them.
TEST(PublicIo, RenderFilesByNameInTheFiltersConventions) {
    TempDir dir;
    auto r = test::runCli("render --scene cornell --width 24 --height 16 --spp 2 --out " + dir / "render");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const RenderFiles f = readRenderFiles(dir / "render");
    for (const char* name : {"color", "variance", "albedo", "normal", "position", "depth", "ids", "emission"})
        ASSERT_NE(f.get(name), nullptr) << name;
    EXPECT_EQ(f.get("motion"), nullptr);
    EXPECT_EQ(f.get("depth")->channels(), 1);
    EXPECT_EQ(f.get("ids")->channels(), 2);
    EXPECT_EQ(f.get("albedo")->channels(), 3);
    const Image color = readImage(dir / "render/color.exr");
    for (size_t i = 0; i < color.size(); ++i) ASSERT_EQ(f.get("color")->data()[i], color.data()[i]) << i;
    ASSERT_EQ(f.from.size(), f.buffers.size());
    try {
        readRenderFiles(dir / "nothing");
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("nothing"), std::string::npos) << e.what();
    }
    EXPECT_THROW(readRenderFiles(dir / "render", {"albedo"}), InputError);  // not BUFFER=NAME
}

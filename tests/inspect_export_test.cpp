// `atrous inspect FILE --export DIR` (apps/atrous/cmd_inspect.cpp): the buffers atrous takes from a
// layered EXR or a render directory, every convention applied, written as plain EXRs; bad input
// writes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "denoise_test_util.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "test_util.h"

using namespace atrous;
using namespace atrous::io;
using namespace atrous::test;

namespace {

Image ramp(int w, int h, int channels, float base) { return channelRamp(w, h, channels, base, 0.01f); }

int lines(const std::string& s) {
    int n = 0;
    for (char c : s) n += c == '\n';
    return n;
}

// A Blender-like multipart render whose passes need every convention: albedo above 1 (clamped),
// normals of length 2 (normalised), depth with Cycles' 1e10 background (-> 1e30), Vector (y up ->
// atrous motion, y down), object and material index (-> ids R, G).
struct Render {
    static constexpr int W = 9, H = 7;
    Image combined = ramp(W, H, 4, 0.5f), albedo = ramp(W, H, 3, 0.6f), normal = ramp(W, H, 3, 0.0f),
          depth = ramp(W, H, 1, 3.0f), object = ramp(W, H, 1, 0.0f), material = ramp(W, H, 1, 0.0f),
          vector = ramp(W, H, 4, -0.3f), emission = ramp(W, H, 3, 0.0f);
    Render() {
        albedo(2, 3, 1) = 7.5f;  // Cycles writes an emitter's radiance there
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                normal(x, y, 0) = 2.0f, normal(x, y, 1) = 0.0f, normal(x, y, 2) = 0.0f;
                object(x, y, 0) = float(1 + x % 3), material(x, y, 0) = float(4 + y % 2);
            }
        depth(0, 0, 0) = 1e10f;
    }
    void write(const std::string& path, bool withEmission) const {
        std::vector<ExrOutLayer> l = {{"ViewLayer.Combined", &combined, {"R", "G", "B", "A"}},
                                      {"ViewLayer.Denoising Albedo", &albedo},
                                      {"ViewLayer.Normal", &normal, {"X", "Y", "Z"}},
                                      {"ViewLayer.Depth", &depth, {"Z"}},
                                      {"ViewLayer.Object Index", &object, {"X"}},
                                      {"ViewLayer.Material Index", &material, {"X"}},
                                      {"ViewLayer.Vector", &vector, {"X", "Y", "Z", "W"}}};
        if (withEmission) l.push_back({"ViewLayer.Emission", &emission});
        writeLayeredExr(path, l, /*multipart=*/true);
    }
};

}  // namespace

TEST(InspectExport, LayeredFileBuffersAsAtrousReadsThem) {
    TempDir in, out;
    const Render r;
    r.write(in / "render.exr", true);
    const std::string dir = out / "buffers";
    const CliResult res = runCli("inspect " + (in / "render.exr") + " --export " + dir);
    ASSERT_EQ(res.exitCode, 0) << res.output;
    EXPECT_NE(res.output.find("export: wrote color.exr"), std::string::npos) << res.output;
    // Exactly the buffers the file has (no variance, no position): ids hold object and material.
    for (const char* f : {"color.exr", "albedo.exr", "normal.exr", "depth.exr", "ids.exr", "emission.exr", "motion.exr"})
        EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(dir) / f)) << f;
    EXPECT_EQ(countEntries(dir), 7) << "no other file (no temporary left behind)";

    // Every exported buffer equals what denoise --in takes (loadBuffers), float32 exact.
    BufferFiles bf;
    bf.in = in / "render.exr";
    const BufferSet set = loadBuffers(bf);
    const std::pair<Buffer, const char*> pairs[] = {{Buffer::Color, "color.exr"}, {Buffer::Albedo, "albedo.exr"},
                                                    {Buffer::Normal, "normal.exr"}, {Buffer::Depth, "depth.exr"},
                                                    {Buffer::ObjectId, "ids.exr"}, {Buffer::Emission, "emission.exr"}};
    // (The exports are 3-channel files; atrous holds depth in 1 plane and the ids in 2.)
    for (const auto& [b, f] : pairs)
        EXPECT_EQ(maxAbsDiff(readImage(std::filesystem::path(dir) / f, nullptr, set.get(b)->channels()), *set.get(b)), 0.0) << f;

    // And the conventions are the ones applied (not the file's raw values).
    const Image albedo = readImage(dir + "/albedo.exr"), normal = readImage(dir + "/normal.exr"),
                depth = readImage(dir + "/depth.exr"), ids = readImage(dir + "/ids.exr"),
                motion = readImage(dir + "/motion.exr"), color = readImage(dir + "/color.exr");
    EXPECT_EQ(albedo(2, 3, 1), 1.0f);                   // clamped to [0, 1]
    EXPECT_EQ(albedo(4, 1, 0), r.albedo(4, 1, 0));      // others as written
    EXPECT_EQ(normal(3, 3, 0), 1.0f);                   // length 2 -> 1
    EXPECT_EQ(depth(0, 0, 2), 1e30f);                   // 1e10 background -> 1e30, repeated into 3 channels
    EXPECT_EQ(depth(5, 2, 1), r.depth(5, 2, 0));
    EXPECT_EQ(ids(4, 3, 0), r.object(4, 3, 0));         // R object
    EXPECT_EQ(ids(4, 3, 1), r.material(4, 3, 0));       // G material
    EXPECT_EQ(motion(6, 1, 0), r.vector(6, 1, 0));      // X
    EXPECT_EQ(motion(6, 1, 1), -r.vector(6, 1, 1));     // -Y: Blender's y is up
    EXPECT_EQ(motion(6, 1, 2), 0.0f);                   // 2 components, B = 0
    EXPECT_EQ(color(8, 6, 2), r.combined(8, 6, 2));     // colour untouched, alpha dropped

    // A second export of a file without emission removes the first one's emission.exr.
    r.write(in / "noemission.exr", false);
    const CliResult again = runCli("inspect " + (in / "noemission.exr") + " --export " + dir);
    ASSERT_EQ(again.exitCode, 0) << again.output;
    EXPECT_FALSE(std::filesystem::exists(dir + "/emission.exr")) << again.output;
    EXPECT_NE(again.output.find("removed"), std::string::npos) << again.output;
    EXPECT_EQ(countEntries(dir), 6);
}

TEST(InspectExport, RenderDirectoryAsMitsubaSeparateFiles) {
    TempDir in, out;
    const Render r;
    Image color = ramp(Render::W, Render::H, 3, 0.2f);
    writeImage(in / "color.exr", color);
    writeImage(in / "albedo.exr", r.albedo);
    writeImage(in / "normal.exr", r.normal);
    Image depth1 = ramp(Render::W, Render::H, 1, 2.0f);
    depth1(1, 1, 0) = 0.0f;  // Mitsuba's background depth
    writeImage(in / "depth.exr", depth1);
    const CliResult res = runCli("inspect " + in.str() + " --export " + (out / "b"));
    ASSERT_EQ(res.exitCode, 0) << res.output;
    EXPECT_NE(res.output.find("render directory"), std::string::npos) << res.output;
    EXPECT_EQ(countEntries(out / "b"), 4);
    EXPECT_EQ(maxAbsDiff(readImage(out / "b/color.exr"), color), 0.0);
    const Image d = readImage(out / "b/depth.exr");
    EXPECT_EQ(d(1, 1, 0), 1e30f);
    EXPECT_EQ(d(2, 1, 0), depth1(2, 1, 0));
    EXPECT_EQ(readImage(out / "b/normal.exr")(0, 0, 0), 1.0f);
    EXPECT_EQ(readImage(out / "b/albedo.exr")(2, 3, 1), 1.0f);
}

TEST(InspectExport, BadInputOneLineExitTwoNothingWritten) {
    TempDir in, out;
    const Render r;
    // No colour pass.
    writeLayeredExr(in / "nocolor.exr", {{"ViewLayer.Denoising Albedo", &r.albedo}}, true);
    // Not an EXR.
    std::ofstream(in / "junk.exr") << "not an exr";
    r.write(in / "render.exr", true);
    std::ofstream(out / "afile") << "x";
    struct Case {
        std::string args, mention;
    } cases[] = {
        {"inspect " + (in / "nocolor.exr") + " --export " + (out / "d"), "no colour pass"},
        {"inspect " + (in / "junk.exr") + " --export " + (out / "d"), "junk.exr"},
        {"inspect " + (in / "missing.exr") + " --export " + (out / "d"), "missing.exr"},
        {"inspect " + (in / "render.exr") + " --pass albedo=Nope --export " + (out / "d"), "Nope"},
        {"inspect " + (in / "render.exr") + " --export " + (out / "afile") + "/sub", "afile"},
    };
    for (const Case& c : cases) {
        const CliResult res = runCli(c.args);
        EXPECT_EQ(res.exitCode, 2) << c.args << "\n" << res.output;
        EXPECT_EQ(lines(res.output), 1) << c.args << "\n" << res.output;
        EXPECT_NE(res.output.find(c.mention), std::string::npos) << c.args << "\n" << res.output;
        EXPECT_EQ(countEntries(out.str()), 1) << c.args << ": only 'afile' there";
    }
}

// Other renderers' layered files under bad input (issue 29, cases 1, 2, 7 and 8; docs/inputs.md):
// a header that claims more than its file holds fails at once on every path, with bounded memory;
// parts are placed by their data windows (or refused); a buffer named twice in --pass is refused
// on every path; one channel never stands for a direction (normal, position, motion).
//
// Each test runs the CLI (ATROUS_TEST_CLI=OLD_BUILD/atrous runs them against another build: each
// fails on the build before these fixes).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "exr_fixture.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "atrous/io/pass_map.h"

using namespace atrous;
using namespace atrous::test;
namespace fs = std::filesystem;

namespace {

float colourAt(int x, int y, int c) { return 0.25f + 0.01f * float(x) + 0.002f * float(y) + 0.1f * float(c); }
float albedoAt(int x, int y, int c) { return 0.3f + 0.02f * float(x + 20) + 0.001f * float(y + 20) + 0.05f * float(c); }

const std::vector<std::string> kRgb = {"R", "G", "B"};

// 256 x 256 of noise as floats: ~790 KB that ZIP cannot shrink (a file under 1 MB that is
// mostly real pixel data).
float noiseAt(int x, int y, int c) {
    uint32_t h = uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u ^ uint32_t(c) * 83492791u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return float(h & 0xffffff) / float(0xffffff);
}

}  // namespace

// Case 1: a ~20 KB multipart file whose first part claims 16384 x 16384 made every path allocate
// 3 GiB per buffer (6 GB peak, 6-12 s) and fail with "out of host memory" naming no file.
TEST(LayeredInput, LyingFirstPartFailsAtOnceOnEveryPath) {
    TempDir dir;
    const std::string lie = dir / "lie.exr";
    ExrPart colour = simplePart("ViewLayer.Combined", 16384, 16384, kRgb, nullptr);
    writeExrParts(lie, {colour, simplePart("ViewLayer.Denoising Albedo", 8, 6, kRgb, albedoAt)});
    ASSERT_LT(fs::file_size(lie), 64u * 1024u);
    atrous::writeImage(dir / "plain.exr", Image(8, 6, 3));
    fs::create_directories(dir / "seq");
    fs::copy_file(lie, dir / "seq/render0001.exr");
    fs::copy_file(lie, dir / "seq/render0002.exr");
    const std::vector<std::string> commands = {
        "denoise --in " + lie + " --out " + (dir / "o.exr"),
        "inspect " + lie + " --export " + (dir / "export"),
        "denoise --sequence " + (dir / "seq") + " --out " + (dir / "oseq"),
        "denoise --color " + (dir / "plain.exr") + " --albedo " + lie + " --out " + (dir / "o2.exr"),
    };
    for (const std::string& args : commands) {
        const auto t0 = std::chrono::steady_clock::now();
        const CliRun r = runCliMeasured(args);
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
        EXPECT_TRUE(oneLine(r.output)) << r.output;
        const bool seq = args.find("--sequence") != std::string::npos;
        EXPECT_NE(r.output.find(seq ? "seq/render0001.exr: " : "lie.exr: "), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("truncated or corrupt EXR (part 0 'ViewLayer.Combined': its 16384x16384"), std::string::npos)
            << r.output;
        // The bar is 300 MB for any file under 1 MB; the CLI alone is ~20-40 MB.
        EXPECT_LT(r.peakMb, 150) << args;
        EXPECT_LT(s, 5.0) << args;
    }
    EXPECT_FALSE(fs::exists(dir / "export"));
    EXPECT_FALSE(fs::exists(dir / "oseq"));
}

// Case 1, the header that passes the size bound: a 4096^2 colour part of no pixels beside 790 KB of
// real pixels fits what the file could hold at ZIP's ratio, so it is decoded row by row first
// (exr_limits.h, rule 3) and fails there, before 200 MB of planes are allocated and zeroed.
TEST(LayeredInput, LyingPartWithinTheBoundFailsOnItsRows) {
    TempDir dir;
    const std::string lie = dir / "lie.exr";
    writeExrParts(lie, {simplePart("ViewLayer.Combined", 4096, 4096, kRgb, nullptr),
                        simplePart("ViewLayer.Grain", 256, 256, {"V"}, noiseAt)});
    ASSERT_LT(fs::file_size(lie), 1u << 20);
    const CliRun r = runCliMeasured("denoise --in " + lie + " --out " + (dir / "o.exr"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(oneLine(r.output)) << r.output;
    EXPECT_NE(r.output.find("lie.exr"), std::string::npos) << r.output;
    EXPECT_LT(r.peakMb, 150) << r.output;
    EXPECT_FALSE(fs::exists(dir / "o.exr"));
}

// Case 2: a pass part whose data window starts at (5, 5) was read as if it started at (0, 0).
TEST(LayeredInput, PartsArePlacedByTheirDataWindowsOrRefused) {
    TempDir dir;
    ExrPart colour = simplePart("ViewLayer.Combined", 8, 6, kRgb, colourAt);
    {
        // The colour's size, shifted: it does not cover the image. Refused, naming the part.
        ExrPart albedo = simplePart("ViewLayer.Denoising Albedo", 8, 6, kRgb, albedoAt);
        albedo.dataWindow = box(5, 5, 12, 10);
        writeExrParts(dir / "shifted.exr", {colour, albedo});
        const auto r = runCli("inspect " + (dir / "shifted.exr") + " --export " + (dir / "e1"));
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find("Denoising Albedo"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("does not cover"), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(dir / "e1"));
    }
    {
        // Larger, around the image: placed by its window, the pixels outside dropped.
        ExrPart albedo = simplePart("ViewLayer.Denoising Albedo", 8, 6, kRgb, albedoAt);
        albedo.dataWindow = box(-2, -1, 9, 7);
        writeExrParts(dir / "wide.exr", {colour, albedo});
        const auto r = runCli("inspect " + (dir / "wide.exr") + " --export " + (dir / "e2"));
        ASSERT_EQ(r.exitCode, 0) << r.output;
        const Image a = atrous::readImage(dir / "e2/albedo.exr"), c = atrous::readImage(dir / "e2/color.exr");
        ASSERT_EQ(a.width(), 8);
        ASSERT_EQ(a.height(), 6);
        for (int y = 0; y < 6; ++y)
            for (int x = 0; x < 8; ++x)
                for (int ch = 0; ch < 3; ++ch) {
                    EXPECT_FLOAT_EQ(a(x, y, ch), albedoAt(x, y, ch)) << x << "," << y;
                    EXPECT_FLOAT_EQ(c(x, y, ch), colourAt(x, y, ch)) << x << "," << y;
                }
    }
    {
        // Overscan: the colour's data window beyond its display window. The image is the display
        // window; the plain reader (a single-part RGB file) follows the same rule.
        ExrPart over = simplePart("", 8, 6, kRgb, colourAt);
        over.dataWindow = box(-1, -2, 9, 7);
        writeExrParts(dir / "overscan.exr", {over});
        const Image img = atrous::readImage(dir / "overscan.exr");
        ASSERT_EQ(img.width(), 8);
        ASSERT_EQ(img.height(), 6);
        EXPECT_FLOAT_EQ(img(0, 0, 0), colourAt(0, 0, 0));
        EXPECT_FLOAT_EQ(img(7, 5, 2), colourAt(7, 5, 2));
    }
}

// Case 7: the same buffer twice in --pass: --in took the last, --albedo FILE the first.
TEST(LayeredInput, SameBufferTwiceInPassIsRefusedOnEveryPath) {
    TempDir dir;
    const std::string f = dir / "render.exr";
    writeExrParts(f, {simplePart("ViewLayer.Combined", 8, 6, kRgb, colourAt),
                      simplePart("ViewLayer.DiffCol", 8, 6, kRgb, albedoAt),
                      simplePart("ViewLayer.Denoising Albedo", 8, 6, kRgb, albedoAt)});
    atrous::writeImage(dir / "plain.exr", Image(8, 6, 3));
    const std::string twice = " --pass albedo=DiffCol --pass 'albedo=Denoising Albedo'";
    for (const std::string& args : {"denoise --in " + f + twice + " --out " + (dir / "a.exr"),
                                    "denoise --color " + (dir / "plain.exr") + " --albedo " + f + twice + " --out " + (dir / "b.exr"),
                                    "inspect " + f + twice}) {
        const auto r = runCli(args);
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
        EXPECT_NE(r.output.find("--pass albedo given twice"), std::string::npos) << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "a.exr"));
    EXPECT_FALSE(fs::exists(dir / "b.exr"));
}

// Case 8: a one-channel Vector pass became motion (X, -X), a one-channel Normal (x, x, x)/|.|.
TEST(LayeredInput, OneChannelNeverStandsForADirection) {
    TempDir dir;
    const ExrPart colour = simplePart("ViewLayer.Combined", 8, 6, kRgb, colourAt);
    writeExrParts(dir / "vector.exr", {colour, simplePart("ViewLayer.Vector", 8, 6, {"X"}, albedoAt)});
    writeExrParts(dir / "normal.exr", {colour, simplePart("ViewLayer.Normal", 8, 6, {"X"}, albedoAt)});
    for (const auto& [file, what] : {std::pair<std::string, std::string>{"vector.exr", "motion needs 2"},
                                     std::pair<std::string, std::string>{"normal.exr", "normal needs 3"}}) {
        const auto r = runCli("denoise --in " + (dir / file) + " --out " + (dir / "o.exr"));
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(file), std::string::npos) << r.output;
        EXPECT_NE(r.output.find(what), std::string::npos) << r.output;
    }
    // The same rule for a plain grey file given as a normal; a grey albedo stays grey.
    {
        std::ofstream pfm(dir / "grey.pfm", std::ios::binary);  // "Pf": one channel
        pfm << "Pf\n8 6\n-1.0\n";
        const std::vector<float> px(48, 0.5f);
        pfm.write(reinterpret_cast<const char*>(px.data()), std::streamsize(px.size() * sizeof(float)));
    }
    atrous::writeImage(dir / "c.exr", Image(8, 6, 3));
    auto r = runCli("denoise --color " + (dir / "c.exr") + " --normal " + (dir / "grey.pfm") + " --out " + (dir / "o.exr"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("grey.pfm has 1 channel; normal needs 3"), std::string::npos) << r.output;
    r = runCli("denoise --color " + (dir / "c.exr") + " --albedo " + (dir / "grey.pfm") + " --out " + (dir / "o.exr"));
    EXPECT_EQ(r.exitCode, 0) << r.output;
}

// The copy --add-pass writes, of a file whose image is not its first part's whole data window
// (overscan): the denoised pass lands on the image's pixels (found by tests/fuzz: the copy was
// refused, "layer 'Denoised' does not match the file's size").
TEST(LayeredInput, AddPassPlacesThePassOnTheImage) {
    TempDir dir;
    for (const bool multipart : {false, true}) {
        ExrPart colour = simplePart(multipart ? "ViewLayer.Combined" : "", 8, 6, kRgb, colourAt);
        colour.dataWindow = box(-1, -2, 9, 7);
        std::vector<ExrPart> parts = {colour};
        if (multipart) parts.push_back(simplePart("ViewLayer.Denoising Albedo", 8, 6, kRgb, albedoAt));
        const std::string in = dir / (multipart ? "multi.exr" : "single.exr");
        writeExrParts(in, parts);
        const std::string plain = dir / "plain.exr", copy = dir / "copy.exr";
        auto r = runCli("denoise --method eaw --device cpu --in " + in + " --out " + plain);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        r = runCli("denoise --method eaw --device cpu --in " + in + " --add-pass Denoised --out " + copy);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        const io::ExrInfo info = io::inspectExr(copy);
        EXPECT_EQ(info.width, 8);
        EXPECT_EQ(info.height, 6);
        const io::PassMap m = io::mapPasses(info, {io::parsePassRequest("color=Denoised")}, "");
        const Image added = io::readPass(info, m[io::Buffer::Color], io::Buffer::Color), want = atrous::readImage(plain);
        ASSERT_EQ(added.size(), want.size());
        EXPECT_TRUE(std::equal(want.data(), want.data() + want.size(), added.data())) << (multipart ? "multipart" : "single part");
    }
}

// Rule 0 of exr_limits.h: OpenEXR 3.1's header parser allocates an attribute's claimed size before
// reading it (2 GB and ~4 s from a 901-byte file, found by tests/fuzz/libfuzzer). An attribute that
// claims more bytes than the file has is refused before OpenEXR sees the file, on every reader.
TEST(LayeredInput, HeaderAttributeLargerThanTheFileIsRefusedFirst) {
    TempDir dir;
    writeExrParts(dir / "ok.exr", {simplePart("ViewLayer.Combined", 8, 6, kRgb, colourAt),
                                   simplePart("ViewLayer.Denoising Albedo", 8, 6, kRgb, albedoAt)});
    std::string bytes = fileBytes(dir / "ok.exr");
    const std::string key = std::string("channels") + '\0' + "chlist" + '\0';
    const size_t at = bytes.find(key);
    ASSERT_NE(at, std::string::npos);
    const uint32_t huge = 0x7ff00000u;  // ~2 GB
    for (int i = 0; i < 4; ++i) bytes[at + key.size() + size_t(i)] = char((huge >> (8 * i)) & 0xff);
    std::ofstream(dir / "lie.exr", std::ios::binary) << bytes;
    for (const std::string& args : {"inspect " + (dir / "lie.exr"), "denoise --in " + (dir / "lie.exr") + " --out " + (dir / "o.exr"),
                                    "compare --ref " + (dir / "lie.exr") + " " + (dir / "lie.exr")}) {
        const CliRun r = runCliMeasured(args);
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
        EXPECT_TRUE(oneLine(r.output)) << r.output;
        EXPECT_NE(r.output.find("lie.exr: truncated or corrupt EXR header (attribute 'channels'"), std::string::npos) << r.output;
        EXPECT_LT(r.peakMb, 150) << args;
    }
}

// An EXR without channels, given for one buffer: read info.layers[0] of an empty list (SIGSEGV,
// found by tests/fuzz/libfuzzer's exr_layered target).
TEST(LayeredInput, FileWithoutChannelsIsRefused) {
    TempDir dir;
    // OpenEXR will not write such a file: the libFuzzer target's reproducer (1386 bytes).
    fs::copy_file(std::string(ATROUS_SOURCE_DIR) + "/tests/data/exr_regressions/no_channels.exr", dir / "empty.exr");
    atrous::writeImage(dir / "c.exr", Image(8, 6, 3));
    for (const std::string& args : {"denoise --color " + (dir / "empty.exr") + " --out " + (dir / "o.exr"),
                                    "denoise --color " + (dir / "c.exr") + " --albedo " + (dir / "empty.exr") + " --out " + (dir / "o.exr")}) {
        const auto r = runCli(args);
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
        EXPECT_NE(r.output.find("empty.exr"), std::string::npos) << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "o.exr"));
}

// The libFuzzer targets' EXR reproducers (tests/data/exr_regressions, kept here as regression
// inputs): every command refuses each with one line naming it, within bounded memory, or reads it.
// attribute_size_2gb / attribute_after_chlist_2gb / declared_size_desync_2gb: a header attribute
// OpenEXR 3.1 would allocate ~2 GB for (behind a channel list or a fixed-size attribute whose
// declared size is not its own); huge_data_window_2gb: a 234M-pixel-wide window (OpenEXR's line
// buffers); huge_tile_size_7gb: 4 x 28835840 tiles and no data window (OpenEXR's tile buffers);
// duplicate_attributes: a second dataWindow (the classic API keeps the last, the Core the first:
// a heap overflow placing the Core's narrower chunks); no_channels: no channels (a SIGSEGV in readBufferFile); rgba_half_segv: a valid RGBA
// half file (a SIGSEGV in OpenEXR Core's 4-channel half routine).
TEST(LayeredInput, FuzzReproducersAreRefusedInOneLineOrRead) {
    TempDir dir;
    const std::string data = std::string(ATROUS_SOURCE_DIR) + "/tests/data/exr_regressions/";
    for (const char* name : {"attribute_size_2gb.exr", "attribute_after_chlist_2gb.exr", "declared_size_desync_2gb.exr",
                             "huge_data_window_2gb.exr", "huge_tile_size_7gb.exr", "duplicate_attributes.exr", "no_channels.exr",
                             "rgba_half_segv.exr"}) {
        const std::string f = data + name;
        const bool valid = std::string(name) == "rgba_half_segv.exr";
        for (const std::string& args : {"denoise --in " + f + " --out " + (dir / "o.exr"), "compare --ref " + f + " " + f,
                                        "inspect " + f + " --export " + (dir / "x")}) {
            const CliRun r = runCliMeasured(args);
            EXPECT_LT(r.peakMb, 150) << args;
            if (valid) {
                EXPECT_EQ(r.exitCode, 0) << args << "\n" << r.output;
                continue;
            }
            EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
            EXPECT_TRUE(oneLine(r.output)) << r.output;
            EXPECT_NE(r.output.find(name), std::string::npos) << r.output;
        }
        fs::remove_all(dir / "x");
        fs::remove(dir / "o.exr");
    }
}

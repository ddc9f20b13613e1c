// Layered EXR input (src/io/exr_layers, pass_map, buffer_set) and the CLI on it: Blender's
// multipart and single-part multilayer files, Mitsuba's aov file, the pass rules and their
// ambiguity errors, the conventions applied, the copy with an added pass, `atrous inspect`, and
// oidnDenoise's command line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "atrous/error.h"
#include "denoise_test_util.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "atrous/io/pass_map.h"
#include "test_util.h"

using namespace atrous;
using namespace atrous::io;
using namespace atrous::test;

namespace {

Image constant(int w, int h, int channels, float base) { return channelRamp(w, h, channels, base, 0.001f); }

// A Blender-like render: every pass Blender 5 writes for the denoiser, under one view layer.
struct BlenderLike {
    Image combined = constant(8, 6, 4, 1.0f), albedo = constant(8, 6, 3, 0.5f), dnormal = constant(8, 6, 3, 0.2f),
          normal = constant(8, 6, 3, 0.3f), depth = constant(8, 6, 1, 4.0f), object = constant(8, 6, 1, 2.0f),
          vector = constant(8, 6, 4, -1.0f), emission = constant(8, 6, 3, 0.0f);
    std::vector<ExrOutLayer> layers(const std::string& view) const {
        return {{view + ".Combined", &combined, {"R", "G", "B", "A"}},
                {view + ".Denoising Albedo", &albedo},
                {view + ".Denoising Normal", &dnormal, {"X", "Y", "Z"}},
                {view + ".Normal", &normal, {"X", "Y", "Z"}},
                {view + ".Depth", &depth, {"Z"}},
                {view + ".Object Index", &object, {"X"}},
                {view + ".Vector", &vector, {"X", "Y", "Z", "W"}},
                {view + ".Emission", &emission}};
    }
};

std::string takenFrom(const ExrInfo& info, const PassMap& m, Buffer b) {
    const PassChoice& c = m[b];
    std::string s;
    for (int ch : c.channels) s += (s.empty() ? "" : ",") + info.channels[size_t(ch)].fullName;
    return s;
}

// Each buffer of `expected` is taken from exactly the channels listed (comma-separated full names).
void expectTakenFrom(const ExrInfo& info, const PassMap& m, const std::vector<std::pair<Buffer, std::string>>& expected) {
    for (const auto& [b, channels] : expected) EXPECT_EQ(takenFrom(info, m, b), channels) << "buffer " << int(b);
}

}  // namespace

TEST(ExrLayers, BlenderMultipartAndSinglePartMapTheSamePasses) {
    TempDir dir;
    BlenderLike b;
    for (bool multipart : {true, false}) {
        const std::string path = dir / (multipart ? "multi.exr" : "single.exr");
        writeLayeredExr(path, b.layers("ViewLayer"), multipart, /*halfFloat=*/!multipart);
        const ExrInfo info = inspectExr(path);
        EXPECT_EQ(info.parts.size(), multipart ? 8u : 1u);
        const PassMap m = mapPasses(info, {}, "");
        // Normal: the world-space Normal before the camera-space Denoising Normal (SVGF compares
        // across frames).
        expectTakenFrom(info, m,
                        {{Buffer::Color, "ViewLayer.Combined.R,ViewLayer.Combined.G,ViewLayer.Combined.B"},
                         {Buffer::Albedo,
                          "ViewLayer.Denoising Albedo.R,ViewLayer.Denoising Albedo.G,ViewLayer.Denoising Albedo.B"},
                         {Buffer::Normal, "ViewLayer.Normal.X,ViewLayer.Normal.Y,ViewLayer.Normal.Z"},
                         {Buffer::Depth, "ViewLayer.Depth.Z"},
                         {Buffer::ObjectId, "ViewLayer.Object Index.X"},
                         {Buffer::Motion, "ViewLayer.Vector.X,ViewLayer.Vector.Y"},
                         {Buffer::Emission, "ViewLayer.Emission.R,ViewLayer.Emission.G,ViewLayer.Emission.B"}});
        EXPECT_FALSE(m[Buffer::Variance].found());
        EXPECT_FALSE(m[Buffer::Position].found());
        // Pixels: float exactly, half to half precision.
        const Image albedo = readPass(info, m[Buffer::Albedo], Buffer::Albedo);
        const float tol = multipart ? 0.0f : 1e-3f;
        EXPECT_NEAR(albedo(3, 2, 1), b.albedo(3, 2, 1), tol);
        const Image depth = readPass(info, m[Buffer::Depth], Buffer::Depth);
        EXPECT_NEAR(depth(5, 1, 2), b.depth(5, 1, 0), 4 * tol);  // one channel repeated into three
    }
}

TEST(ExrLayers, MitsubaAovFileAndASingleBufferFromIt) {
    TempDir dir;
    const Image rgb = constant(6, 4, 4, 0.7f), albedo = constant(6, 4, 3, 0.4f), nn = constant(6, 4, 3, 0.1f),
                dd = constant(6, 4, 1, 3.0f), pos = constant(6, 4, 3, -2.0f);
    const std::string path = dir / "mitsuba.exr";
    writeLayeredExr(path, {{"", &rgb, {"R", "G", "B", "A"}}, {"albedo", &albedo}, {"nn", &nn, {"X", "Y", "Z"}},
                           {"dd", &dd, {"T"}}, {"pos", &pos, {"X", "Y", "Z"}}},
                    false);
    const ExrInfo info = inspectExr(path);
    const PassMap m = mapPasses(info, {}, "");
    expectTakenFrom(info, m,
                    {{Buffer::Color, "R,G,B"},
                     {Buffer::Albedo, "albedo.R,albedo.G,albedo.B"},
                     {Buffer::Normal, "nn.X,nn.Y,nn.Z"},
                     {Buffer::Depth, "dd.T"},
                     {Buffer::Position, "pos.X,pos.Y,pos.Z"}});
    // `--albedo mitsuba.exr` takes the albedo AOV, not the image's R,G,B (it used to).
    const Image a = readBufferFile(path, Buffer::Albedo, {}, "");
    EXPECT_FLOAT_EQ(a(2, 1, 0), albedo(2, 1, 0));
    // A layered file without an albedo pass, given as the albedo: an error naming it and its layers.
    try {
        readBufferFile(path, Buffer::Emission, {}, "");
        FAIL() << "no emission pass: expected an InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("mitsuba.exr: has several layers"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--pass emission=LAYER"), std::string::npos) << e.what();
    }
    // --pass picks by layer name, pass name or channel name.
    const PassMap p = mapPasses(info, {parsePassRequest("normal=pos"), parsePassRequest("depth=albedo.G")}, "");
    EXPECT_EQ(takenFrom(info, p, Buffer::Normal), "pos.X,pos.Y,pos.Z");
    EXPECT_EQ(takenFrom(info, p, Buffer::Depth), "albedo.G");
    EXPECT_THROW(mapPasses(info, {parsePassRequest("albedo=nothing")}, ""), InputError);
    EXPECT_THROW(parsePassRequest("albedo"), InputError);
    EXPECT_THROW(parsePassRequest("colour=x"), InputError);
}

TEST(ExrLayers, TwoViewLayersAreAmbiguousUntilOneIsChosen) {
    TempDir dir;
    BlenderLike b;
    std::vector<ExrOutLayer> layers = b.layers("Front");
    for (const ExrOutLayer& l : b.layers("Back")) layers.push_back(l);
    const std::string path = dir / "two.exr";
    writeLayeredExr(path, layers, true);
    const ExrInfo info = inspectExr(path);
    try {
        mapPasses(info, {}, "");
        FAIL() << "expected an ambiguity error";
    } catch (const InputError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("two.exr: ambiguous color pass"), std::string::npos) << msg;
        EXPECT_NE(msg.find("part 'Front.Combined'"), std::string::npos) << msg;
        EXPECT_NE(msg.find("part 'Back.Combined'"), std::string::npos) << msg;
    }
    const PassMap m = mapPasses(info, {}, "Back");
    EXPECT_EQ(takenFrom(info, m, Buffer::Albedo), "Back.Denoising Albedo.R,Back.Denoising Albedo.G,Back.Denoising Albedo.B");
    EXPECT_THROW(mapPasses(info, {}, "Side"), InputError);
}

TEST(ExrLayers, ConventionsOfOtherRenderers) {
    Image depth(4, 1, 3), normal(4, 1, 3), pos(2, 1, 3);
    const float zs[4] = {2.5f, INFINITY, 1e10f, 0.0f};  // a hit, Inf, Cycles' 1e10, Mitsuba's 0 on a miss
    for (int x = 0; x < 4; ++x)
        for (int c = 0; c < 3; ++c) depth(x, 0, c) = zs[x];
    conformBuffer(Buffer::Depth, depth);
    EXPECT_EQ(depth(0, 0, 0), 2.5f);
    for (int x = 1; x < 4; ++x) EXPECT_EQ(depth(x, 0, 0), 1e30f) << x;
    const float ns[4][3] = {{0, 0, 2}, {0, 0.6f, 0}, {0, 0, 0}, {NAN, 0, 1}};  // unnormalised, edge mean, background, NaN
    for (int x = 0; x < 4; ++x)
        for (int c = 0; c < 3; ++c) normal(x, 0, c) = ns[x][c];
    conformBuffer(Buffer::Normal, normal);
    EXPECT_FLOAT_EQ(normal(0, 0, 2), 1.0f);
    EXPECT_FLOAT_EQ(normal(1, 0, 1), 0.6f);
    EXPECT_EQ(normal(2, 0, 2), 0.0f);
    EXPECT_EQ(normal(3, 0, 2), 0.0f);
    pos(0, 0, 0) = NAN;
    pos(1, 0, 1) = 3.0f;
    conformBuffer(Buffer::Position, pos);
    EXPECT_EQ(pos(0, 0, 0), 0.0f);
    EXPECT_EQ(pos(1, 0, 1), 3.0f);
}

TEST(ExrLayers, CopyWithAnAddedPassKeepsEveryPart) {
    TempDir dir;
    BlenderLike b;
    const Image denoised = constant(8, 6, 3, 9.0f);
    for (bool multipart : {true, false}) {
        const std::string src = dir / "src.exr", out = dir / "out.exr";
        writeLayeredExr(src, b.layers("ViewLayer"), multipart);
        const ExrInfo info = inspectExr(src);
        writeExrWithLayers(out, info, {{"Denoised", &denoised}});
        const ExrInfo copy = inspectExr(out);
        EXPECT_EQ(copy.channels.size(), info.channels.size() + 3);
        EXPECT_EQ(copy.parts.size(), info.parts.size() + (multipart ? 1 : 0));
        const PassMap m = mapPasses(copy, {parsePassRequest(multipart ? "color=ViewLayer.Denoised" : "color=Denoised")}, "");
        EXPECT_FLOAT_EQ(readPass(copy, m[Buffer::Color], Buffer::Color)(4, 3, 2), denoised(4, 3, 2));
        const PassMap orig = mapPasses(copy, {}, "");
        EXPECT_FLOAT_EQ(readPass(copy, orig[Buffer::Albedo], Buffer::Albedo)(1, 1, 1), b.albedo(1, 1, 1));
        // The name is taken: an error, and nothing replaces the file written before.
        EXPECT_THROW(writeExrWithLayers(out, copy, {{"Denoised", &denoised}}), InputError);
        std::filesystem::remove(out);
    }
}

TEST(ExrLayers, ReadImageTakesTheColourPassOfALayeredFile) {
    // `atrous compare --ref blender.exr` and every other reader of a plain image go through readImage.
    TempDir dir;
    BlenderLike b;
    writeLayeredExr(dir / "blender.exr", b.layers("ViewLayer"), true);
    const Image c = readImage(dir / "blender.exr");
    EXPECT_FLOAT_EQ(c(2, 3, 2), b.combined(2, 3, 2));
    const Image albedo = constant(4, 4, 3, 0.5f);
    writeLayeredExr(dir / "nocolor.exr", {{"albedo", &albedo}, {"nn", &albedo}}, false);
    EXPECT_THROW(readImage(dir / "nocolor.exr"), InputError);
}

TEST(ExrLayers, NotAnExrAndUnusableFiles) {
    TempDir dir;
    {
        std::ofstream f(dir / "junk.exr");
        f << "not an exr";
    }
    EXPECT_THROW(inspectExr(dir / "junk.exr"), InputError);
    EXPECT_THROW(inspectExr(dir / "missing.exr"), InputError);
    const Image alpha = constant(4, 4, 1, 1.0f);
    writeLayeredExr(dir / "alpha.exr", {{"", &alpha, {"A"}}}, false);
    const ExrInfo info = inspectExr(dir / "alpha.exr");
    EXPECT_FALSE(mapPasses(info, {}, "")[Buffer::Color].found());
}

// ---------------------------------------------------------------------------------------- CLI

namespace {

int lines(const std::string& s) {
    int n = 0;
    for (char c : s) n += c == '\n';
    return n;
}

void expectCleanFailure(const std::string& args, const std::string& mention, const TempDir& outDir) {
    const CliResult r = runCli(args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find(mention), std::string::npos) << "expected '" << mention << "' in: " << r.output;
    EXPECT_EQ(countEntries(outDir.str()), 0) << args;
}

// A synthetic noisy scene as a Blender multipart render.
void writeBlenderRender(const SyntheticScene& s, const std::string& path) {
    Image depth1 = s.depth.clone();
    writeLayeredExr(path, {{"ViewLayer.Combined", &s.noisy}, {"ViewLayer.Denoising Albedo", &s.albedo},
                           {"ViewLayer.Normal", &s.normal, {"X", "Y", "Z"}}, {"ViewLayer.Position", &s.position, {"X", "Y", "Z"}},
                           {"ViewLayer.Depth", &depth1, {"Z"}}},
                    true, true);
}

}  // namespace

TEST(LayeredCli, DenoiseABlenderRenderAndAddThePass) {
    TempDir in, out;
    const SyntheticScene s = makeScene(40, 40, 0.3f, 31);
    writeBlenderRender(s, in / "render.exr");
    CliResult r = runCli("denoise --in " + (in / "render.exr") + " --method eaw --out " + (out / "d.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("buffers used: color,albedo,normal,position"), std::string::npos) << r.output;
    const Image d = readImage(out / "d.exr");
    EXPECT_LT(mse(d, s.truth), mse(s.noisy, s.truth) / 4);
    // The copy with the pass added holds the same pixels as the plain output.
    r = runCli("denoise --in " + (in / "render.exr") + " --method eaw --add-pass Denoised --out " + (out / "copy.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const ExrInfo copy = inspectExr(out / "copy.exr");
    EXPECT_EQ(copy.parts.size(), 6u);
    const PassMap m = mapPasses(copy, {parsePassRequest("color=ViewLayer.Denoised")}, "");
    const Image added = readPass(copy, m[Buffer::Color], Buffer::Color);
    EXPECT_EQ(mse(added, d), 0.0);
    // inspect lists the parts and what denoise takes.
    r = runCli("inspect " + (in / "render.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("part 1: 'ViewLayer.Denoising Albedo'"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("albedo       ViewLayer.Denoising Albedo.R"), std::string::npos) << r.output;
}

TEST(LayeredCli, BadLayeredInput) {
    TempDir in, out;
    const SyntheticScene s = makeScene(16, 16, 0.3f, 32);
    const std::string o = " --out " + (out / "d.exr");
    // No colour pass.
    writeLayeredExr(in / "nocolor.exr", {{"ViewLayer.Denoising Albedo", &s.albedo}, {"ViewLayer.Normal", &s.normal}}, true);
    expectCleanFailure("denoise --in " + (in / "nocolor.exr") + o, "nocolor.exr: no colour pass", out);
    // Two view layers.
    writeLayeredExr(in / "two.exr", {{"A.Combined", &s.noisy}, {"B.Combined", &s.noisy}}, true);
    expectCleanFailure("denoise --in " + (in / "two.exr") + o, "ambiguous color pass", out);
    // A pass of the wrong size (a part smaller than the first).
    const SyntheticScene small = makeScene(8, 16, 0.3f, 33);
    writeLayeredExr(in / "size.exr", {{"ViewLayer.Combined", &s.noisy}}, true);
    writeLayeredExr(in / "albedo_small.exr", {{"ViewLayer.Denoising Albedo", &small.albedo}, {"x", &small.albedo}}, true);
    expectCleanFailure("denoise --in " + (in / "size.exr") + " --albedo " + (in / "albedo_small.exr") + o,
                       "albedo_small.exr", out);
    // --pass naming nothing, a bad --pass, an unknown buffer.
    writeBlenderRender(s, in / "render.exr");
    expectCleanFailure("denoise --in " + (in / "render.exr") + " --pass albedo=Nope" + o, "names no layer or channel", out);
    expectCleanFailure("denoise --in " + (in / "render.exr") + " --pass albedo" + o, "--pass", out);
    expectCleanFailure("denoise --in " + (in / "render.exr") + " --pass shadow=x" + o, "unknown buffer 'shadow'", out);
    // inspect on a file that is not an EXR; --add-pass without a layered input.
    io::writePfm(in / "c.pfm", s.noisy);
    expectCleanFailure("inspect " + (in / "c.pfm"), "c.pfm: not an OpenEXR file", out);
    expectCleanFailure("denoise --color " + (in / "c.pfm") + " --add-pass D" + o, "--add-pass", out);
}

TEST(LayeredCli, OidnDenoiseCommandLine) {
    TempDir in, out;
    const SyntheticScene s = makeScene(32, 32, 0.3f, 34);
    writePfm(in / "color.pfm", s.noisy);
    writePfm(in / "albedo.pfm", s.albedo);
    writePfm(in / "normal.pfm", s.normal);
    // As a script written for oidnDenoise calls it.
    CliResult r = runCli("denoise -f RT --hdr " + (in / "color.pfm") + " --alb " + (in / "albedo.pfm") + " --nrm " +
                         (in / "normal.pfm") + " -q high --clean_aux -d default -o " + (out / "oidn.pfm"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    r = runCli("denoise --color " + (in / "color.pfm") + " --albedo " + (in / "albedo.pfm") + " --normal " +
               (in / "normal.pfm") + " --out " + (out / "atrous.pfm"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(mse(readImage(out / "oidn.pfm"), readImage(out / "atrous.pfm")), 0.0);
    // --ldr clamps to [0, 1]; --srgb decodes and encodes.
    r = runCli("denoise --ldr " + (in / "color.pfm") + " --srgb -o " + (out / "ldr.pfm"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const Image ldr = readImage(out / "ldr.pfm");
    float lo = 1, hi = 0;
    for (size_t i = 0; i < 3 * ldr.plane(); ++i) lo = std::min(lo, ldr.data()[i]), hi = std::max(hi, ldr.data()[i]);
    EXPECT_GE(lo, 0.0f);
    EXPECT_LE(hi, 1.0f);
    TempDir none;
    expectCleanFailure("denoise -f RTLightmap --hdr " + (in / "color.pfm") + " -o " + (none / "x.pfm"), "RTLightmap", none);
}

// ------------------------------------------------------------------------- layered sequences

namespace {

// Three Blender-like frames of a camera pan: content moves 1 px left per frame (motion = previous
// - current = +1 in x), depth in 3-px stripes that move with it, Vector X = +1 (times `vectorSign`),
// object ids constant (or renumbered every frame).
void writePanSequence(const std::string& dir, float vectorSign, bool renumberIds) {
    const int w = 48, h = 32;
    for (int t = 0; t < 3; ++t) {
        Image color(w, h, 3), depth(w, h, 1), normal(w, h, 3), vec(w, h, 4), ids(w, h, 1);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const int u = x + t;
                for (int c = 0; c < 3; ++c) color(x, y, c) = 0.3f + 0.2f * float((u / 5) % 2) + 0.01f * float((x * 7 + y * 3 + t) % 5);
                depth(x, y, 0) = (u / 3) % 2 ? 2.0f : 4.0f;
                normal(x, y, 0) = normal(x, y, 1) = 0.0f, normal(x, y, 2) = 1.0f;
                vec(x, y, 0) = vectorSign, vec(x, y, 1) = vec(x, y, 2) = vec(x, y, 3) = 0.0f;
                ids(x, y, 0) = renumberIds ? float(t + 1) : 1.0f;
            }
        char name[32];
        std::snprintf(name, sizeof(name), "/render%04d.exr", t + 1);
        writeLayeredExr(dir + name, {{"ViewLayer.Combined", &color}, {"ViewLayer.Depth", &depth, {"Z"}},
                                     {"ViewLayer.Normal", &normal, {"X", "Y", "Z"}},
                                     {"ViewLayer.Vector", &vec, {"X", "Y", "Z", "W"}},
                                     {"ViewLayer.Object Index", &ids, {"X"}}},
                        true);
    }
}

}  // namespace

TEST(LayeredCli, SequenceOfLayeredFilesWithSignAndIdChecks) {
    TempDir a, b, c, out;
    writePanSequence(a.str(), 1.0f, false);
    CliResult r = runCli("denoise --method svgf --sequence " + a.str() + " --out " + (out / "a"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("render0002: svgf"), std::string::npos) << r.output;
    // 47 of 48 columns: the last one moves out of the image.
    EXPECT_NE(r.output.find("98% reprojects onto the previous frame"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("opposite sign"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("ids change"), std::string::npos) << r.output;
    EXPECT_TRUE(std::filesystem::exists(out / "a/render0003.exr"));
    // The other sign convention: named in a warning.
    writePanSequence(b.str(), -1.0f, false);
    r = runCli("denoise --method svgf --sequence " + b.str() + " --out " + (out / "b"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("motion vectors look like the opposite sign convention"), std::string::npos) << r.output;
    // Ids renumbered every frame: detected and dropped.
    writePanSequence(c.str(), 1.0f, true);
    r = runCli("denoise --method eaw --sequence " + c.str() + " --out " + (out / "c"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("the ids change between frames"), std::string::npos) << r.output;
}

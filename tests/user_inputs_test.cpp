// What a user of another renderer hands `atrous denoise` (issue 49): an RGBA file's alpha passed
// through unchanged (EXR, a layered EXR, a render folder, PNG), an 8-bit LDR colour denoised as LDR,
// Mitsuba's moment integrator's m2_ layers, --layer narrowing --pass, an all-NaN colour and a
// misspelt flag: each a one-line error with exit 2 where it is bad input, nothing written.
#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/io/alpha.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "atrous/io/pass_map.h"
#include "atrous/param_set.h"
#include "atrous/params.h"
#include "atrous/srgb.h"
#include "denoise_test_util.h"
#include "test_util.h"

using namespace atrous;
using namespace atrous::io;
using namespace atrous::test;

namespace {

// An alpha with values a float32 conversion could disturb if it went through any arithmetic:
// 1/3-like fractions, 0, 1, and half-float ones (they are stored as half in the test files).
Image oddAlpha(int w, int h) {
    Image a(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) a(x, y, 0) = float(half(float((x * 7 + y * 13) % 23) / 22.0f));
    return a;
}

// The noisy colour of a small synthetic scene with `a` as its 4th channel.
Image rgba(const SyntheticScene& s, const Image& a) { return withAlpha(s.noisy.clone(), a); }

// A file's alpha exactly as stored (io::readAlpha reads it; half values convert exactly to float).
bool sameAlpha(const std::string& file, const Image& a) {
    const Image b = readAlpha(file);
    return !b.empty() && sameImages(a, b);
}

// An RGB EXR whose A is stored at half resolution (xSampling = ySampling = 2): "another size".
void writeSubsampledAlpha(const std::string& path, const Image& rgb) {
    const int w = rgb.width(), h = rgb.height();
    Imf::Header header(w, h);
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    header.channels().insert("A", Imf::Channel(Imf::FLOAT, 2, 2));
    std::vector<float> inter(size_t(w) * h * 3), a(size_t(w / 2) * (h / 2), 0.5f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) inter[(size_t(y) * w + x) * 3 + c] = rgb(x, y, c);
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(inter.data() + c), 12, size_t(w) * 12));
    fb.insert("A", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(a.data()), 4, size_t(w / 2) * 4, 2, 2));
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(h);
}

// Mitsuba 3's moment integrator around an aov integrator ("aovs": albedo, nn) and a path tracer
// ("path"): the film's R,G,B,A, the nested outputs, "path.X/Y/Z", and "m2_" + each of them.
std::string writeMomentFile(const TempDir& dir, const SyntheticScene& s) {
    const std::string path = dir / "moment.exr";
    writeLayeredExr(path,
                    {{"", &s.noisy, {"R", "G", "B"}},
                     {"aovs.albedo", &s.albedo},
                     {"aovs.nn", &s.normal, {"X", "Y", "Z"}},
                     {"path", &s.noisy, {"X", "Y", "Z"}},
                     {"m2_aovs.albedo", &s.albedo},
                     {"m2_aovs.nn", &s.normal, {"X", "Y", "Z"}},
                     {"m2_path", &s.noisy, {"X", "Y", "Z"}}},
                    false);
    return path;
}

}  // namespace

TEST(MomentLayers, InspectAndDenoiseTakeTheFirstMomentsNotTheSecond) {
    TempDir dir;
    const SyntheticScene s = makeScene(24, 16, 0.2f, 3);
    const std::string file = writeMomentFile(dir, s);
    // Both "aovs.albedo" and "m2_aovs.albedo" are named albedo: the m2_ one is never a buffer.
    const ExrInfo info = inspectExr(file);
    const PassMap m = mapPasses(info, {}, "");
    ASSERT_TRUE(m[Buffer::Albedo].found());
    EXPECT_EQ(info.layers[size_t(m[Buffer::Albedo].layer)].name, "aovs.albedo");
    EXPECT_EQ(info.layers[size_t(m[Buffer::Normal].layer)].name, "aovs.nn");
    expectCli("inspect " + file, 0, {"aovs.albedo.R,aovs.albedo.G,aovs.albedo.B", "not taken: m2_aovs.albedo, m2_aovs.nn, m2_path"});
    expectCli("denoise --in " + file + " --out " + dir / "out.exr", 0, {"buffers used: color"});
    // A --pass by pass name is ambiguous between the two, until --layer narrows it to one view layer.
    expectCli("denoise --in " + file + " --pass albedo=albedo --out " + dir / "a.exr", 2,
              {"ambiguous", "'aovs.albedo' and 'm2_aovs.albedo'", "--layer"});
    const PassMap narrowed = mapPasses(info, {parsePassRequest("albedo=albedo")}, "aovs");
    EXPECT_EQ(info.layers[size_t(narrowed[Buffer::Albedo].layer)].name, "aovs.albedo");
    expectCli("denoise --in " + file + " --layer aovs --pass albedo=albedo --out " + dir / "b.exr", 0);
    // A --pass may still name a second moment's layer in full.
    const PassMap full = mapPasses(info, {parsePassRequest("albedo=m2_aovs.albedo")}, "");
    EXPECT_EQ(info.layers[size_t(full[Buffer::Albedo].layer)].name, "m2_aovs.albedo");
}

TEST(Alpha, AnRgbaExrKeepsItsAlphaBitForBit) {
    TempDir dir;
    const SyntheticScene s = makeScene(24, 16, 0.2f, 5);
    const Image a = oddAlpha(24, 16);
    // A plain RGBA file (A stored as half), a Blender multilayer file, a render folder.
    writeLayeredExr(dir / "rgba.exr", {{"", &s.noisy, {"R", "G", "B"}}, {"", &a, {"A"}}}, false, true);
    const Image c4 = rgba(s, a);
    writeLayeredExr(dir / "blender.exr",
                    {{"ViewLayer.Combined", &c4, {"R", "G", "B", "A"}}, {"ViewLayer.Denoising Albedo", &s.albedo},
                     {"ViewLayer.Denoising Normal", &s.normal, {"X", "Y", "Z"}}},
                    true);
    std::filesystem::create_directories(dir / "render");
    writeImage(dir / "render/color.exr", c4);
    writeImage(dir / "render/albedo.exr", s.albedo);
    ASSERT_TRUE(sameAlpha(dir / "rgba.exr", a));
    for (const auto& [in, name] : std::vector<std::pair<std::string, std::string>>{
             {"--color " + dir / "rgba.exr", "plain"}, {"--in " + dir / "blender.exr", "layered"},
             {"--in " + dir / "render", "folder"}}) {
        const std::string out = dir / (name + "_out.exr");
        expectCli("denoise " + in + " --out " + out, 0, {"alpha of ", "passed through unchanged"});
        EXPECT_TRUE(sameAlpha(out, a)) << name;
        // The colour is the denoised one, not the input's.
        EXPECT_FALSE(sameImages(readImage(out), s.noisy.clone())) << name;
    }
    // --add-pass: the copy keeps the file's own alpha, and the added pass carries it too.
    expectCli("denoise --in " + dir / "blender.exr" + " --add-pass Denoised --out " + dir / "copy.exr", 0);
    const ExrInfo copy = inspectExr(dir / "copy.exr");
    bool found = false;
    for (const ExrLayer& l : copy.layers)
        if (l.passName() == "Denoised") found = std::find(l.components.begin(), l.components.end(), "A") != l.components.end();
    EXPECT_TRUE(found) << layerList(copy);
    // PFM has no alpha: written without it, and the output line says so.
    expectCli("denoise --color " + dir / "rgba.exr" + " --out " + dir / "out.pfm", 0, {"PFM has none: the alpha is not written"});
}

TEST(Alpha, APngKeepsItsAlphaCodes) {
    TempDir dir;
    const SyntheticScene s = makeScene(24, 16, 0.1f, 6);
    Image a(24, 16, 1);
    for (int i = 0; i < 24 * 16; ++i) a.data()[i] = float(i % 256) / 255.0f;
    Image clamped = s.noisy.clone();
    for (size_t i = 0; i < clamped.size(); ++i) clamped.data()[i] = std::min(std::max(clamped.data()[i], 0.0f), 1.0f);
    writeImage(dir / "in.png", withAlpha(std::move(clamped), a));
    ASSERT_TRUE(sameAlpha(dir / "in.png", a));
    expectCli("denoise --color " + dir / "in.png" + " --out " + dir / "out.png", 0, {"passed through unchanged"});
    EXPECT_TRUE(sameAlpha(dir / "out.png", a));
    expectCli("denoise --color " + dir / "in.png" + " --out " + dir / "out.exr", 0);
    EXPECT_TRUE(sameAlpha(dir / "out.exr", a));
}

TEST(Alpha, AnAlphaOfAnotherSizeIsOneLineAndNothingIsWritten) {
    TempDir dir;
    const SyntheticScene s = makeScene(16, 12, 0.2f, 7);
    writeSubsampledAlpha(dir / "sub.exr", s.noisy);
    const CliResult r = expectCli("denoise --color " + dir / "sub.exr" + " --out " + dir / "out.exr", 2,
                                  {"sub.exr: alpha channel 'A' is 8x6 (subsampled 2x2) but the colour is 16x12"});
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_EQ(countEntries(dir.str()), 1);  // sub.exr only
    EXPECT_THROW(readAlpha(dir / "sub.exr"), InputError);
    EXPECT_THROW(withAlpha(s.noisy.clone(), Image(8, 6, 1)), InputError);
}

TEST(LdrInput, APngIsDenoisedAsLdrAndItsCodesComeBack) {
    TempDir dir;
    // A flat image stays flat through any denoiser: PNG code in, the same code out. Before, the
    // reader's x^2.2 and the writer's sRGB curve disagreed: code 13 came back as 5, 128 as 129.
    for (int code : {13, 128, 240}) {
        Image flat(16, 12, 3);
        for (size_t i = 0; i < flat.size(); ++i) flat.data()[i] = srgbDecode(float(code) / 255.0f);
        const std::string in = dir / ("flat" + std::to_string(code) + ".png"), out = dir / ("out" + std::to_string(code) + ".png");
        writeImage(in, flat);
        EXPECT_FLOAT_EQ(readImage(in)(3, 4, 1), srgbDecode(float(code) / 255.0f)) << code;
        expectCli("denoise --color " + in + " --method eaw --out " + out, 0,
                  {"LDR input: " + in + " is an 8-bit, display-encoded image: denoised as LDR", "written sRGB-encoded"});
        const Image back = readImage(out);
        for (size_t i = 0; i < back.size(); ++i) ASSERT_EQ(std::lround(srgbEncode(back.data()[i]) * 255.0f), code) << i;
    }
    // The output of LDR input is clamped to [0, 1]; an EXR output says it is linear.
    const SyntheticScene s = makeScene(24, 16, 0.3f, 8);
    writeImage(dir / "noisy.png", s.noisy);
    expectCli("denoise --color " + dir / "noisy.png" + " --out " + dir / "ldr.exr", 0, {"written linear"});
    const Image o = readImage(dir / "ldr.exr");
    EXPECT_LE(*std::max_element(o.data(), o.data() + o.size()), 1.0f);
    EXPECT_GE(*std::min_element(o.data(), o.data() + o.size()), 0.0f);
    // An EXR colour is HDR: no LDR line.
    writeImage(dir / "noisy.exr", s.noisy);
    const CliResult hdr = expectCli("denoise --color " + dir / "noisy.exr" + " --out " + dir / "hdr.exr", 0);
    EXPECT_EQ(hdr.output.find("LDR"), std::string::npos) << hdr.output;
}

TEST(LdrInput, AnLdrColourWithAVarianceIsRefused) {
    TempDir dir;
    const SyntheticScene s = makeScene(16, 12, 0.3f, 9);
    writeImage(dir / "noisy.png", s.noisy);
    writeImage(dir / "variance.exr", s.variance);
    const CliResult r = expectCli("denoise --color " + dir / "noisy.png" + " --variance " + dir / "variance.exr" + " --out " +
                                      dir / "out.png",
                                  2, {"noisy.png: an LDR colour", "with a variance buffer", "variance.exr"});
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
    // oidnDenoise's --ldr is LDR too.
    writeImage(dir / "noisy.pfm", s.noisy);
    expectCli("denoise --ldr " + dir / "noisy.pfm" + " --variance " + dir / "variance.exr" + " --out " + dir / "o.pfm", 2,
              {"(--ldr) with a variance buffer"});
}

TEST(NonFiniteColour, AColourWithNoFinitePixelIsOneLine) {
    TempDir dir;
    Image nan(12, 8, 3);
    for (size_t i = 0; i < nan.size(); ++i) nan.data()[i] = i % 2 ? std::numeric_limits<float>::quiet_NaN() : INFINITY;
    writeImage(dir / "nan.exr", nan);
    expectCli("denoise --color " + dir / "nan.exr" + " --out " + dir / "out.exr", 2,
              {"nan.exr: color buffer has no finite pixel"});
    EXPECT_FALSE(std::filesystem::exists(dir / "out.exr"));
    // One finite pixel is enough to denoise (the rest is treated as missing, as before).
    nan(3, 2, 0) = nan(3, 2, 1) = nan(3, 2, 2) = 0.5f;
    writeImage(dir / "one.exr", nan);
    expectCli("denoise --color " + dir / "one.exr" + " --out " + dir / "out.exr", 0, {"had NaN/Inf colour"});
    Image allNan(2, 2, 3);
    for (size_t k = 0; k < allNan.size(); ++k) allNan.data()[k] = NAN;
    EXPECT_THROW(requireFinitePixel(allNan, "x"), InputError);
    EXPECT_NO_THROW(requireFinitePixel(Image(2, 2, 3), "x"));
}

TEST(DidYouMean, UnknownNamesGetTheNearestOne) {
    const std::vector<std::string> names = paramKeywords(ParamSet(denoiseParams()));
    EXPECT_EQ(closestName("levles", names), "levels");
    EXPECT_EQ(closestName("sigma_norml", names), "sigma_normal");
    EXPECT_EQ(closestName("Sigma-Normal", names), "sigma_normal");
    EXPECT_EQ(closestName("nofirefly", names), "no_firefly");
    EXPECT_EQ(closestName("xyz", names), "");        // nothing near
    EXPECT_EQ(closestName("radiance", names), "");   // a word, not a slip
    EXPECT_EQ(didYouMean("levles", names), " (did you mean 'levels'?)");
    // The CLI: an unknown flag gets the command's nearest flag, on the one error line.
    expectCli("denoise --color x.exr --out y.exr --sigma-norml 2", 2, {"did you mean --sigma-normal?"});
    expectCli("compare --sequence a --no-refrence", 2, {"did you mean --no-reference?"});
    // A choice's value likewise (setParamFromText).
    expectCli("denoise --color x.exr --out y.exr --sure-mode jamesstein", 2, {"did you mean 'james-stein'?"});
    const CliResult far = expectCli("denoise --color x.exr --out y.exr --frobnicate", 2);
    EXPECT_EQ(far.output.find("did you mean"), std::string::npos) << far.output;
}

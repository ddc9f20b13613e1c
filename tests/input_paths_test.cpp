// Other renderers' files under bad input (issue 29, cases 3, 4, 5, 6, 9 and 10; docs/inputs.md):
// outputs never overwrite inputs; a buffer is in every frame of a layered sequence or in none;
// a sequence's errors name the frame's file; flags that cannot apply are refused; a directory as
// the weight file is one clear line; --layer, --pass and --add-pass apply to every frame.
//
// Each test runs the CLI (ATROUS_TEST_CLI=OLD_BUILD/atrous runs them against another build: each
// fails on the build before these fixes).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "exr_fixture.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "atrous/io/pass_map.h"

using namespace atrous;
using namespace atrous::test;
namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kRgb = {"R", "G", "B"};

std::function<float(int, int, int)> ramp(float base) {
    return [base](int x, int y, int c) { return base + 0.01f * float(x) + 0.003f * float(y) + 0.05f * float(c); };
}

// A layered frame as Blender writes it (one part per pass under view layer `vl`), w x h.
void blenderFrame(const std::string& path, float base, bool albedo = true, const std::string& vl = "ViewLayer",
                  std::vector<ExrPart> extra = {}) {
    std::vector<ExrPart> parts = {simplePart(vl + ".Combined", 12, 8, kRgb, ramp(base))};
    if (albedo) parts.push_back(simplePart(vl + ".Denoising Albedo", 12, 8, kRgb, ramp(0.4f)));
    parts.push_back(simplePart(vl + ".Denoising Normal", 12, 8, {"X", "Y", "Z"}, [](int, int, int c) { return c == 2 ? 1.0f : 0.0f; }));
    for (auto& p : extra) parts.push_back(std::move(p));
    writeExrParts(path, parts);
}

// The bytes of every file under `dir`, by path.
std::vector<std::pair<std::string, std::string>> snapshot(const std::string& dir) {
    std::vector<std::pair<std::string, std::string>> files;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) files.emplace_back(e.path().string(), fileBytes(e.path().string()));
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace

// Case 3: `denoise --sequence S --out S` over layered frames frame_0000.exr ... wrote the results
// over the input frames. Every output that would be an input (or lie in an input directory) is
// refused before anything runs, on every command.
TEST(InputPaths, OutputsNeverOverwriteInputs) {
    TempDir dir;
    const std::string seq = dir / "seq";
    fs::create_directories(seq);
    for (int f = 0; f < 3; ++f) blenderFrame(seq + "/frame_000" + std::to_string(f) + ".exr", 0.2f + 0.1f * f);
    const std::string rd = dir / "render";
    fs::create_directories(rd);
    atrous::writeImage(rd + "/color.exr", Image(12, 8, 3));
    const auto before = snapshot(dir.str());
    const std::vector<std::string> commands = {
        "denoise --method eaw --sequence " + seq + " --out " + seq,
        "denoise --method eaw --sequence " + seq + " --out " + seq + "/",
        "denoise --method eaw --sequence " + seq + " --out " + seq + "/denoised",
        "denoise --color " + seq + "/frame_0000.exr --out " + seq + "/frame_0000.exr",
        "denoise --in " + seq + "/frame_0001.exr --add-pass Denoised --out " + seq + "/frame_0001.exr",
        "denoise --in " + rd + " --out " + rd + "/color.exr",
        "denoise --in " + rd + " --out " + rd + "/albedo.exr",  // would be read as the albedo next time
        "inspect " + rd + " --export " + rd,
        "inspect " + seq + "/frame_0002.exr --export " + seq,  // allowed: see below
    };
    for (size_t i = 0; i + 1 < commands.size(); ++i) {
        const auto r = runCli(commands[i]);
        EXPECT_EQ(r.exitCode, 2) << commands[i] << "\n" << r.output;
        EXPECT_NE(r.output.find("outputs never overwrite inputs"), std::string::npos) << r.output;
    }
    EXPECT_EQ(snapshot(dir.str()), before) << "an input changed";
    // Writing beside the inputs under new names is fine: an export of a layered frame into the
    // sequence directory writes color.exr, albedo.exr, ... there, none of them a frame.
    const auto r = runCli(commands.back());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    const auto after = snapshot(seq);
    for (const auto& [path, bytes] : before)
        if (path.rfind(seq, 0) == 0) EXPECT_NE(std::find(after.begin(), after.end(), std::make_pair(path, bytes)), after.end()) << path;
}

// Case 4: an albedo part in two of three layered frames (or a motion companion in two of three)
// was accepted, though a buffer must be in every frame or in none.
TEST(InputPaths, LayeredSequenceBufferInSomeFramesIsRefused) {
    TempDir dir;
    const std::string seq = dir / "seq", seq2 = dir / "seq2";
    fs::create_directories(seq);
    fs::create_directories(seq2);
    for (int f = 1; f <= 3; ++f) {
        blenderFrame(seq + "/render000" + std::to_string(f) + ".exr", 0.3f, f != 3);
        blenderFrame(seq2 + "/render000" + std::to_string(f) + ".exr", 0.3f);
        if (f != 2) atrous::writeImage(seq2 + "/render000" + std::to_string(f) + "_motion.exr", Image(12, 8, 3));
    }
    auto r = runCli("denoise --method eaw --sequence " + seq + " --out " + (dir / "o1"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("render0003.exr: has no albedo"), std::string::npos) << r.output;
    r = runCli("denoise --method eaw --sequence " + seq2 + " --out " + (dir / "o2"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("render0002.exr: has no motion"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "o1"));
    EXPECT_FALSE(fs::exists(dir / "o2"));
}

// Case 5: a colour of 1e20 in one frame: the message named no file or frame.
TEST(InputPaths, SequenceErrorsNameTheFrame) {
    TempDir dir;
    const std::string layered = dir / "layered", folders = dir / "folders";
    fs::create_directories(layered);
    for (int f = 0; f < 3; ++f) {
        auto colour = f == 1 ? std::function<float(int, int, int)>([](int x, int y, int) { return x == 0 && y == 0 ? 1e20f : 0.5f; })
                             : ramp(0.3f);
        const std::string name = "frame_000" + std::to_string(f);
        writeExrParts(layered + "/" + name + ".exr", {simplePart("ViewLayer.Combined", 12, 8, kRgb, colour)});
        fs::create_directories(folders + "/" + name);
        Image img(12, 8, 3);
        img.fill(0.5f);
        if (f == 1) img(0, 0, 0) = 1e20f;
        atrous::writeImage(folders + "/" + name + "/color.exr", img);
    }
    for (const char* method : {"eaw", "sure", "svgf"}) {
        auto r = runCli(std::string("denoise --method ") + method + " --sequence " + layered + " --out " + (dir / "o"));
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find("frame_0001.exr"), std::string::npos) << method << ": " << r.output;
        r = runCli(std::string("denoise --method ") + method + " --sequence " + folders + " --out " + (dir / "o"));
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find("frame_0001/color.exr"), std::string::npos) << method << ": " << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "o"));
}

// Case 6: flags that cannot apply were ignored without a word.
TEST(InputPaths, FlagsThatCannotApplyAreRefused) {
    TempDir dir;
    const std::string rd = dir / "render", f = dir / "render.exr";
    fs::create_directories(rd);
    atrous::writeImage(rd + "/color.exr", Image(12, 8, 3));
    atrous::writeImage(rd + "/albedo.exr", Image(12, 8, 3));
    atrous::writeImage(dir / "c.pfm", Image(12, 8, 3));
    blenderFrame(f, 0.3f);
    fs::create_directories(dir / "seq/frame_0000");
    atrous::writeImage(dir / "seq/frame_0000/color.exr", Image(12, 8, 3));
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"denoise --in " + rd + " --pass color=Nope --out " + (dir / "o.exr"), "--pass color=Nope"},
        {"denoise --in " + rd + " --pass albedo=Nope --out " + (dir / "o.exr"), "--pass albedo=Nope"},
        {"denoise --color " + (dir / "c.pfm") + " --layer Nope --out " + (dir / "o.exr"), "--layer"},
        {"denoise --color " + (dir / "c.pfm") + " --albedo " + f + " --layer Nope --out " + (dir / "o.exr"), "--layer 'Nope'"},
        {"inspect " + rd + " --pass albedo=X", "--pass albedo=X"},
        {"inspect " + rd + " --layer X", "--layer"},
        {"inspect " + f + " --layer ''", "--layer"},
        {"inspect " + f + " --export ''", "--export"},
        {"denoise --method eaw --sequence " + (dir / "seq") + " --pass color=X --out " + (dir / "os"), "--pass"},
        {"denoise --method eaw --sequence " + (dir / "seq") + " --layer X --out " + (dir / "os"), "--layer"},
        {"denoise --method eaw --sequence " + (dir / "seq") + " --add-pass D --out " + (dir / "os"), "--add-pass"},
    };
    for (const auto& [args, flag] : cases) {
        const auto r = runCli(args);
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
        EXPECT_TRUE(oneLine(r.output)) << r.output;
        EXPECT_NE(r.output.find(flag), std::string::npos) << args << "\n" << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "o.exr"));
    EXPECT_FALSE(fs::exists(dir / "os"));
}

// Case 9: a directory as --learned-weights gave "basic_filebuf::underflow error reading the file".
TEST(InputPaths, DirectoryAsWeightFileIsOneClearLine) {
    TempDir dir;
    atrous::writeImage(dir / "c.exr", Image(12, 8, 3));
    fs::create_directories(dir / "weights");
    const auto r = runCli("denoise --method learned --learned-weights " + (dir / "weights") + " --color " + (dir / "c.exr") +
                          " --out " + (dir / "o.exr"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(oneLine(r.output)) << r.output;
    EXPECT_NE(r.output.find("weights: is a directory"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "o.exr"));
}

// Case 10: --layer, --pass and --add-pass were not even parsed with --sequence, so a Blender
// sequence with two view layers could not be denoised at all.
TEST(InputPaths, SequenceAppliesLayerPassAndAddPassToEveryFrame) {
    TempDir dir;
    const std::string seq = dir / "seq";
    fs::create_directories(seq);
    for (int f = 1; f <= 3; ++f) {
        // Two view layers: Sun (brighter) and Shade.
        std::vector<ExrPart> shade = {simplePart("Shade.Combined", 12, 8, kRgb, ramp(0.1f + 0.05f * f)),
                                      simplePart("Shade.Denoising Albedo", 12, 8, kRgb, ramp(0.4f))};
        blenderFrame(seq + "/render000" + std::to_string(f) + ".exr", 0.6f + 0.05f * f, true, "Sun", shade);
    }
    auto r = runCli("denoise --method eaw --sequence " + seq + " --out " + (dir / "none"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("--layer"), std::string::npos) << r.output;
    for (const char* layer : {"Sun", "Shade"}) {
        const std::string out = dir / (std::string("out_") + layer);
        r = runCli("denoise --method eaw --device cpu --sequence " + seq + " --layer " + layer + " --out " + out);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        // Each frame is what `denoise --in FRAME --layer L` gives for that frame.
        for (int f = 1; f <= 3; ++f) {
            const std::string one = dir / (std::string("one_") + layer + std::to_string(f) + ".exr");
            auto s = runCli("denoise --method eaw --device cpu --in " + seq + "/render000" + std::to_string(f) + ".exr --layer " +
                            layer + " --out " + one);
            ASSERT_EQ(s.exitCode, 0) << s.output;
            const Image a = atrous::readImage(one), b = atrous::readImage(out + "/render000" + std::to_string(f) + ".exr");
            ASSERT_EQ(a.size(), b.size());
            EXPECT_TRUE(std::equal(a.data(), a.data() + a.size(), b.data())) << layer << " frame " << f;
        }
    }
    // --pass picks the same passes by name; --add-pass writes each frame as a copy with the pass.
    const std::string out = dir / "out_pass";
    r = runCli("denoise --method eaw --device cpu --sequence " + seq + " --pass color=Shade.Combined --pass 'albedo=Shade.Denoising "
               "Albedo' --pass 'normal=Sun.Denoising Normal' --add-pass Denoised --out " + out);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const io::ExrInfo info = io::inspectExr(out + "/render0002.exr");
    std::vector<std::string> layers;
    for (const auto& l : info.layers) layers.push_back(l.name);
    EXPECT_NE(std::find(layers.begin(), layers.end(), "Sun.Denoised"), layers.end()) << io::layerList(info);
    EXPECT_NE(std::find(layers.begin(), layers.end(), "Shade.Combined"), layers.end()) << io::layerList(info);
}

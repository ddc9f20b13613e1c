// `atrous view --in` / `--sequence` (issue 49): the viewer's pipeline on a frame read from files
// (no window: the slots give what denoise() gives on the same buffers, a method or parameter
// switch refilters, an unchanged step does not, a sequence's frames), and the viewer under Xvfb
// on a Blender-like multilayer EXR, a LuxCore-style folder and a rendered sequence (screenshots
// that differ between methods and parameters; the written image and its printed `atrous denoise`
// command, which gives the same bytes; bad input: one line, exit 2).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "atrous/view_pipeline.h"
#include "test_util.h"
#include "xvfb_util.h"

using namespace atrous;
using namespace atrous::test;
namespace fs = std::filesystem;

namespace {

// A cornell render at 48x32, 4 spp (every buffer atrous writes): DIR/render/.
std::string renderStill(const TempDir& dir) {
    const std::string out = dir / "render";
    const CliResult r = runCli("render --scene cornell --spp 4 --width 48 --height 32 --out " + out);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return out;
}

// The render's buffers in a folder under LuxCore's film output names.
std::string luxFolder(const TempDir& dir, const std::string& render) {
    const std::string lux = dir / "lux";
    fs::create_directories(lux);
    for (const auto& [ours, theirs] : {std::pair<const char*, const char*>{"color.exr", "RGB.exr"},
                                       {"albedo.exr", "ALBEDO.exr"},
                                       {"normal.exr", "AVG_SHADING_NORMAL.exr"},
                                       {"position.exr", "POSITION.exr"},
                                       {"depth.exr", "DEPTH.exr"}})
        fs::copy_file(fs::path(render) / ours, fs::path(lux) / theirs);
    return lux;
}

// The render's buffers as a Blender multilayer EXR (one view layer, Blender's pass names).
std::string multilayerExr(const TempDir& dir, const std::string& render) {
    const Image color = readImage(render + "/color.exr"), albedo = readImage(render + "/albedo.exr"),
                normal = readImage(render + "/normal.exr"), depth3 = readImage(render + "/depth.exr");
    Image depth(depth3.width(), depth3.height(), 1);
    for (size_t p = 0; p < depth.plane(); ++p) depth.data()[p] = depth3.data()[p];
    const std::string path = dir / "render_multilayer.exr";
    io::writeLayeredExr(path,
                        {{"ViewLayer.Combined", &color},
                         {"ViewLayer.Denoising Albedo", &albedo},
                         {"ViewLayer.Normal", &normal, {"X", "Y", "Z"}},
                         {"ViewLayer.Depth", &depth, {"Z"}}},
                        /*multipart=*/true);
    return path;
}

io::BufferSet load(const std::string& in) {
    io::BufferFiles f;
    f.in = in;
    return io::loadBuffers(f);
}

bool sameBits(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (a.data()[i] != b.data()[i]) return false;
    return true;
}

double meanAbsDiff(const Image& a, const Image& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += std::abs(double(a.data()[i]) - double(b.data()[i]));
    return s / double(a.size());
}

}  // namespace

// ---- the pipeline on a loaded frame (no window) ----

TEST(ViewFiles, EachStillMethodGivesWhatDenoiseGivesOnTheSameBuffers) {
    TempDir dir;
    const std::string lux = luxFolder(dir, renderStill(dir));
    view::ViewPipeline pl(load(lux), Device::Cpu);
    EXPECT_TRUE(pl.fromFiles());
    EXPECT_EQ(pl.width(), 48);
    const io::BufferSet set = load(lux);
    for (const char* name : {"eaw", "sure", "blend", "auto"}) {
        view::PipelineSettings s;
        s.methodA = view::parseMethod(name);
        s.denoise.eaw.levels = 3;
        pl.step(s);
        ASSERT_TRUE(pl.slot(0).error.empty()) << pl.slot(0).error;
        DenoiseOptions o = s.denoise;
        o.method = parseDenoiseMethod(name);
        // Bit for bit: the viewer hands the loaded buffers over as `atrous denoise --in` does.
        EXPECT_TRUE(sameBits(pl.resultHost(0), denoise(io::refsOf(set), o))) << name;
    }
}

TEST(ViewFiles, OnlyAChangedMethodParameterOrFrameFiltersAgain) {
    TempDir dir;
    const std::string render = renderStill(dir);
    view::ViewPipeline pl(load(render), Device::Cpu);
    view::PipelineSettings s;
    s.methodA = view::parseMethod("eaw");
    pl.step(s);
    EXPECT_TRUE(pl.stepFiltered());
    const Image first = pl.resultHost(0).clone();
    pl.step(s);  // nothing changed: the result stays, nothing ran
    EXPECT_FALSE(pl.stepFiltered());
    EXPECT_TRUE(sameBits(pl.resultHost(0), first));
    s.denoise.eaw.levels = 2;  // a parameter
    pl.step(s);
    EXPECT_TRUE(pl.stepFiltered());
    EXPECT_GT(meanAbsDiff(pl.resultHost(0), first), 0.0);
    s.methodA = view::parseMethod("sure");  // a method
    pl.step(s);
    EXPECT_TRUE(pl.stepFiltered());
    EXPECT_EQ(pl.slot(0).method, view::parseMethod("sure"));
    s.split = true;  // slot B appears: filtered, slot A kept
    s.methodB = view::parseMethod("none");
    pl.step(s);
    EXPECT_TRUE(pl.stepFiltered());
    EXPECT_TRUE(sameBits(pl.resultHost(1), load(render).image[int(io::Buffer::Color)]));
    pl.resetAccumulation();  // the panel's "filter again"
    pl.step(s);
    EXPECT_TRUE(pl.stepFiltered());
}

TEST(ViewFiles, ASequencesFramesReplaceTheFrameAndFeedTheSequenceMethods) {
    TempDir dir;
    const std::string seq = dir / "seq";
    ASSERT_EQ(runCli("render --scene cornell-moving --frames 3 --spp 1 --width 32 --height 24 --out " + seq).exitCode, 0);
    view::ViewPipeline pl(load(seq + "/frame_0000"), Device::Cpu);
    view::PipelineSettings s;
    s.methodA = view::parseMethod("svgf");
    pl.step(s);
    ASSERT_TRUE(pl.slot(0).error.empty()) << pl.slot(0).error;
    const Image f0 = pl.resultHost(0).clone();
    pl.step(s);  // the same frame is not pushed again
    EXPECT_FALSE(pl.stepFiltered());
    pl.setFrame(load(seq + "/frame_0001"), true);
    pl.step(s);
    ASSERT_TRUE(pl.slot(0).error.empty()) << pl.slot(0).error;
    EXPECT_GT(meanAbsDiff(pl.resultHost(0), f0), 0.0);
    EXPECT_TRUE(sameBits(pl.color(), load(seq + "/frame_0001").image[int(io::Buffer::Color)]));
    // A frame of another size is refused, naming its file.
    TempDir other;
    ASSERT_EQ(runCli("render --scene cornell --spp 1 --width 16 --height 8 --out " + std::string(other / "r")).exitCode, 0);
    try {
        pl.setFrame(load(other / "r"), false);
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("color.exr"), std::string::npos) << e.what();
    }
}

// ---- the viewer (Xvfb) and the CLI ----

namespace {

// A headless run's screenshot of the image alone (--hide-ui), read back.
Image screenshot(const std::string& args, const std::string& png, int frames = 2) {
    const CliResult r = runUnderXvfb(args + " --frames " + std::to_string(frames) + " --hide-ui --screenshot " + png);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return r.exitCode == 0 ? readImage(png) : Image();
}

std::string firstLine(const std::string& path) {
    std::ifstream f(path);
    std::string line;
    std::getline(f, line);
    return line;
}

std::string readBytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// --write-image, then the command it printed (and wrote in the .txt) run: the same EXR bytes.
void expectCommandReproduces(const TempDir& dir, const std::string& args, const std::string& tag) {
    const std::string out = dir / ("written_" + tag);
    const CliResult r = runUnderXvfb(args + " --frames 1 --hide-ui --write-image --out " + out);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string exr = out + "/view_0001.exr", cmd = firstLine(out + "/view_0001.txt");
    ASSERT_TRUE(fs::exists(exr) && fs::exists(out + "/view_0001.png")) << r.output;
    ASSERT_EQ(cmd.rfind("atrous denoise ", 0), 0u) << cmd;
    EXPECT_NE(r.output.find(cmd), std::string::npos) << "the command is printed too:\n" << r.output;
    const std::string viewer = readBytes(exr);
    fs::remove(exr);
    const CliResult d = runShell(std::string(ATROUS_CLI) + cmd.substr(6));
    ASSERT_EQ(d.exitCode, 0) << cmd << "\n" << d.output;
    EXPECT_TRUE(readBytes(exr) == viewer) << tag << ": " << cmd;
}

}  // namespace

TEST(ViewFilesWindow, MultilayerExrAndLuxCoreFolderShowEveryMethod) {
    REQUIRE_VIEWER_AND_XVFB();
    TempDir dir;
    const std::string render = renderStill(dir);
    const std::string inputs[] = {multilayerExr(dir, render), luxFolder(dir, render)};
    for (const std::string& in : inputs) {
        const std::string base = "view --in " + in + " ";
        const Image noisy = screenshot(base + "--method none", dir / "none.png");
        const Image eaw = screenshot(base + "--method eaw", dir / "eaw.png");
        const Image eaw3 = screenshot(base + "--method eaw --levels 2 --sigma-normal 0.2", dir / "eaw3.png");
        const Image sure = screenshot(base + "--method sure", dir / "sure.png");
        const Image blend = screenshot(base + "--method blend --compare eaw", dir / "blend.png");
        ASSERT_FALSE(noisy.empty() || eaw.empty() || eaw3.empty() || sure.empty() || blend.empty()) << in;
        EXPECT_EQ(noisy.width(), 48);
        EXPECT_EQ(noisy.height(), 32);
        // Each method, and a parameter, change the image (8-bit screenshots: any difference is
        // at least one code value somewhere).
        EXPECT_GT(meanAbsDiff(noisy, eaw), 0.0) << in;
        EXPECT_GT(meanAbsDiff(eaw, eaw3), 0.0) << in;
        EXPECT_GT(meanAbsDiff(eaw, sure), 0.0) << in;
        EXPECT_GT(meanAbsDiff(sure, blend), 0.0) << in;
    }
}

TEST(ViewFilesWindow, TheWrittenCommandGivesTheSameImageBytes) {
    REQUIRE_VIEWER_AND_XVFB();
    TempDir dir;
    const std::string render = renderStill(dir);
    const std::string ml = multilayerExr(dir, render), lux = luxFolder(dir, render);
    expectCommandReproduces(dir, "view --in " + ml + " --method eaw --levels 3 --sigma-normal 0.25 --no-firefly", "ml_eaw");
    expectCommandReproduces(dir, "view --in " + lux + " --method sure --sure-mode james-stein --sure-window 2", "lux_sure");
    expectCommandReproduces(dir, "view --in " + lux + " --method blend", "lux_blend");
    expectCommandReproduces(dir, "view --color " + render + "/color.exr --albedo " + render + "/albedo.exr --method auto",
                            "files_auto");
    // A sequence's frame: the command reads that frame alone (the headless run shows frame 1).
    const std::string seq = dir / "seq";
    ASSERT_EQ(runCli("render --scene cornell-moving --frames 2 --spp 1 --width 32 --height 24 --out " + seq).exitCode, 0);
    expectCommandReproduces(dir, "view --sequence " + seq + " --method eaw --levels 4", "seq_eaw");
    // A sequence method has no single-frame command: the .txt says why.
    const std::string out = dir / "written_svgf";
    ASSERT_EQ(runUnderXvfb("view --sequence " + seq + " --method svgf --frames 1 --hide-ui --write-image --out " + out).exitCode, 0);
    EXPECT_EQ(firstLine(out + "/view_0001.txt").rfind("# method svgf is a sequence method", 0), 0u);
}

TEST(ViewFilesWindow, ASequencePlaysAndItsMethodsRun) {
    REQUIRE_VIEWER_AND_XVFB();
    TempDir dir;
    const std::string seq = dir / "seq";
    ASSERT_EQ(runCli("render --scene cornell-moving --frames 3 --spp 1 --width 32 --height 24 --out " + seq).exitCode, 0);
    const Image first = screenshot("view --sequence " + seq + " --method none", dir / "f1.png", 1);
    const Image third = screenshot("view --sequence " + seq + " --method none", dir / "f3.png", 3);
    ASSERT_FALSE(first.empty() || third.empty());
    EXPECT_GT(meanAbsDiff(first, third), 0.0) << "frame 3 is not frame 1";
    const Image svgf = screenshot("view --sequence " + seq + " --method svgf", dir / "svgf.png", 3);
    const Image temporal = screenshot("view --sequence " + seq + " --method temporal", dir / "temporal.png", 3);
    ASSERT_FALSE(svgf.empty() || temporal.empty());
    EXPECT_GT(meanAbsDiff(svgf, temporal), 0.0);
}

TEST(ViewFiles, BadInputIsOneLineNamingTheFileAndExitCode2) {
    if (!viewerBuilt()) GTEST_SKIP() << "atrous built without the viewer";
    TempDir dir;
    const std::string json = dir / "scene.json", missing = dir / "missing.exr", render = dir / "render.exr";
    std::ofstream(json) << "{}";
    std::ofstream(render) << "not an exr";
    const std::pair<std::string, std::string> cases[] = {
        {"view --in " + missing, missing},
        {"view --in " + render, "render.exr"},
        {"view --in " + json, "a JSON scene, not a render"},
        {"view --sequence " + json, "a JSON scene, not a render"},
        {"view --in " + render + " --scene cornell", "--in and --scene"},
        {"view --scene " + render, "open it with --in"},
        {"view --in " + render + " --spp 4", "--spp: a render read from files"},
        {"view --layer ViewLayer", "give exactly one of --in"},
        {"view --sequence " + std::string(dir / "nothing"), "nothing"},
    };
    for (const auto& [args, needle] : cases) {
        const CliResult r = runCli(args);
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
        EXPECT_NE(r.output.find(needle), std::string::npos) << args << "\n" << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << args << "\n" << r.output;
    }
}

// End-to-end tests of `atrous render`: the files it writes and every bad-input case (exit code 2,
// one line naming the problem, nothing written).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "atrous/device.h"
#include "atrous/image.h"
#include "atrous/io/image_io.h"
#include "test_util.h"

namespace atrous {
namespace {

namespace fs = std::filesystem;
using test::sameImages;
using test::countEntries;
using test::runCli;
using test::TempDir;

int lines(const std::string& s) {
    int n = 0;
    for (char c : s) n += c == '\n';
    return n;
}

TEST(RenderCli, WritesAllBuffersAndASummary) {
    TempDir tmp;
    auto r = runCli("render --scene cornell --width 24 --height 16 --spp 2 --seed 3 --max-depth 4 --threads 1 --out " + tmp.str());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("24x16"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("samples/s"), std::string::npos) << r.output;
    for (const char* f : {"color.exr", "variance.exr", "albedo.exr", "normal.exr", "position.exr", "depth.exr", "ids.exr",
                          "emission.exr", "color.png"})
        EXPECT_TRUE(fs::exists(tmp / f)) << f;
    EXPECT_EQ(countEntries(tmp.str()), 9);  // and no temporary files left behind
    // The camera sees the ceiling light: its emission is in emission.exr, and nowhere else is.
    Image emission = atrous::readImage(tmp / "emission.exr");
    float maxE = 0.0f;
    for (size_t i = 0; i < emission.size(); ++i) maxE = std::max(maxE, emission.data()[i]);
    EXPECT_GT(maxE, 1.0f);
    Image ids = atrous::readImage(tmp / "ids.exr");
    EXPECT_EQ(ids.width(), 24);
    EXPECT_EQ(ids.height(), 16);
    Image depth = atrous::readImage(tmp / "depth.exr");
    EXPECT_GT(depth(12, 8, 0), 0.0f);
}

TEST(RenderCli, CudaWithoutAGpuIsAClearError) {
    if (cudaAvailable()) GTEST_SKIP() << "a GPU is present: --device cuda is valid here";
    TempDir tmp;
    auto r = runCli("render --scene cornell --width 8 --height 8 --spp 1 --device cuda --out " + (tmp / "out"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("cuda"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(tmp / "out"));
}

TEST(RenderCli, HelpListsTheOptions) {
    auto r = runCli("render --help");
    EXPECT_EQ(r.exitCode, 0);
    for (const char* opt : {"--scene", "--width", "--height", "--spp", "--seed", "--max-depth", "--threads", "--out", "--denoise"})
        EXPECT_NE(r.output.find(opt), std::string::npos) << opt;
}

TEST(RenderCli, DenoiseWritesDenoisedImages) {
    TempDir tmp;
    auto r = runCli("render --scene cornell --width 32 --height 32 --spp 4 --denoise eaw,sure --out " + tmp.str());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (const char* f : {"denoised_eaw.exr", "denoised_sure.exr", "denoised_eaw.png", "denoised_sure.png"})
        EXPECT_TRUE(fs::exists(tmp / f)) << f;
}

// Each case: exit code 2, exactly one line "atrous: error: ..." containing `expect`, and nothing
// written (the output directory is not even created).
void expectBadInput(const std::string& args, const std::string& expect, const TempDir& tmp) {
    std::string out = tmp / "out";
    auto r = runCli("render " + args + " --out " + out);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_EQ(r.output.rfind("atrous: error:", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(expect), std::string::npos) << args << "\n" << r.output;
    EXPECT_TRUE(!fs::exists(out) || countEntries(out) == 0) << args;
}

TEST(RenderCli, BadInputIsOneLineExitTwoNothingWritten) {
    TempDir tmp;
    std::string d = tmp.str();
    std::ofstream(tmp / "malformed.json") << "{ \"camera\": ";
    std::ofstream(tmp / "bad.obj") << "v 0 0 0\nf 1 2 3\n";
    std::ofstream(tmp / "objscene.json")
        << R"({"camera": {"position": [0,0,3], "lookAt": [0,0,0]}, "objects": [{"type": "mesh", "file": "bad.obj"}]})";
    std::ofstream(tmp / "missingobj.json")
        << R"({"camera": {"position": [0,0,3], "lookAt": [0,0,0]}, "objects": [{"type": "mesh", "file": "gone.obj"}]})";
    std::ofstream(tmp / "tex.json")
        << R"({"camera": {"position": [0,0,3], "lookAt": [0,0,0]}, "materials": {"m": {"texture": "gone.png"}}, "objects": []})";
    std::ofstream(tmp / "badtex.png") << "this is not a png";
    std::ofstream(tmp / "badtex.json")
        << R"({"camera": {"position": [0,0,3], "lookAt": [0,0,0]}, "materials": {"m": {"texture": "badtex.png"}}, "objects": []})";
    const std::string ok = " --width 8 --height 8 --spp 1";
    // Each case: the command line's arguments and what its one error line must name.
    const std::pair<std::string, std::string> cases[] = {
        {"--scene " + d + "/nothere.json" + ok, "nothere.json"},
        {"--scene " + d + "/malformed.json" + ok, "malformed.json"},
        {"--scene " + d + "/objscene.json" + ok, "bad.obj"},
        {"--scene " + d + "/missingobj.json" + ok, "gone.obj"},
        {"--scene " + d + "/tex.json" + ok, "gone.png"},
        {"--scene " + d + "/badtex.json" + ok, "badtex.png"},
        {"--scene kitchen" + ok, "kitchen"},
        {"--scene cornell --spp 0 --width 8 --height 8", "--spp"},
        {"--scene cornell --spp -4 --width 8 --height 8", "--spp"},
        {"--scene cornell --width 0 --height 8 --spp 1", "--width"},
        {"--scene cornell --width 8 --height -1 --spp 1", "--height"},
        {"--scene cornell --width 20000 --height 8 --spp 1", "--width"},
        {"--scene cornell --width 8 --height 16385 --spp 1", "--height"},
        {"--scene cornell --width 8 --height 8 --spp 1 --denoise blur", "blur"},
        {"--scene cornell --width 8 --height 8 --spp 1 --max-depth -1", "--max-depth"},
        {"--scene cornell --width 8 --height 8 --spp 1 --threads -1", "--threads"},
        // The render table's rules, the flag named from the library's field (no message parsing).
        {"--scene cornell --width 0 --height 8 --spp 1", "--width: must be in 1..16384 (got 0)"},
        {"--scene cornell --width 8 --height 8 --spp 1 --max-depth 2000", "--max-depth: must be in 0..1024 (got 2000)"},
        {"--scene cornell --width 8 --height 8 --spp ''", "--spp"},
    };
    for (const auto& [args, needle] : cases) expectBadInput(args, needle, tmp);
}

// render --denoise and denoise of the buffers it wrote take their inputs from the one assembly
// (Frame): every buffer, emission included. The buffers are written as 32-bit float
// EXR and the CPU filters are deterministic, so the images must be equal bit for bit; without
// emission.exr the result differs (so the comparison sees whether emission was used).
TEST(RenderCli, DenoiseEqualsDenoiseOfTheWrittenBuffers) {
    TempDir tmp;
    const std::string dir = tmp / "r";
    auto r = runCli("render --scene cornell --width 40 --height 32 --spp 4 --device cpu --denoise eaw,sure --quiet --out " + dir);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string noEmission = tmp / "r_no_emission";
    fs::create_directories(noEmission);
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().extension() == ".exr" && e.path().filename() != "emission.exr")
            fs::copy_file(e.path(), fs::path(noEmission) / e.path().filename());
    for (const char* m : {"eaw", "sure"}) {
        const std::string out = tmp / (std::string("d_") + m + ".exr"), out2 = tmp / (std::string("n_") + m + ".exr");
        r = runCli("denoise --in " + dir + " --method " + m + " --device cpu --out " + out);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        EXPECT_NE(r.output.find("emission"), std::string::npos) << r.output;  // "buffers used: ..."
        const Image fromRender = atrous::readImage(dir + "/denoised_" + m + ".exr");
        EXPECT_TRUE(sameImages(fromRender, atrous::readImage(out))) << m;
        r = runCli("denoise --in " + noEmission + " --method " + m + " --device cpu --out " + out2);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        EXPECT_FALSE(sameImages(fromRender, atrous::readImage(out2))) << m << ": emission.exr made no difference";
    }
}

TEST(RenderCli, UnwritableOutputDirectory) {
    TempDir tmp;
    std::ofstream(tmp / "blocker") << "a file, not a directory";
    // An output path below a regular file can never be created (even by root, unlike chmod).
    std::string out = tmp / "blocker/out";
    auto r = runCli("render --scene cornell --width 8 --height 8 --spp 1 --out " + out);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("blocker"), std::string::npos) << r.output;
    r = runCli("render --scene cornell --width 8 --height 8 --spp 1 --out " + (tmp / "blocker"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("not a directory"), std::string::npos) << r.output;
    EXPECT_EQ(countEntries(tmp.str()), 1);  // still just the blocker
}

// Runs the CLI with stderr on a pseudo-terminal (stdout on a pipe): what an interactive user sees.
// Returns the exit code; `out` gets stdout, `tty` what was written to the terminal.
int runCliWithTerminal(const std::string& args, std::string& out, std::string& tty) {
    const int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) return -1;
    const std::string slave = ptsname(master);
    const int keep = open(slave.c_str(), O_RDWR | O_NOCTTY);  // held open: no hang-up when the CLI exits
    test::CliResult r = runCli(args + " 2>" + slave + " #");       // '#' comments out runCli's own 2>&1
    out = r.output;
    fcntl(master, F_SETFL, O_NONBLOCK);
    char buf[4096];
    for (ssize_t n; (n = read(master, buf, sizeof(buf))) > 0;) tty.append(buf, size_t(n));
    close(keep);
    close(master);
    return r.exitCode;
}

// Long renders show a progress line on a terminal (UX audit, item 3): still images by finished
// tiles, sequences per frame with an ETA; --quiet silences it, and a pipe (logs, the other
// tests here) never gets it.
TEST(RenderCli, ProgressLineOnlyOnATerminal) {
    TempDir tmp;
    std::string out, tty;
    int rc = runCliWithTerminal("render --scene cornell --width 16 --height 16 --spp 1 --out " + (tmp / "a"), out, tty);
    ASSERT_EQ(rc, 0) << out << tty;
    EXPECT_NE(tty.find("render: "), std::string::npos) << tty;
    EXPECT_NE(tty.find("% ("), std::string::npos) << tty;
    EXPECT_NE(tty.find("\r\033[K"), std::string::npos) << tty;  // redrawn in place and cleared at the end
    EXPECT_EQ(out.find("%"), std::string::npos) << out;         // stdout keeps the one summary line

    tty.clear();
    rc = runCliWithTerminal("render --scene cornell --width 16 --height 16 --spp 1 --frames 2 --reference-spp 2 --out " +
                                (tmp / "s"),
                            out, tty);
    ASSERT_EQ(rc, 0) << out << tty;
    EXPECT_NE(tty.find("render: frame 1/2, "), std::string::npos) << tty;
    EXPECT_NE(tty.find("ETA"), std::string::npos) << tty;

    tty.clear();
    rc = runCliWithTerminal("render --quiet --scene cornell --width 16 --height 16 --spp 1 --frames 2 --out " + (tmp / "q"),
                            out, tty);
    ASSERT_EQ(rc, 0) << out << tty;
    EXPECT_EQ(tty, "");

    auto r = runCli("render --scene cornell --width 16 --height 16 --spp 1 --out " + (tmp / "p"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(r.output.find("ETA"), std::string::npos) << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
}

// Messages that name the flag (UX audit, item 7).
TEST(RenderCli, ErrorsNameTheFlag) {
    TempDir tmp;
    const std::string ok = "render --scene cornell --width 8 --height 8 --spp 1 --out " + tmp.str();
    auto r = runCli(ok + " --device gpu");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("--device: must be cpu, cuda or auto (got 'gpu')"), std::string::npos) << r.output;
    r = runCli(ok + " --denoise foo");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("--denoise: unknown denoise method 'foo'"), std::string::npos) << r.output;
    EXPECT_EQ(countEntries(tmp.str()), 0);
}

}  // namespace
}  // namespace atrous

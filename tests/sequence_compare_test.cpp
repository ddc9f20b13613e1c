// `atrous compare --sequence REF_DIR OUT_DIR ...` (issue 28, temporal metrics): per-sequence relMSE,
// PSNR, SSIM and the temporal relMSE and tPSNR of frame-to-frame differences, frames matched by
// number. The sequences are made here: a static reference, an output off by a constant (no flicker)
// and one off by an alternating sign (flicker): the same per-frame error, different temporal error.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "atrous/image.h"
#include "atrous/metrics.h"
#include "atrous/io/image_io.h"
#include "test_util.h"

using atrous::test::runCli;
using atrous::test::TempDir;
namespace fs = std::filesystem;

namespace {

// A stand-in for an external command (flip, atrous-cvvdp): DIR/NAME/EXE, a shell script.
std::string standIn(const TempDir& dir, const std::string& name, const std::string& exe, const std::string& body) {
    const std::string bin = dir / name;
    fs::create_directories(bin);
    std::ofstream(bin + "/" + exe) << "#!/bin/sh\n" << body;
    fs::permissions(bin + "/" + exe, fs::perms::owner_all);
    return bin;
}

// `compare --json ARGS --sequence DIR/ref DIR/out` with PATH set to `path`: the first sequence's
// value of `key` and the output. The other metrics must be there (exit 0, relMSE > 0).
std::pair<nlohmann::json, std::string> compareWith(const TempDir& dir, const std::string& path, const std::string& args,
                                                   const char* key) {
    const char* old = std::getenv("PATH");
    const std::string oldPath = old ? old : "/usr/bin:/bin";
    setenv("PATH", path.c_str(), 1);
    auto r = runCli("compare --json " + args + " --sequence " + dir / "ref" + " " + dir / "out");
    setenv("PATH", oldPath.c_str(), 1);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    const auto s = nlohmann::json::parse(r.output.substr(r.output.find('{')))["sequences"][0];
    EXPECT_GT(s["relmse"].get<double>(), 0.0) << r.output;
    return {s[key], r.output};
}

std::string currentPath() {
    const char* old = std::getenv("PATH");
    return old ? old : "/usr/bin:/bin";
}

atrous::Image frame(float base, float offset) {
    atrous::Image img(16, 12, 3);
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 16; ++x)
            for (int c = 0; c < 3; ++c) img(x, y, c) = base + 0.01f * float(x + y + c) + offset;
    return img;
}

void writeSequence(const std::string& dir, int frames, float offset, bool alternate) {
    fs::create_directories(dir);
    for (int f = 1; f <= frames; ++f)
        atrous::writeImage(dir + "/frame_000" + std::to_string(f) + ".exr",
                               frame(0.5f, alternate && f % 2 ? -offset : offset));
}

}  // namespace

TEST(SequenceCompare, TemporalErrorSeesFlickerThatPerFrameErrorDoesNot) {
    TempDir dir;
    writeSequence(dir / "ref", 4, 0.0f, false);
    writeSequence(dir / "steady", 4, 0.1f, false);
    writeSequence(dir / "flicker", 4, 0.1f, true);
    auto r = runCli("compare --json --sequence " + dir / "ref" + " " + dir / "ref" + " " + dir / "steady" + " " + dir / "flicker");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const nlohmann::json j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
    ASSERT_EQ(j["sequences"].size(), 3u);
    const auto& same = j["sequences"][0];
    const auto& steady = j["sequences"][1];
    const auto& flicker = j["sequences"][2];
    EXPECT_EQ(same["frames"], 4);
    EXPECT_EQ(same["relmse"].get<double>(), 0.0);
    EXPECT_EQ(same["temporal_relmse"].get<double>(), 0.0);
    EXPECT_EQ(same["tpsnr"].get<double>(), 100.0);
    // The same per-frame error (|offset| 0.1 everywhere, up to float32 rounding of x ± 0.1: 1e-6 relative) ...
    EXPECT_NEAR(steady["relmse"].get<double>(), flicker["relmse"].get<double>(), 1e-6 * steady["relmse"].get<double>());
    EXPECT_GT(steady["relmse"].get<double>(), 1e-3);
    // ... but only the flickering one changes from frame to frame: differences of ±0.2.
    EXPECT_LT(steady["temporal_relmse"].get<double>(), 1e-10);
    EXPECT_GT(flicker["temporal_relmse"].get<double>(), 0.01);
    EXPECT_LT(flicker["tpsnr"].get<double>(), 40.0);
    // The library's function agrees with the CLI on one step: d - d_ref = 0.2 everywhere.
    const atrous::TemporalMetrics t =
        atrous::computeTemporalMetrics(frame(0.5f, 0.1f), frame(0.5f, -0.1f), frame(0.5f, 0.0f), frame(0.5f, 0.0f));
    EXPECT_GT(t.relMse, 0.04 / (1.6 * 1.6 + 0.01));
    EXPECT_LT(t.relMse, 0.04 / (0.5 * 0.5 + 0.01));
}

TEST(SequenceCompare, FramesThatDoNotMatchAreOneLineAndExit2) {
    TempDir dir;
    writeSequence(dir / "ref", 3, 0.0f, false);
    writeSequence(dir / "short", 2, 0.1f, false);
    auto r = runCli("compare --sequence " + dir / "ref" + " " + dir / "short");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("frame 3 is missing"), std::string::npos) << r.output;
    // A frame of another size names the frame.
    writeSequence(dir / "odd", 3, 0.1f, false);
    atrous::writeImage(dir / "odd/frame_0002.exr", atrous::Image(8, 8, 3));
    r = runCli("compare --sequence " + dir / "ref" + " " + dir / "odd");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("frame 2"), std::string::npos) << r.output;
    // --ref is for images. (A sequence alone is judged without a reference: tests/flicker_test.cpp.)
    r = runCli("compare --sequence " + dir / "ref" + " --ref " + dir / "ref/frame_0001.exr " + dir / "odd");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    r = runCli("compare --sequence " + dir / "ref" + " --no-reference --video " + dir / "v.mp4");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    r = runCli("compare " + dir / "odd/frame_0001.exr");
    EXPECT_EQ(r.exitCode, 2) << r.output;
}

TEST(SequenceCompare, VideoSideBySide) {
    TempDir dir;
    writeSequence(dir / "ref", 3, 0.0f, false);
    writeSequence(dir / "flicker", 3, 0.1f, true);
    // Refused before anything is read: not with images, not over an input, not another container.
    auto r = runCli("compare --ref " + dir / "ref/frame_0001.exr " + dir / "flicker/frame_0001.exr --video " + dir / "v.mp4");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    r = runCli("compare --sequence " + dir / "ref " + dir / "flicker --video " + dir / "v.avi");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    r = runCli("compare --sequence " + dir / "ref " + dir / "flicker --video " + dir / "ref/frame_0002.exr");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    if (system("command -v ffmpeg > /dev/null 2>&1") != 0) GTEST_SKIP() << "ffmpeg is not on PATH";
    r = runCli("compare --sequence " + dir / "ref " + dir / "flicker --video " + dir / "v.mp4");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    ASSERT_TRUE(fs::exists(dir / "v.mp4")) << r.output;
    std::ifstream f(dir / "v.mp4", std::ios::binary);
    char head[8] = {};
    f.read(head, 8);
    EXPECT_EQ(std::string(head + 4, 4), "ftyp");  // an MP4 container
    // No temporary folder is left beside it.
    int entries = 0;
    for (const auto& e : fs::directory_iterator(dir.str())) entries += e.path().filename().string().rfind(".atrous", 0) == 0;
    EXPECT_EQ(entries, 0);
}

// FLIP: with NVIDIA's `flip` on PATH, the mean over frames of the "Mean: x" it prints per frame
// (a stand-in here that answers -h as FLIP does and checks its arguments name two written EXRs);
// --no-flip and a PATH without `flip` give none (the latter with a note); another program called
// flip (Debian's line-ending converter) is not taken for FLIP, and a FLIP that fails on a frame
// leaves that sequence's FLIP out (null, one note) while the other metrics are printed, exit 0.
TEST(SequenceCompare, FlipColumnFromTheFlipCommandOnPath) {
    TempDir dir;
    writeSequence(dir / "ref", 3, 0.0f, false);
    writeSequence(dir / "out", 3, 0.1f, false);
    const std::string good = standIn(dir, "good", "flip",
                                     "[ \"$1\" = -h ] && { echo 'FLIP v1.7.'; exit 0; }\n"
                                     "[ \"$1\" = -r ] && [ -s \"$2\" ] && [ \"$3\" = -t ] && [ -s \"$4\" ] || exit 3\n"
                                     "echo 'FLIP between reference image and test image'\necho '     Mean: 0.250000'\n");
    const std::string other = standIn(dir, "other", "flip", "echo 'usage: flip [-t|-u|-m] file ...'\nexit 1\n");
    const std::string failing =
        standIn(dir, "failing", "flip", "[ \"$1\" = -h ] && { echo 'FLIP v1.7.'; exit 0; }\necho 'boom'\nexit 1\n");
    const std::string path = currentPath();
    auto compare = [&](const std::string& p, const std::string& args) { return compareWith(dir, p, "--no-cvvdp " + args, "flip"); };
    EXPECT_DOUBLE_EQ(compare(good + ":" + path, "").first.get<double>(), 0.25);
    EXPECT_TRUE(compare(good + ":" + path, "--no-flip").first.is_null());
    auto none = compare("/usr/bin:/bin", "");
    EXPECT_TRUE(none.first.is_null());
    EXPECT_NE(none.second.find("note: no FLIP column"), std::string::npos) << none.second;
    auto notFlip = compare(other + ":/usr/bin:/bin", "");
    EXPECT_TRUE(notFlip.first.is_null());
    EXPECT_NE(notFlip.second.find("is not NVIDIA's FLIP"), std::string::npos) << notFlip.second;
    auto failed = compare(failing + ":/usr/bin:/bin", "");
    EXPECT_TRUE(failed.first.is_null());
    EXPECT_NE(failed.second.find("failed on frame 1"), std::string::npos) << failed.second;
}

// The real FLIP, where `make python` installed it (.venv/bin/flip): a sequence against itself has
// FLIP 0 and one off by 0.1 a FLIP in (0, 1).
TEST(SequenceCompare, RealFlipWhereInstalled) {
    const std::string venv = std::string(ATROUS_SOURCE_DIR) + "/.venv/bin";
    if (!fs::exists(venv + "/flip")) GTEST_SKIP() << "no .venv/bin/flip (make python)";
    TempDir dir;
    writeSequence(dir / "ref", 3, 0.0f, false);
    writeSequence(dir / "out", 3, 0.1f, false);
    const char* old = std::getenv("PATH");
    const std::string oldPath = old ? old : "/usr/bin:/bin";
    setenv("PATH", (venv + ":" + oldPath).c_str(), 1);
    auto r = runCli("compare --json --sequence " + dir / "ref" + " " + dir / "ref" + " " + dir / "out");
    setenv("PATH", oldPath.c_str(), 1);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const nlohmann::json j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
    EXPECT_EQ(j["sequences"][0]["flip"].get<double>(), 0.0);
    EXPECT_GT(j["sequences"][1]["flip"].get<double>(), 0.0);
    EXPECT_LT(j["sequences"][1]["flip"].get<double>(), 1.0);
}

// ColorVideoVDP: with the atrous-cvvdp command on PATH and its --check passing, one JOD per sequence
// from the "JOD: x" it prints for a --pairs list of REFERENCE<TAB>TEST frames it can read (a
// stand-in here that checks the list names written EXRs, one line per frame); --no-cvvdp gives
// none; a --check that fails (cvvdp not installed) gives none and its reason in one note; no
// command gives none and a note; a run that fails leaves that sequence's value null, exit 0.
TEST(SequenceCompare, CvvdpColumnFromTheAtrousCvvdpCommand) {
    TempDir dir;
    writeSequence(dir / "ref", 3, 0.0f, false);
    writeSequence(dir / "out", 3, 0.1f, false);
    const std::string exe = "atrous-cvvdp";
    const std::string good = standIn(
        dir, "good", exe,
        "[ \"$1\" = --check ] && { echo 'ColorVideoVDP: ready'; exit 0; }\n"
        "[ \"$1\" = --pairs ] && [ \"$(wc -l < \"$2\")\" -eq 3 ] || exit 3\n"
        "while IFS=\"$(printf '\\t')\" read -r r t; do [ -s \"$r\" ] && [ -s \"$t\" ] || exit 4; done < \"$2\"\n"
        "echo 'JOD: 7.500000'\n");
    const std::string missing =
        standIn(dir, "missing", exe, "echo 'Traceback (most recent call last):'\necho 'cvvdp is not installed in /x/python (pip install cvvdp)'\nexit 3\n");
    const std::string failing = standIn(dir, "failing", exe, "[ \"$1\" = --check ] && exit 0\necho boom\nexit 1\n");
    const std::string path = currentPath();
    auto compare = [&](const std::string& p, const std::string& args) { return compareWith(dir, p, "--no-flip " + args, "cvvdp"); };
    EXPECT_DOUBLE_EQ(compare(good + ":" + path, "").first.get<double>(), 7.5);
    EXPECT_TRUE(compare(good + ":" + path, "--no-cvvdp").first.is_null());
    auto notInstalled = compare(missing + ":/usr/bin:/bin", "");
    EXPECT_TRUE(notInstalled.first.is_null());
    // The note gives the command's last line (a Python error's is what went wrong).
    EXPECT_NE(notInstalled.second.find("note: no CVVDP column: cvvdp is not installed"), std::string::npos)
        << notInstalled.second;
    auto none = compare("/usr/bin:/bin", "");
    EXPECT_TRUE(none.first.is_null());
    EXPECT_NE(none.second.find("atrous-cvvdp command"), std::string::npos) << none.second;
    auto failed = compare(failing + ":/usr/bin:/bin", "");
    EXPECT_TRUE(failed.first.is_null());
    EXPECT_NE(failed.second.find("ColorVideoVDP (" + failing + "/atrous-cvvdp) failed on"), std::string::npos)
        << failed.second;
    // The text table has the column when it runs.
    setenv("PATH", (good + ":" + path).c_str(), 1);
    auto table = runCli("compare --no-flip --sequence " + dir / "ref" + " " + dir / "out");
    setenv("PATH", path.c_str(), 1);
    EXPECT_NE(table.output.find("CVVDP(JOD)"), std::string::npos) << table.output;
    EXPECT_NE(table.output.find("7.5000"), std::string::npos) << table.output;
}

// Helpers shared by the GoogleTest files: temporary directories and running the CLI.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <random>
#include <string>

#include "atrous/image.h"

namespace atrous::test {

// A 3-channel affine ramp, img(x, y, c) = dx·x + dy·y + dc·c + 0.125 (the I/O round-trip tests'
// image: distinct values per pixel and channel for distinct steps).
inline Image rampImage(int w, int h, float dx, float dy, float dc) {
    Image img(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) img(x, y, c) = dx * x + dy * y + dc * c + 0.125f;
    return img;
}

// Any channel count: img(x, y, c) = base + 0.1·c + step·(x + w·y) (the layered-file tests' passes:
// each pass, channel and pixel its own value).
inline Image channelRamp(int w, int h, int channels, float base, float step) {
    Image img(w, h, channels);
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) img(x, y, c) = base + 0.1f * c + step * float(x + w * y);
    return img;
}

// Values drawn uniformly from [lo, hi) with a seeded generator (the row-loop equality tests).
inline Image randomImage(int w, int h, int channels, unsigned seed, float lo, float hi) {
    Image img(w, h, channels);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(lo, hi);
    for (size_t i = 0; i < img.size(); ++i) img.data()[i] = u(rng);
    return img;
}

// Equal size, channels and values bit for bit (the CLI paths that must give the same image).
inline bool sameImages(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() && a.channels() == b.channels() &&
           std::equal(a.data(), a.data() + a.size(), b.data());
}

// A fresh directory under the system temp dir, removed when the object dies.
class TempDir {
public:
    TempDir() {
        std::random_device rd;
        auto base = std::filesystem::temp_directory_path();
        for (;;) {
            mPath = base / ("atrous_test_" + std::to_string(getpid()) + "_" + std::to_string(rd()));
            if (std::filesystem::create_directories(mPath)) break;
        }
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::permissions(mPath, std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ec);
        std::filesystem::remove_all(mPath, ec);
    }
    std::string str() const { return mPath.string(); }
    std::string operator/(const std::string& name) const { return (mPath / name).string(); }
    const std::filesystem::path& path() const { return mPath; }

private:
    std::filesystem::path mPath;
};

struct CliResult {
    int exitCode = -1;
    std::string output;  // stdout and stderr together
};

// Runs a shell command line and captures its output (stdout and stderr) and exit code.
inline CliResult runShell(const std::string& command) {
    const std::string cmd = command + " 2>&1";
    CliResult r;
    FILE* pipe = popen(cmd.c_str(), "r");
    if (!pipe) return r;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
    int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

// The CLI under test: build/atrous, or $ATROUS_TEST_CLI when set (to show that a test fails on
// an older build: ATROUS_TEST_CLI=/path/to/old/atrous build/tests/some_test).
inline std::string cliPath() {
    const char* env = std::getenv("ATROUS_TEST_CLI");
    return env && *env ? env : ATROUS_CLI;
}

// Runs `build/atrous <args>` through the shell and captures its output and exit code.
inline CliResult runCli(const std::string& args) { return runShell(cliPath() + " " + args); }

// runCli, checking the exit code and that the output holds each of `needles`; the result for more.
inline CliResult expectCli(const std::string& args, int exitCode, std::initializer_list<std::string> needles = {}) {
    CliResult r = runCli(args);
    EXPECT_EQ(r.exitCode, exitCode) << args << "\n" << r.output;
    for (const std::string& n : needles) EXPECT_NE(r.output.find(n), std::string::npos) << n << " in\n" << r.output;
    return r;
}

// Counts the entries of a directory (to check that a failed command wrote nothing).
inline int countEntries(const std::string& dir) {
    int n = 0;
    std::error_code ec;
    for (auto it = std::filesystem::directory_iterator(dir, ec); !ec && it != std::filesystem::directory_iterator(); ++it) ++n;
    return n;
}

// `atrous render --frames` of the Cornell box into DIR/seq (1 spp, 32x24, 4-spp references): the
// small sequence the CLI's sequence tests denoise. Returns its path.
inline std::string renderSequence(const TempDir& dir, int frames = 3) {
    const std::string seq = dir / "seq";
    auto r = runCli("render --scene cornell --frames " + std::to_string(frames) +
                    " --spp 1 --width 32 --height 24 --reference-spp 4 --out " + seq);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return seq;
}

}  // namespace atrous::test

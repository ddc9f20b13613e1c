// `atrous view`: headless runs under Xvfb (screenshot size, content, denoised closer to a
// high-spp render than the noisy view, split screen, buffer dumps) and the bad-input paths (no
// display, unknown scene, CUDA without a GPU, bad flags). Every viewer run goes through
// `timeout`, so a hung window cannot hang the suite.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "atrous/device.h"
#include "atrous/image.h"
#include "io/image_io.h"
#include "test_util.h"

using atrous::Image;
using atrous::test::CliResult;
using atrous::test::runCli;
using atrous::test::TempDir;

namespace {

bool viewerBuilt() {
    static const bool built = runCli("view --help").output.find("--screenshot") != std::string::npos;
    return built;
}

bool haveXvfb() { return std::system("command -v xvfb-run > /dev/null 2>&1") == 0; }

// runCli's shape, with the CLI started by xvfb-run inside a hard time limit.
CliResult runUnderXvfb(const std::string& args) {
    std::string cmd = "timeout -k 5 120 xvfb-run -a -s '-screen 0 1024x768x24' " + std::string(ATROUS_CLI) + " " +
                      args + " 2>&1";
    CliResult r;
    FILE* pipe = popen(cmd.c_str(), "r");
    if (!pipe) return r;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof(buf), pipe)) > 0) r.output.append(buf, n);
    const int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

#define REQUIRE_VIEWER_AND_XVFB()                                                      \
    do {                                                                               \
        if (!viewerBuilt()) GTEST_SKIP() << "atrous built without the viewer";         \
        if (!haveXvfb()) GTEST_SKIP() << "xvfb-run is not installed";                  \
    } while (0)

double mse(const Image& a, const Image& b, int x0 = 0, int x1 = -1) {
    if (x1 < 0) x1 = a.width();
    double s = 0;
    long n = 0;
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < a.height(); ++y)
            for (int x = x0; x < x1; ++x) {
                const double d = double(a(x, y, c)) - double(b(x, y, c));
                s += d * d;
                ++n;
            }
    return s / double(n);
}

// Mean squared difference between each pixel and its 3x3 neighbours' mean (columns [x0, x1)):
// high-frequency energy, which is mostly noise in a Cornell box.
double localVariance(const Image& a, int x0 = 0, int x1 = -1) {
    if (x1 < 0) x1 = a.width();
    double s = 0;
    long n = 0;
    for (int c = 0; c < 3; ++c)
        for (int y = 1; y + 1 < a.height(); ++y)
            for (int x = std::max(1, x0); x < std::min(a.width() - 1, x1); ++x) {
                double m = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) m += a(x + dx, y + dy, c);
                const double d = a(x, y, c) - m / 9.0;
                s += d * d;
                ++n;
            }
    return s / double(n);
}

double meanValue(const Image& a) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += a.data()[i];
    return s / double(a.size());
}

const char* kBase = "view --scene cornell --width 128 --height 128 --hide-ui";

}  // namespace

TEST(ViewCli, NoDisplayIsAClearError) {
    if (!viewerBuilt()) GTEST_SKIP() << "atrous built without the viewer";
    TempDir dir;
    const char* display = std::getenv("DISPLAY");
    const std::string saved = display ? display : "";
    unsetenv("DISPLAY");
    unsetenv("WAYLAND_DISPLAY");
    CliResult r = runCli(std::string(kBase) + " --frames 1 --screenshot " + (dir / "s.png"));
    if (display) setenv("DISPLAY", saved.c_str(), 1);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("xvfb-run"), std::string::npos) << r.output;
    EXPECT_EQ(atrous::test::countEntries(dir.str()), 0);
}

TEST(ViewCli, BadInputExitsTwoBeforeOpeningAWindow) {
    if (!viewerBuilt()) GTEST_SKIP() << "atrous built without the viewer";
    TempDir dir;
    const std::string shot = " --frames 1 --screenshot " + (dir / "s.png");
    CliResult r = runCli("view --scene no_such_scene_xyz" + shot);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find("no_such_scene_xyz"), std::string::npos) << r.output;
    r = runCli(std::string(kBase) + " --method bilateral" + shot);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find("bilateral"), std::string::npos) << r.output;
    r = runCli(std::string(kBase) + " --frames 1 --screenshot " + (dir / "s.exr"));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find("--screenshot"), std::string::npos) << r.output;
    r = runCli(std::string(kBase) + " --width 0" + shot);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find("--width"), std::string::npos) << r.output;
    if (!atrous::cudaAvailable()) {
        r = runCli(std::string(kBase) + " --device cuda" + shot);
        EXPECT_EQ(r.exitCode, 2);
        EXPECT_NE(r.output.find("--device cuda"), std::string::npos) << r.output;
    }
    EXPECT_EQ(atrous::test::countEntries(dir.str()), 0);
}

TEST(ViewHeadless, DenoisedScreenshotIsCloserToTheReferenceThanTheNoisyOne) {
    REQUIRE_VIEWER_AND_XVFB();
    TempDir dir;
    // Reference: 16 accumulated frames of 16 spp = 256 spp (64x the 4-spp views below).
    CliResult r = runUnderXvfb(std::string(kBase) + " --method none --frames 16 --spp 16 --seed 101 --screenshot " +
                               (dir / "ref.png"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (const char* m : {"none", "eaw", "svgf"}) {
        r = runUnderXvfb(std::string(kBase) + " --method " + m + " --seed 3 --frames 4 --screenshot " + (dir / (std::string(m) + ".png")));
        ASSERT_EQ(r.exitCode, 0) << m << ": " << r.output;
        // Headless runs print one JSON line of timings.
        EXPECT_NE(r.output.find("\"frame_ms_median\""), std::string::npos) << r.output;
    }
    const Image ref = atrous::io::readImage(dir / "ref.png");
    const Image noisy = atrous::io::readImage(dir / "none.png");
    const Image eaw = atrous::io::readImage(dir / "eaw.png");
    const Image svgf = atrous::io::readImage(dir / "svgf.png");
    for (const Image* img : {&ref, &noisy, &eaw, &svgf}) {
        ASSERT_EQ(img->width(), 128);
        ASSERT_EQ(img->height(), 128);
        // Not blank: a lit Cornell box has a clearly non-zero mean and structure (walls, boxes).
        EXPECT_GT(meanValue(*img), 0.05);
        EXPECT_GT(localVariance(*img), 1e-5);
    }
    const double mNoisy = mse(noisy, ref), mEaw = mse(eaw, ref), mSvgf = mse(svgf, ref);
    const double lNoisy = localVariance(noisy), lEaw = localVariance(eaw), lSvgf = localVariance(svgf);
    std::printf("vs 256-spp reference (display-linear): MSE noisy %.5f eaw %.5f svgf %.5f; local variance noisy %.5f "
                "eaw %.5f svgf %.5f ref %.5f\n",
                mNoisy, mEaw, mSvgf, lNoisy, lEaw, lSvgf, localVariance(ref));
    // EAW on the 4-frame running mean: measured MSE ratio 0.60 (seeds fixed, so deterministic); the
    // bound leaves room for filter tuning but fails when the filter does nothing (ratio 1).
    EXPECT_LT(mEaw, 0.8 * mNoisy);
    // SVGF filters this frame's 1 spp with only 4 frames of history, so its MSE is close to the
    // 4-spp mean's (measured ratio 0.94: edge and light-silhouette bias); what it must do is remove
    // the noise. The reference's own local variance is the signal's (edges, 256-spp residue); the
    // excess above it is noise: measured excess ratios 0.17 (EAW) and 0.22 (SVGF).
    const double lRef = localVariance(ref);
    EXPECT_LT(lEaw - lRef, 0.4 * (lNoisy - lRef));
    EXPECT_LT(lSvgf - lRef, 0.4 * (lNoisy - lRef));
    // No darkening: the mean stays within 10% of the reference's (tonemapped, so a loose bound).
    EXPECT_NEAR(meanValue(eaw), meanValue(ref), 0.1 * meanValue(ref));
    EXPECT_NEAR(meanValue(svgf), meanValue(ref), 0.1 * meanValue(ref));
}

TEST(ViewHeadless, SplitScreenAndBufferDump) {
    REQUIRE_VIEWER_AND_XVFB();
    TempDir dir;
    const std::string dump = dir / "buffers";
    CliResult r = runUnderXvfb(std::string(kBase) + " --method eaw --compare none --frames 3 --screenshot " +
                               (dir / "split.png") + " --dump " + dump);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const Image s = atrous::io::readImage(dir / "split.png");
    ASSERT_EQ(s.width(), 128);
    // Left half EAW, right half noisy: the left is far smoother (noise dominates the local variance
    // at 3 spp; the box edges are present in both halves).
    EXPECT_LT(localVariance(s, 0, 60), 0.5 * localVariance(s, 68, 128));
    for (const char* f : {"color.exr", "variance.exr", "albedo.exr", "normal.exr", "position.exr", "depth.exr", "ids.exr",
                          "denoised_a_eaw.exr"})
        EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(dump) / f)) << f;
    const Image color = atrous::io::readImage((std::filesystem::path(dump) / "color.exr").string());
    EXPECT_EQ(color.width(), 128);
    EXPECT_GT(meanValue(color), 0.01);
}

TEST(ViewHeadless, SureFractionsAndDetailBuffers) {
    REQUIRE_VIEWER_AND_XVFB();
    TempDir dir;
    const std::string d1 = dir / "sure", d2 = dir / "detail";
    CliResult r = runUnderXvfb("view --scene cornell --width 64 --height 64 --hide-ui --method sure --buffer sure-s "
                               "--frames 2 --dump " + d1);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (int l = 0; l < 5; ++l) {
        const std::string f = (std::filesystem::path(d1) / ("sure_s_level" + std::to_string(l) + ".exr")).string();
        ASSERT_TRUE(std::filesystem::exists(f)) << f;
        const Image s = atrous::io::readImage(f);
        float lo = 1e9f, hi = -1e9f;
        for (size_t i = 0; i < s.size(); ++i) lo = std::min(lo, s.data()[i]), hi = std::max(hi, s.data()[i]);
        EXPECT_GE(lo, 0.0f);  // fractions s_i in [0, 1]
        EXPECT_LE(hi, 1.0f);
    }
    r = runUnderXvfb("view --scene cornell --width 64 --height 64 --hide-ui --method eaw --buffer detail --frames 2 --dump " + d2);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string f = (std::filesystem::path(d2) / "detail_level0.exr").string();
    ASSERT_TRUE(std::filesystem::exists(f)) << f;
    // d_0 = c_0 - c_1 carries the finest noise: clearly non-zero at 2 spp.
    const Image d = atrous::io::readImage(f);
    double e = 0;
    for (size_t i = 0; i < d.size(); ++i) e += std::fabs(d.data()[i]);
    EXPECT_GT(e / double(d.size()), 1e-3);
}

// The reference-free flicker measure (metrics.h computeFlicker, `atrous compare --sequence` without a
// reference; issue 49): each frame against the one before it, warped by the motion vectors where the
// temporal filter's reprojection test holds. A texture slides one pixel a frame; a steady sequence of
// it has no flicker, one whose brightness alternates has, and a disocclusion (another id) is left out.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "atrous/error.h"
#include "atrous/io/image_io.h"
#include "atrous/metrics.h"
#include "test_util.h"

using namespace atrous;
using namespace atrous::test;
namespace fs = std::filesystem;

namespace {

constexpr int kW = 32, kH = 20;

// Frame t of a texture that moves +1 pixel in x per frame, times `gain`.
Image texture(int t, float gain) {
    Image img(kW, kH, 3);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int c = 0; c < 3; ++c) {
                const float u = float(x - t);
                img(x, y, c) = gain * (0.4f + 0.25f * std::sin(0.7f * u + 0.3f * c) * std::cos(0.5f * y));
            }
    return img;
}

// The frame's G-buffer: motion (previous - current) = (-1, 0); a wall at depth 5 facing the camera;
// ids 1, except a column band (x < `occluded`) of id 2: a surface that was not there before.
struct Gbuffer {
    Image motion{kW, kH, 2}, depth{kW, kH, 1}, normal{kW, kH, 3}, ids{kW, kH, 2};
    explicit Gbuffer(int occluded = 0) {
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                motion(x, y, 0) = -1.0f;
                depth(x, y, 0) = 5.0f;
                normal(x, y, 2) = 1.0f;
                ids(x, y, 0) = x < occluded ? 2.0f : 1.0f;
            }
    }
    Frame frame() const {
        Frame f;
        f.motion = &motion, f.depth = &depth, f.normal = &normal, f.ids = &ids;
        return f;
    }
};

// A sequence of 6 frames: frame_000t.exr (colour only, as `denoise --sequence` writes them), or with
// `withBuffers` frame_000t/ folders with every buffer the measure reads.
void writeSequence(const std::string& dir, bool flicker, bool withBuffers) {
    fs::create_directories(dir);
    const Gbuffer g;
    for (int t = 1; t <= 6; ++t) {
        const Image c = texture(t, flicker && t % 2 ? 1.25f : 1.0f);
        if (!withBuffers) {
            atrous::writeImage(dir + "/frame_000" + std::to_string(t) + ".exr", c);
            continue;
        }
        const std::string f = dir + "/frame_000" + std::to_string(t);
        fs::create_directories(f);
        atrous::writeImage(f + "/color.exr", c);
        Image m(kW, kH, 3), ids(kW, kH, 3);
        for (int i = 0; i < kW * kH; ++i) m.data()[i] = g.motion.data()[i], ids.data()[i] = g.ids.data()[i];
        atrous::writeImage(f + "/motion.exr", m);
        atrous::writeImage(f + "/depth.exr", g.depth);
        atrous::writeImage(f + "/normal.exr", g.normal);
        atrous::writeImage(f + "/ids.exr", ids);
    }
}

}  // namespace

TEST(Flicker, SteadyMotionHasNoneAlternatingBrightnessHas) {
    const Gbuffer g;
    // The texture moved exactly by its motion vectors: the warp is exact (integer motion, one tap).
    const FlickerMetrics steady = computeFlicker(texture(2, 1.0f), texture(1, 1.0f), g.frame(), g.frame());
    EXPECT_LT(steady.relMse, 1e-12);
    // Every pixel but the first column (whose predecessor is outside the image) reprojects.
    EXPECT_NEAR(steady.reprojected, double(kW - 1) / kW, 1e-9);
    // 25% brighter: d = 0.25 x, m = 1.125 x, so d² / (m² + 0.01) is just under (0.25 / 1.125)² = 0.049.
    const FlickerMetrics flicker = computeFlicker(texture(2, 1.25f), texture(1, 1.0f), g.frame(), g.frame());
    EXPECT_GT(flicker.relMse, 0.03);
    EXPECT_LT(flicker.relMse, 0.0494);
    // A surface that was not there (another id than the predecessor's) is not compared.
    const Gbuffer now(8), before;
    const FlickerMetrics disoccluded = computeFlicker(texture(2, 1.25f), texture(1, 1.0f), now.frame(), before.frame());
    EXPECT_NEAR(disoccluded.reprojected, double(kW - 8) / kW, 1e-9);
    // Without motion there is nothing to warp by: an error, not a number.
    Frame none;
    EXPECT_THROW(computeFlicker(texture(2, 1.0f), texture(1, 1.0f), none, none), InputError);
}

TEST(Flicker, CompareRanksSequencesWithoutAReference) {
    TempDir dir;
    writeSequence(dir / "input", false, true);  // what was denoised: its buffers place the frames
    writeSequence(dir / "steady", false, false);
    writeSequence(dir / "flicker", true, false);
    // One sequence with its own motion vectors: the measure, printed, exit 0.
    expectCli("compare --sequence " + dir / "input", 0, {"no reference: flicker", "reprojected"});
    // Two denoisers' outputs, placed by the input's buffers: the flickering one ranks last.
    const CliResult r = expectCli("compare --json --no-reference --input " + dir / "input" + " --sequence " + dir / "flicker" +
                                      " " + dir / "steady",
                                  0);
    const nlohmann::json j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
    ASSERT_EQ(j["ranking"].size(), 2u);
    EXPECT_EQ(j["ranking"][0], dir / "steady");
    EXPECT_EQ(j["ranking"][1], dir / "flicker");
    EXPECT_TRUE(j["reference"].is_null());
    EXPECT_LT(j["sequences"][1]["flicker"].get<double>(), 1e-10);
    EXPECT_GT(j["sequences"][0]["flicker"].get<double>(), 0.03);
    EXPECT_GT(j["sequences"][0]["reprojected"].get<double>(), 0.9);
    expectCli("compare --no-reference --input " + dir / "input" + " --sequence " + dir / "flicker" + " " + dir / "steady", 0,
              {"ranking (least flicker first): " + dir / "steady" + ", " + dir / "flicker"});
    // Without --input, a colour-only sequence's motion is estimated from its colours (a note says so).
    expectCli("compare --sequence " + dir / "steady", 0, {"motion estimated from its colours"});
    // With a reference, the flicker is a column beside the temporal error, and the reference's own is its floor.
    const CliResult withRef = expectCli("compare --json --no-flip --no-cvvdp --input " + dir / "input" + " --sequence " +
                                            dir / "steady" + " " + dir / "flicker",
                                        0);
    const nlohmann::json k = nlohmann::json::parse(withRef.output.substr(withRef.output.find('{')));
    EXPECT_LT(k["reference_flicker"].get<double>(), 1e-10);
    EXPECT_GT(k["sequences"][0]["flicker"].get<double>(), 0.03);
    // A guide without the judged frames' numbers: one line naming them.
    writeSequence(dir / "short", false, true);
    fs::remove_all(dir / "short/frame_0006");
    expectCli("compare --no-reference --input " + dir / "short" + " --sequence " + dir / "steady", 2,
              {"frame 6 has no frame of that number in " + dir / "short"});
}

// Motion from the Position pass (include/atrous/temporal.h, src/filters/camera_fit.cpp): a known
// pinhole camera is recovered from its own pixels' world positions (jittered as a 1-spp render's
// are), motion between two known cameras is recovered on geometry and on the sky, and the CLI uses
// it for a sequence without motion vectors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "atrous/metrics.h"
#include "atrous/temporal.h"
#include "atrous/io/image_io.h"
#include "test_util.h"

using namespace atrous;
namespace fs = std::filesystem;

namespace {

struct Cam {
    double f = 90, cx = 40, cy = 30;  // pixels
    double yaw = 0, px = 0, py = 0.5, pz = 0;  // rotation about +y (radians), centre
    // World point -> pixel (centres at integer coordinates); false behind the camera.
    bool project(const double P[3], double& u, double& v) const {
        const double X = P[0] - px, Y = P[1] - py, Z = P[2] - pz;
        const double c = std::cos(yaw), s = std::sin(yaw);
        const double xc = c * X - s * Z, zc = s * X + c * Z;
        if (zc <= 0) return false;
        u = cx + f * xc / zc, v = cy - f * Y / zc;
        return true;
    }
    // The ray through pixel (u, v): direction in world space.
    void ray(double u, double v, double d[3]) const {
        const double xc = (u - cx) / f, yc = -(v - cy) / f, zc = 1;
        const double c = std::cos(yaw), s = std::sin(yaw);
        d[0] = c * xc + s * zc, d[1] = yc, d[2] = -s * xc + c * zc;
    }
};

// 80x60 Position pass of a floor (y = 0) and a wall (z = 6, up to y = 2), sky above: one jittered
// sample per pixel, 0 where the ray hits nothing. distortion > 0: a lens that is no pinhole (pixel
// p sees the pinhole's ray through c + (p - c)(1 + distortion |p - c|²)).
Image positions(const Cam& cam, unsigned seed, double distortion = 0) {
    Image p(80, 60, 3);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> jitter(-0.5, 0.5);
    for (int y = 0; y < p.height(); ++y)
        for (int x = 0; x < p.width(); ++x) {
            double d[3], u = x + jitter(rng), v = y + jitter(rng);
            const double k = 1 + distortion * ((u - cam.cx) * (u - cam.cx) + (v - cam.cy) * (v - cam.cy));
            cam.ray(cam.cx + (u - cam.cx) * k, cam.cy + (v - cam.cy) * k, d);
            double best = 1e30;
            if (d[1] < 0) best = std::min(best, -cam.py / d[1]);
            if (d[2] > 0) {
                const double t = (6 - cam.pz) / d[2];
                if (cam.py + t * d[1] <= 2.0) best = std::min(best, t);
            }
            if (best == 1e30) continue;
            p(x, y, 0) = float(cam.px + best * d[0]), p(x, y, 1) = float(cam.py + best * d[1]);
            p(x, y, 2) = float(cam.pz + best * d[2]);
        }
    return p;
}

}  // namespace

TEST(CameraFit, RecoversAPinholeCameraFromItsPositions) {
    Cam cam;
    cam.yaw = 0.2, cam.px = 0.3;
    const CameraFit fit = fitCamera(positions(cam, 1));
    ASSERT_TRUE(fit.ok);
    EXPECT_GT(fit.medianErrorPx, 0.2);  // the 1-spp jitter: about 0.38 px for a uniform square
    EXPECT_LT(fit.medianErrorPx, 0.5);
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> any(-2, 2);
    int tried = 0;
    for (int i = 0; i < 1000; ++i) {  // points that the camera sees (a fit is not made to extrapolate)
        const double P[3] = {any(rng), any(rng) + 1, 4 + any(rng)};
        double u, v, fu, fv;
        if (!cam.project(P, u, v) || u < 0 || v < 0 || u > 79 || v > 59) continue;
        ++tried;
        ASSERT_TRUE(fit.project(P, fu, fv));
        EXPECT_NEAR(fu, u, 0.1);  // 1-spp jitter of +-0.5 px over ~2000 points: a few hundredths, more at the edges
        EXPECT_NEAR(fv, v, 0.1);
    }
    EXPECT_GT(tried, 100);
    // A flat world (every point on one plane) does not determine a camera: not ok.
    Image flat(80, 60, 3);
    for (int y = 0; y < 60; ++y)
        for (int x = 0; x < 80; ++x) flat(x, y, 0) = float(x), flat(x, y, 1) = float(y), flat(x, y, 2) = 5;
    EXPECT_FALSE(fitCamera(flat).ok);
    EXPECT_FALSE(fitCamera(Image(80, 60, 3)).ok);  // nothing hit
    // A strongly distorted lens is no pinhole: the fit's median error is over the bound, not ok.
    const CameraFit bent = fitCamera(positions(cam, 5, 2e-4));
    EXPECT_FALSE(bent.ok) << bent.medianErrorPx;
    EXPECT_GT(bent.medianErrorPx, kCameraFitMaxErrorPx);
}

// The camera turns and moves between frames: on the floor and the wall the motion is the point's
// (previous projection - current, the sample's jitter cancelled), on the sky the direction's,
// within 0.1 px.
TEST(CameraFit, MotionBetweenTwoCamerasOnGeometryAndSky) {
    Cam prev, cur;
    prev.yaw = 0.15, prev.px = -0.2;
    cur.yaw = 0.2, cur.px = 0.0;
    const Image pos = positions(cur, 3);
    const Image motion = motionFromPositions(pos, fitCamera(pos), fitCamera(positions(prev, 4)));
    int geometry = 0, sky = 0;
    for (int y = 0; y < 60; ++y)
        for (int x = 0; x < 80; ++x) {
            const double P[3] = {pos(x, y, 0), pos(x, y, 1), pos(x, y, 2)};
            double want[2];
            if (P[0] != 0 || P[1] != 0 || P[2] != 0) {
                double u0, v0, u1, v1;
                ASSERT_TRUE(prev.project(P, u0, v0) && cur.project(P, u1, v1));
                want[0] = u0 - u1, want[1] = v0 - v1;
                ++geometry;
            } else {
                double d[3], u0, v0;
                cur.ray(x, y, d);
                const double far[3] = {prev.px + 1e7 * d[0], prev.py + 1e7 * d[1], prev.pz + 1e7 * d[2]};
                ASSERT_TRUE(prev.project(far, u0, v0));
                want[0] = u0 - x, want[1] = v0 - y;
                ++sky;
            }
            // The fits' error (a few hundredths of a pixel from the samples' jitter, most in the corners).
            EXPECT_NEAR(motion(x, y, 0), want[0], 0.1) << x << "," << y;
            EXPECT_NEAR(motion(x, y, 1), want[1], 0.1) << x << "," << y;
        }
    EXPECT_GT(geometry, 1000);
    EXPECT_GT(sky, 100);
    // Without a previous camera there is no motion: NaN (no history) everywhere.
    const Image none = motionFromPositions(pos, fitCamera(pos), CameraFit{});
    EXPECT_TRUE(std::isnan(none(40, 50, 0)));
}

// An atrous sequence rendered into DIR/seq with references, and what `denoise --sequence` does
// with it: the mean over its frames of the relMSE against the references.
struct CliSequence {
    test::TempDir dir;
    std::string seq = dir / "seq";
    int frames;
    CliSequence(const std::string& scene, const std::string& path, int n, int spp, int w, int h, int refSpp)
        : frames(n) {
        const auto r = test::runCli("render --scene " + scene + " --camera-path " + path + " --frames " + std::to_string(n) +
                                    " --spp " + std::to_string(spp) + " --width " + std::to_string(w) + " --height " +
                                    std::to_string(h) + " --reference-spp " + std::to_string(refSpp) + " --quiet --out " + seq);
        EXPECT_EQ(r.exitCode, 0) << r.output;
    }
    std::string frame(int f) const { return seq + "/frame_000" + std::to_string(f); }
    void remove(const char* file) const {
        for (int f = 0; f < frames; ++f) fs::remove(frame(f) + "/" + file);
    }
    // Denoises with the temporal method and EAW after the average into DIR/name; the log.
    std::string denoise(const std::string& name) const {
        const auto r = test::runCli("denoise --sequence " + seq + " --spatial eaw --out " + (dir / name));
        EXPECT_EQ(r.exitCode, 0) << r.output;
        return r.output;
    }
    double relmse(const std::string& name) const {
        double sum = 0;
        for (int f = 0; f < frames; ++f)
            sum += computeMetrics(atrous::readImage(dir / name + "/frame_000" + std::to_string(f) + ".exr"),
                                  atrous::readImage(frame(f) + "/reference.exr"))
                       .relMse;
        return sum / frames;
    }
    // All-zero motion vectors: the frames taken as still.
    void zeroMotion(int w, int h) const {
        for (int f = 0; f < frames; ++f) atrous::writeImage(frame(f) + "/motion.exr", Image(w, h, 3));
    }
};

// A sequence whose frames lost their motion.exr: `denoise --sequence` fits the cameras to the
// position.exr, says so, and gives what the motion vectors give (within 10%); without the Position
// pass too, motion estimated from the colours, within 10% of the fitted cameras and of zero
// vectors on this small orbit (2026-12-04: vectors 0.0242, fitted 0.0250, estimated 0.0259, zero
// vectors 0.0261); the dolly below is where the estimate matters.
TEST(CameraFitCli, SequenceWithoutVectorsUsesThePositionPass) {
    const CliSequence s("cornell-spheres", "orbit", 7, 4, 64, 48, 256);
    s.denoise("vectors");
    s.remove("motion.exr");
    std::string log = s.denoise("fitted");
    EXPECT_NE(log.find("motion from the Position pass"), std::string::npos) << log;
    s.remove("position.exr");
    log = s.denoise("estimated");
    EXPECT_NE(log.find("motion estimated from the frames' colours"), std::string::npos) << log;
    s.zeroMotion(64, 48);
    s.denoise("still");
    const double vectors = s.relmse("vectors"), fitted = s.relmse("fitted"), estimated = s.relmse("estimated"),
                 still = s.relmse("still");
    const std::string all = std::to_string(vectors) + " " + std::to_string(fitted) + " " + std::to_string(estimated) +
                            " " + std::to_string(still);
    std::printf("relMSE: vectors, fitted, estimated, still: %s\n", all.c_str());
    EXPECT_LT(fitted, 1.1 * vectors) << all;
    EXPECT_LT(estimated, 1.1 * fitted) << all;
    EXPECT_LT(estimated, 1.1 * still) << all;
}

// A dolly (the camera moves toward the scene: everything on screen moves outward) with neither
// motion vectors nor a Position pass: taking the frames as still (zero vectors) averages what
// moved; the motion estimated from the colours follows it. 2026-12-04: relMSE 0.061 against 0.397
// (96x72, 2 spp, 6 frames, EAW after the average); the bound is half.
TEST(CameraFitCli, ADollyWithoutVectorsOrPositionsUsesTheColoursMotion) {
    const CliSequence s("cornell-spheres", "dolly", 6, 2, 96, 72, 128);
    s.remove("motion.exr");
    s.remove("position.exr");
    s.denoise("estimated");
    s.zeroMotion(96, 72);
    s.denoise("still");
    EXPECT_LT(s.relmse("estimated"), 0.5 * s.relmse("still")) << s.relmse("estimated") << " " << s.relmse("still");
}

// Animation: camera paths, moving objects, motion vectors (exact reprojection), the emission
// buffer, and `atrous render --frames` (frame folders, bad input).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "atrous/error.h"
#include "atrous/render.h"
#include "core/sampler.h"
#include "atrous/io/image_io.h"
#include "render/animation.h"
#include "render/camera.h"
#include "render/scene_data.h"
#include "test_util.h"

namespace atrous {
namespace {

namespace fs = std::filesystem;
using test::countEntries;
using test::runCli;
using test::TempDir;

constexpr int kW = 64, kH = 48;

RenderSettings smallSettings(uint32_t seed = 5) {
    RenderSettings s;
    s.width = kW;
    s.height = kH;
    s.spp = 1;  // one sample: the position buffer is exactly that sample's primary hit
    s.maxDepth = 1;
    s.seed = seed;
    s.threads = 2;
    return s;
}

// Reprojection error in pixels of pixel (x, y): the camera sample's image position (replayed from
// the renderer's RNG stream) plus the motion vector must be where the previous camera sees the
// point `prevPoint`. Measured with the forward camera mapping (cameraRayDirection), independent of
// the inverse projection the renderer uses: the angle between the two rays times the focal length
// in pixels.
double reprojectionErrorPx(const pt::Camera& prevCam, Vec3 prevPoint, const Image& motion, int x, int y, uint32_t seed) {
    Vec2 j = stratifiedPixelJitter(uint32_t(y) * kW + uint32_t(x), 0u, seed);  // sample 0's position
    float jx = j.x, jy = j.y;
    float px = float(x) + jx + motion(x, y, 0), py = float(y) + jy + motion(x, y, 1);
    Vec3 want = normalize(prevPoint - prevCam.position);
    Vec3 got = pt::cameraRayDirection(prevCam, px, py, kW, kH);
    double focalPx = 0.5 * kH / prevCam.tanHalfFov;
    return double(length(want - got)) * focalPx;
}

TEST(Animation, StaticCameraAndSceneGiveZeroMotion) {
    Scene scene = Scene::builtin("cornell");
    RenderBuffers b = renderFrame(scene, CameraPath::Static, 0.6f, 0.3f, smallSettings());
    ASSERT_FALSE(b.motion.empty());
    float worst = 0.0f;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(b.motion(x, y, c)));
    // Reprojecting with an unchanged camera only sees float rounding (~1e-5 px at this size).
    EXPECT_LT(worst, 1e-3f);
    // A still render has no motion buffer at all.
    EXPECT_TRUE(render(scene, smallSettings()).motion.empty());
}

TEST(Animation, DollyMotionReprojectsStaticPointsExactly) {
    Scene scene = Scene::builtin("cornell");
    const float t = 0.75f, tPrev = 0.5f;
    const uint32_t seed = 9;
    RenderBuffers b = renderFrame(scene, CameraPath::Dolly, t, tPrev, smallSettings(seed));
    pt::Camera prev = pt::cameraAtTime(scene.data(), CameraPath::Dolly, tPrev);
    pt::Camera now = pt::cameraAtTime(scene.data(), CameraPath::Dolly, t);
    // The dolly moved the camera along its axis by a known amount: 1/4 of 0.25 * the target distance.
    float dist = length(scene.data().cameraTarget - scene.data().camera.position);
    EXPECT_NEAR(length(now.position - prev.position), 0.25f * pt::kDollyFraction * dist, 1e-4f);
    int checked = 0;
    double worst = 0.0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            if (b.ids(x, y, 0) < 0) continue;
            Vec3 p(b.position(x, y, 0), b.position(x, y, 1), b.position(x, y, 2));
            worst = std::max(worst, reprojectionErrorPx(prev, p, b.motion, x, y, seed));
            ++checked;
        }
    EXPECT_GT(checked, kW * kH / 2);
    EXPECT_LT(worst, 0.01) << "required accuracy: 0.01 px";
    // And the motion is not trivially zero: a dolly-in makes points move towards the centre.
    EXPECT_GT(std::fabs(b.motion(2, kH / 2, 0)), 0.3f);
}

TEST(Animation, MovingObjectMotionUsesItsPreviousTransform) {
    Scene scene = Scene::builtin("cornell-moving");
    ASSERT_TRUE(scene.hasMovingObjects());
    const int sphere = scene.meshId("moving_sphere"), box = scene.meshId("short_box");
    ASSERT_GE(sphere, 0);
    ASSERT_GE(box, 0);
    const float t = 0.5f, tPrev = 0.4f;
    const uint32_t seed = 4;
    RenderBuffers b = renderFrame(scene, CameraPath::Orbit, t, tPrev, smallSettings(seed));
    pt::Camera prev = pt::cameraAtTime(scene.data(), CameraPath::Orbit, tPrev);
    int onSphere = 0, onBox = 0;
    double worst = 0.0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            int mesh = int(b.ids(x, y, 0));
            Vec3 p(b.position(x, y, 0), b.position(x, y, 1), b.position(x, y, 2));
            Vec3 before;
            if (mesh == sphere) {
                // The sphere slides by (-3, 0, 0) over t in [0, 1].
                before = p + Vec3(-3.0f * (tPrev - t), 0.0f, 0.0f);
                ++onSphere;
            } else if (mesh == box) {
                // The box turns 40 degrees about the vertical axis through (1.855, *, 1.69).
                double a = 40.0 * (tPrev - t) * M_PI / 180.0;
                double dx = p.x - 1.855, dz = p.z - 1.69;
                before = Vec3(float(1.855 + std::cos(a) * dx + std::sin(a) * dz), p.y,
                              float(1.69 - std::sin(a) * dx + std::cos(a) * dz));
                ++onBox;
            } else {
                continue;
            }
            worst = std::max(worst, reprojectionErrorPx(prev, before, b.motion, x, y, seed));
        }
    EXPECT_GT(onSphere, 10);
    EXPECT_GT(onBox, 10);
    EXPECT_LT(worst, 0.01) << "required accuracy: 0.01 px";
}

TEST(Animation, EmissionBufferHoldsTheVisibleLight) {
    RenderBuffers b = render(Scene::builtin("cornell"), smallSettings());
    ASSERT_FALSE(b.emission.empty());
    int lit = 0, other = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            if (b.emission(x, y, 0) == 17.0f && b.emission(x, y, 1) == 12.0f && b.emission(x, y, 2) == 4.0f) ++lit;
            else if (b.emission(x, y, 0) == 0.0f && b.emission(x, y, 1) == 0.0f && b.emission(x, y, 2) == 0.0f) ++other;
        }
    EXPECT_GT(lit, 0);                 // the ceiling light is in view
    EXPECT_EQ(lit + other, kW * kH);   // 1 spp: exactly the light's radiance or nothing
}

TEST(Animation, CameraPaths) {
    // Keep the Scene alive: data() is a reference into it (a reference into the temporary read
    // freed memory under ASan).
    const Scene scene = Scene::builtin("cornell");
    const pt::SceneData& d = scene.data();
    // Orbit: t = 1/2 is the rest camera; the ends are +-10 degrees about the target's vertical axis.
    pt::Camera mid = pt::cameraAtTime(d, CameraPath::Orbit, 0.5f);
    EXPECT_NEAR(length(mid.position - d.camera.position), 0.0f, 1e-5f);
    pt::Camera end = pt::cameraAtTime(d, CameraPath::Orbit, 1.0f);
    Vec3 a = d.camera.position - d.cameraTarget, c = end.position - d.cameraTarget;
    a.y = c.y = 0.0f;
    EXPECT_NEAR(std::acos(dot(normalize(a), normalize(c))) * 180.0 / M_PI, 0.5 * pt::kOrbitSweepDeg, 1e-2);
    // Static: always the rest camera.
    EXPECT_EQ(pt::cameraAtTime(d, CameraPath::Static, 0.9f).position.z, d.camera.position.z);
    EXPECT_THROW(pt::cameraAtTime(d, CameraPath::Keyframes, 0.5f), InputError);
    EXPECT_THROW(parseCameraPath("spiral"), InputError);
}

const char* kKeyframedScene = R"({
  "camera": {"position": [0, 1, 5], "lookAt": [0, 1, 0], "fov": 40,
             "keyframes": [{"t": 0, "position": [0, 1, 5], "target": [0, 1, 0]},
                           {"t": 0.5, "position": [1, 1, 5], "target": [0, 1, 0], "fov": 50},
                           {"t": 1, "position": [2, 1, 5], "target": [0, 1, 0]}]},
  "materials": {"white": {"albedo": 0.8}},
  "objects": [{"type": "sphere", "name": "ball", "center": [0, 1, 0], "radius": 1, "material": "white",
               "motion": {"translate": [0, 2, 0]}}],
  "lights": [{"type": "environment", "color": [1, 1, 1]}]
})";

TEST(Animation, KeyframesInterpolateSmoothlyThroughTheKeys) {
    Scene s = Scene::parse(kKeyframedScene, ".", "anim.json");
    ASSERT_TRUE(s.hasCameraKeyframes());
    ASSERT_TRUE(s.hasMovingObjects());
    // Through the keys exactly; evenly spaced collinear keys give a straight, uniform path.
    EXPECT_NEAR(pt::cameraAtTime(s.data(), CameraPath::Auto, 0.0f).position.x, 0.0f, 1e-6f);
    EXPECT_NEAR(pt::cameraAtTime(s.data(), CameraPath::Auto, 0.5f).position.x, 1.0f, 1e-5f);
    EXPECT_NEAR(pt::cameraAtTime(s.data(), CameraPath::Auto, 0.25f).position.x, 0.5f, 1e-5f);
    EXPECT_NEAR(pt::cameraAtTime(s.data(), CameraPath::Auto, 1.0f).position.x, 2.0f, 1e-6f);
    EXPECT_NEAR(pt::cameraAtTime(s.data(), CameraPath::Auto, 0.5f).tanHalfFov, std::tan(25.0 * M_PI / 180.0), 1e-5);
    // The sphere moves with t; posing twice is refused.
    Scene posed = s.atTime(0.5f, CameraPath::Auto);
    EXPECT_NEAR(posed.data().spheres[0].center.y, 2.0f, 1e-6f);
    EXPECT_THROW(posed.atTime(0.5f, CameraPath::Auto), InputError);
}

TEST(Animation, BadKeyframesAreInputErrors) {
    auto bad = [](const std::string& keyframes) {
        std::string text = std::string(R"({"camera": {"position": [0, 1, 5], "lookAt": [0, 1, 0], "keyframes": )") +
                           keyframes + R"(}, "objects": []})";
        try {
            Scene::parse(text, ".", "bad.json");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(bad("[]").find("camera.keyframes"), std::string::npos);
    EXPECT_NE(bad(R"([{"t": 0, "target": [0, 0, 0]}])").find("\"position\""), std::string::npos);
    EXPECT_NE(bad(R"([{"t": 0.5, "position": [0,1,5], "target": [0,1,0]}, {"t": 0.5, "position": [1,1,5], "target": [0,1,0]}])")
                  .find("keyframes[1]"),
              std::string::npos);
    EXPECT_NE(bad(R"([{"t": 0, "position": [0,1,5], "target": [0,1,5]}])").find("\"target\""), std::string::npos);
}

TEST(AnimationCli, WritesOneFolderPerFrameWithEveryBuffer) {
    TempDir tmp;
    auto r = runCli("render --scene cornell-moving --frames 3 --spp 1 --reference-spp 2 --width 16 --height 12 "
                    "--camera-path orbit --threads 1 --out " + tmp.str());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(countEntries(tmp.str()), 3);
    for (const char* frame : {"frame_0000", "frame_0001", "frame_0002"}) {
        for (const char* f : {"color.exr", "albedo.exr", "normal.exr", "position.exr", "depth.exr", "ids.exr",
                              "motion.exr", "emission.exr", "reference.exr", "color.png"})
            EXPECT_TRUE(fs::exists(tmp.path() / frame / f)) << frame << "/" << f;
        // 1 spp: no variance.exr (unknown at one sample; a zero one would read as noise-free).
        EXPECT_EQ(countEntries((tmp.path() / frame).string()), 10);
    }
    Image m0 = atrous::readImage((tmp.path() / "frame_0000" / "motion.exr").string());
    Image m1 = atrous::readImage((tmp.path() / "frame_0001" / "motion.exr").string());
    EXPECT_EQ(m0(8, 6, 0), 0.0f);  // frame 0 has no previous frame
    EXPECT_NE(m1(8, 6, 0), 0.0f);  // the orbit moves everything sideways
}

TEST(AnimationCli, WritesVarianceFromTwoSamples) {
    TempDir tmp;
    auto r = runCli("render --scene cornell --frames 1 --spp 2 --width 8 --height 8 --threads 1 --out " + tmp.str());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(fs::exists(tmp.path() / "frame_0000" / "variance.exr"));
    EXPECT_FALSE(fs::exists(tmp.path() / "frame_0000" / "reference.exr"));  // no --reference-spp
}

TEST(AnimationCli, BadInputExitsTwoWithOneLineAndWritesNothing) {
    TempDir tmp;
    const std::string out = tmp / "out";
    std::ofstream(tmp / "bad.json") << R"({"camera": {"position": [0, 1, 5], "lookAt": [0, 1, 0],
        "keyframes": [{"t": 1, "position": [0, 1, 5], "target": [0, 1, 0]}, {"t": 0, "position": [0, 1, 4], "target": [0, 1, 0]}]},
        "objects": []})";
    struct Case {
        std::string args, mentions;
    };
    for (const Case& c : {Case{"--scene cornell --frames 0", "--frames"}, Case{"--scene cornell --frames -3", "--frames"},
                          Case{"--scene cornell --frames 2 --camera-path spiral", "--camera-path"},
                          Case{"--scene cornell --frames 2 --camera-path keyframes", "keyframes"},
                          Case{"--scene cornell --frames 2 --reference-spp -1", "--reference-spp"},
                          Case{"--scene " + (tmp / "bad.json") + " --frames 2", "keyframes[1]"},
                          Case{"--scene cornell --reference-spp 4", "--reference-spp"}}) {
        auto r = runCli("render " + c.args + " --width 8 --height 8 --out " + out);
        EXPECT_EQ(r.exitCode, 2) << c.args << "\n" << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
        EXPECT_NE(r.output.find(c.mentions), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(out)) << c.args;
    }
}

}  // namespace
}  // namespace atrous

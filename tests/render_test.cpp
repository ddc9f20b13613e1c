// Statistical and property tests of the CPU path tracer on small images.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/render.h"
#include "core/rng.h"
#include "atrous/io/image_io.h"
#include "render/bsdf.h"
#include "render/camera.h"
#include "render/lights.h"
#include "render/sampling.h"
#include "render/scene_data.h"
#include "render_test_util.h"
#include "test_util.h"

namespace atrous {
namespace {

RenderSettings small(int w, int h, int spp, uint32_t seed = 1) { return test::smallRender(w, h, spp, seed); }

// A diffuse sphere of albedo 0.5 seen from z = 5 under a uniform environment of radiance 1, given
// either as a constant or as an EXR map (which goes through the 2D importance-sampling tables).
Scene furnaceScene(const std::string& envJson,
                   const std::string& material = R"({"type": "diffuse", "albedo": [0.5, 0.5, 0.5]})") {
    std::string json = R"({
      "camera": {"position": [0, 0, 5], "lookAt": [0, 0, 0], "fov": 30},
      "materials": {"grey": )" + material + R"(},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "grey"}],
      "lights": [)" + envJson + "]}";
    return Scene::parse(json, ".", "furnace.json");
}

// Furnace test. A convex object never sees itself, so every path that leaves the sphere sees the
// environment: the exact radiance of a Lambertian sphere of albedo rho under uniform radiance L
// is rho * L at any depth >= 1 (no inter-reflection), and L for pixels that miss it.
void checkFurnace(const Scene& scene, double expected = 0.5, int maxDepth = 8) {
    const int n = 32;
    RenderSettings s = small(n, n, 64);
    s.maxDepth = maxDepth;
    RenderBuffers b = render(scene, s);
    // Sphere: angular radius asin(1/5) = 11.5 deg in a 30 deg fov, i.e. 0.76 of the half-image;
    // pixels within 0.6 of the half-image of the centre are fully covered.
    double sum[3] = {0, 0, 0}, var[3] = {0, 0, 0};
    int count = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            double rx = (x + 0.5) / n * 2 - 1, ry = (y + 0.5) / n * 2 - 1;
            double r = std::sqrt(rx * rx + ry * ry);
            if (r < 0.6) {
                for (int c = 0; c < 3; ++c) {
                    sum[c] += b.color(x, y, c);
                    var[c] += b.variance(x, y, c);
                }
                ++count;
            } else if (r > 0.9) {
                // Camera rays that miss see the environment directly: exactly L, no variance.
                for (int c = 0; c < 3; ++c) {
                    EXPECT_FLOAT_EQ(b.color(x, y, c), 1.0f);
                    EXPECT_EQ(b.variance(x, y, c), 0.0f);
                }
            }
        }
    ASSERT_GT(count, 200);
    for (int c = 0; c < 3; ++c) {
        double mean = sum[c] / count;
        // Standard error of the mean of `count` independent pixel means: sqrt(sum var) / count.
        double se = std::sqrt(var[c]) / count;
        // 5 sigma (false failure ~6e-7) plus 1e-4 for float accumulation over 64 samples.
        EXPECT_NEAR(mean, expected, 5.0 * se + 1e-4) << "channel " << c << " se " << se;
    }
}

TEST(RenderFurnace, DiffuseSphereUnderConstantEnvironment) {
    checkFurnace(furnaceScene(R"({"type": "environment", "color": [1, 1, 1]})"));
}

// Clear glass (and a perfect mirror) absorbs nothing: under a uniform environment every path
// leaves with throughput 1 whatever it does inside, so the sphere is invisible (radiance exactly
// L = 1). Depth 64 makes paths trapped by total internal reflection negligible; Russian roulette
// keeps the estimate unbiased, so the 5-sigma bound from the measured variance applies.
TEST(RenderFurnace, GlassAndMirrorSpheresAreInvisibleUnderUniformLight) {
    checkFurnace(furnaceScene(R"({"type": "environment", "color": [1, 1, 1]})", R"({"type": "dielectric", "ior": 1.5})"), 1.0, 64);
    checkFurnace(furnaceScene(R"({"type": "environment", "color": [1, 1, 1]})", R"({"type": "mirror", "albedo": 1})"), 1.0, 64);
}

TEST(RenderFurnace, DiffuseSphereUnderEnvironmentMap) {
    test::TempDir tmp;
    Image env(64, 32, 3);
    env.fill(1.0f);
    atrous::writeImage(tmp / "white.exr", env);
    checkFurnace(furnaceScene(R"({"type": "environment", "file": ")" + (tmp / "white.exr") + R"("})"));
}

// The variance buffer is the variance of the pixel mean: across K independent seeds the empirical
// variance of each pixel's mean must match the mean reported variance, where the pixel's value
// does not depend on the sub-pixel position. The reported variance (sample variance / n) assumes
// independent samples; the sub-pixel positions are stratified (pt::PixelSampler::Sobol), which
// lowers the actual variance of pixels that straddle an edge, so there the report is conservative:
// reported >= empirical. Edge pixels: those whose emission or feature normal buffer (means over
// the pixel's sample positions) or mesh/material id (the first sample's) differs between seeds.
TEST(RenderVariance, MatchesEmpiricalVarianceAcrossSeeds) {
    const int n = 16, K = 32, spp = 8;
    Scene scene = Scene::builtin("cornell");
    std::vector<RenderBuffers> runs;
    for (int k = 0; k < K; ++k) {
        RenderSettings s = small(n, n, spp, 1000 + k);
        s.maxDepth = 3;
        runs.push_back(render(scene, s));
    }
    auto isEdge = [&](int x, int y) {
        for (const auto& r : runs)
            for (int c = 0; c < 3; ++c) {
                if (std::fabs(r.emission(x, y, c) - runs[0].emission(x, y, c)) > 0.0f) return true;
                if (std::fabs(r.normal(x, y, c) - runs[0].normal(x, y, c)) > 1e-4f) return true;
            }
        for (const auto& r : runs)  // ids are the first sample's, at another position in every run
            if (r.ids(x, y, 0) != runs[0].ids(x, y, 0) || r.ids(x, y, 1) != runs[0].ids(x, y, 1)) return true;
        return false;
    };
    double ratioSum[2] = {0.0, 0.0};  // [interior, edge]
    int used[2] = {0, 0};
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const int e = isEdge(x, y) ? 1 : 0;
            for (int c = 0; c < 3; ++c) {
                double m = 0.0, reported = 0.0;
                for (const auto& r : runs) {
                    m += r.color(x, y, c);
                    reported += r.variance(x, y, c);
                }
                m /= K;
                reported /= K;
                if (reported <= 1e-8) continue;
                double emp = 0.0;
                for (const auto& r : runs) emp += (r.color(x, y, c) - m) * (r.color(x, y, c) - m);
                emp /= (K - 1);
                ratioSum[e] += emp / reported;
                ++used[e];
            }
        }
    ASSERT_GT(used[0], 250);  // 321 and 447 with these seeds
    ASSERT_GT(used[1], 150);
    double interior = ratioSum[0] / used[0], edge = ratioSum[1] / used[1];
    std::printf("empirical / reported variance: interior %.4f over %d pixel channels, edges %.4f over %d\n",
                interior, used[0], edge, used[1]);
    // Per pixel, the empirical variance over K = 32 draws has relative standard deviation about
    // sqrt(2 / 31) = 0.25 for Gaussian means (more with heavy tails); averaged over >= 250 pixel
    // channels (>= 84 pixels: the channels of a pixel are correlated) the mean ratio's standard
    // deviation is ~0.03 (<~0.04 with heavy tails), so 1 +- 0.15 is ~4-5 sigma while a
    // variance that was off by the classic factor n (= 8, sample variance instead of variance of
    // the mean) or by n/(n-1) = 1.14 at the edge would fail.
    EXPECT_NEAR(interior, 1.0, 0.15) << "interior pixels used " << used[0];
    // Edges: conservative (measured 0.71 with these seeds; independent jitter gives ~1). Same
    // statistical margin on the upper side (>= 150 channels: sigma <~ 0.05); a report below the
    // actual variance would show as a ratio well above 1.
    EXPECT_LT(edge, 1.15) << "edge pixels used " << used[1];
}

TEST(RenderVariance, ZeroAtOneSample) {
    RenderBuffers b = render(Scene::builtin("cornell"), small(8, 8, 1));
    for (size_t i = 0; i < b.variance.size(); ++i) EXPECT_EQ(b.variance.data()[i], 0.0f);
}

bool sameBits(const Image& a, const Image& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(RenderDeterminism, SameSeedSameBitsWithOneOrTwoThreads) {
    Scene scene = Scene::builtin("cornell-spheres");
    RenderSettings s = small(24, 24, 4, 7);
    RenderBuffers one, two;
    tbb::task_arena a1(1), a2(2);
    a1.execute([&] { one = render(scene, s); });
    a2.execute([&] { two = render(scene, s); });
    s.threads = 2;  // the settings' own arena too
    RenderBuffers three = render(scene, s);
    for (const RenderBuffers* o : {&two, &three}) {
        EXPECT_TRUE(sameBits(one.color, o->color));
        EXPECT_TRUE(sameBits(one.variance, o->variance));
        EXPECT_TRUE(sameBits(one.albedo, o->albedo));
        EXPECT_TRUE(sameBits(one.normal, o->normal));
        EXPECT_TRUE(sameBits(one.position, o->position));
        EXPECT_TRUE(sameBits(one.depth, o->depth));
        EXPECT_TRUE(sameBits(one.ids, o->ids));
    }
    s.seed = 8;
    RenderBuffers other = render(scene, s);
    EXPECT_FALSE(sameBits(one.color, other.color));
}

TEST(RenderFeatures, BuffersHoldTheirConventions) {
    for (const char* name : {"cornell", "sphere-env"}) {
        Scene scene = Scene::builtin(name);
        RenderBuffers b = render(scene, small(32, 32, 4));
        const auto& d = scene.data();
        int hits = 0, background = 0;
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) {
                float mesh = b.ids(x, y, 0), mat = b.ids(x, y, 1);
                Vec3 nrm(b.normal(x, y, 0), b.normal(x, y, 1), b.normal(x, y, 2));
                for (int c = 0; c < 3; ++c) {
                    EXPECT_GE(b.albedo(x, y, c), 0.0f);
                    EXPECT_LE(b.albedo(x, y, c), 1.0f);
                    EXPECT_TRUE(std::isfinite(b.color(x, y, c)));
                    EXPECT_GE(b.variance(x, y, c), 0.0f);
                    EXPECT_EQ(b.depth(x, y, c), b.depth(x, y, 0));  // repeated in R, G, B
                }
                if (mesh >= 0) {
                    ++hits;
                    EXPECT_LT(mesh, float(d.meshNames.size()));
                    EXPECT_GE(mat, 0.0f);
                    EXPECT_LT(mat, float(d.materials.size()));
                    EXPECT_EQ(b.ids(x, y, 2), 0.0f);
                    EXPECT_NEAR(length(nrm), 1.0f, 1e-4f);  // renormalised mean normal
                    EXPECT_GT(b.depth(x, y, 0), 0.0f);
                    EXPECT_LT(b.depth(x, y, 0), 1e3f);
                } else {
                    ++background;
                    EXPECT_EQ(mat, -1.0f);
                    EXPECT_EQ(b.ids(x, y, 2), -1.0f);
                }
                if (b.depth(x, y, 0) == kBackgroundDepth) {  // no sample hit anything
                    EXPECT_EQ(length(nrm), 0.0f);
                    for (int c = 0; c < 3; ++c) EXPECT_EQ(b.position(x, y, c), 0.0f);
                }
            }
        EXPECT_GT(hits, 0) << name;
        if (std::string(name) == "sphere-env") EXPECT_GT(background, 50) << "the sky fills the top of sphere-env";
    }
}

// Through an ideal mirror the features come from the reflected surface: the pixels whose camera
// ray hits the mirror sphere and reflects steeply down onto the checkered floor must carry the
// floor's normal and material id, not the sphere's.
TEST(RenderFeatures, FollowMirrorBounces) {
    Scene scene = Scene::builtin("cornell-spheres");
    const int n = 64;
    RenderBuffers b = render(scene, small(n, n, 4));
    const auto& d = scene.data();
    int mirrorMat = scene.materialId("mirror"), floorMat = scene.materialId("checker");
    int mirrorMesh = scene.meshId("mirror_sphere");
    ASSERT_GE(mirrorMat, 0);
    ASSERT_GE(floorMat, 0);
    const pt::Sphere* mirror = nullptr;
    for (const auto& s : d.spheres)
        if (s.material == mirrorMat) mirror = &s;
    ASSERT_NE(mirror, nullptr);
    int onMirror = 0, labelledMirror = 0, towardFloor = 0, floorFeatures = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            // Only pixels whose whole footprint sees the mirror (all 4 corners), so jitter does not matter.
            bool all = true;
            Vec3 centreDir = pt::cameraRayDirection(d.camera, x + 0.5f, y + 0.5f, n, n);
            for (int k = 0; k < 4 && all; ++k) {
                Vec3 dir = pt::cameraRayDirection(d.camera, float(x + (k & 1)), float(y + (k >> 1)), n, n);
                all = pt::intersectSphere(mirror->center, mirror->radius, d.camera.position, dir, 0.0f, 1e30f) > 0.0f;
            }
            if (!all) continue;
            ++onMirror;
            if (b.ids(x, y, 1) == float(mirrorMat) || b.ids(x, y, 0) == float(mirrorMesh)) ++labelledMirror;
            float t = pt::intersectSphere(mirror->center, mirror->radius, d.camera.position, centreDir, 0.0f, 1e30f);
            Vec3 p = d.camera.position + centreDir * t;
            Vec3 nrm = normalize(p - mirror->center);
            Vec3 r = centreDir - nrm * (2.0f * dot(centreDir, nrm));
            if (r.y < -0.7f) {  // steeply down: lands on the floor right beside the sphere
                ++towardFloor;
                if (b.normal(x, y, 1) > 0.99f && b.ids(x, y, 1) == float(floorMat)) ++floorFeatures;
            }
        }
    ASSERT_GT(onMirror, 50);
    ASSERT_GT(towardFloor, 5);
    EXPECT_EQ(labelledMirror, 0);  // the mirror never names itself (max depth 8 is never reached)
    EXPECT_EQ(floorFeatures, towardFloor);
}

// Region statistics of a converged-ish Cornell box.
TEST(RenderCornell, ColourBleedingAndSoftShadows) {
    Scene scene = Scene::builtin("cornell");
    const int n = 64;
    RenderBuffers b = render(scene, small(n, n, 128));
    int tall = scene.meshId("tall_box"), shortBox = scene.meshId("short_box");
    // The tall box's face toward the red wall has outward normal (0.956, 0, -0.295); the short
    // box's face toward the green wall (-0.958, 0, -0.287). Both are the same white material, so
    // a red/green ratio that differs is light bounced off the walls.
    auto ratioOf = [&](int mesh, Vec3 normal) {
        double r = 0, g = 0;
        int count = 0;
        for (int y = 1; y < n - 1; ++y)
            for (int x = 1; x < n - 1; ++x) {
                if (b.ids(x, y, 0) != float(mesh)) continue;
                Vec3 nn(b.normal(x, y, 0), b.normal(x, y, 1), b.normal(x, y, 2));
                if (dot(nn, normal) < 0.99f) continue;
                r += b.color(x, y, 0);
                g += b.color(x, y, 1);
                ++count;
            }
        EXPECT_GT(count, 10);
        return r / g;
    };
    double redSide = ratioOf(tall, normalize(Vec3(0.956f, 0, -0.295f)));
    double greenSide = ratioOf(shortBox, normalize(Vec3(-0.958f, 0, -0.287f)));
    // White under the (17,12,4) light has R/G ~ 1.4; the red-lit face is much redder, the
    // green-lit one much greener. Measured 11.4 vs 0.56 at 128 spp; the
    // bound only asks for a clear difference.
    EXPECT_GT(redSide, 1.6 * greenSide) << "red side " << redSide << " green side " << greenSide;

}

// Segment p -> q blocked by a triangle (Moller-Trumbore), ends excluded.
bool segmentBlocked(const pt::SceneData& d, Vec3 p, Vec3 q) {
    Vec3 dir = q - p;
    for (size_t t = 0; t < d.triMaterial.size(); ++t) {
        Vec3 a = d.positions[d.indices[3 * t]], b = d.positions[d.indices[3 * t + 1]], c = d.positions[d.indices[3 * t + 2]];
        Vec3 e1 = b - a, e2 = c - a, pv = cross(dir, e2);
        float det = dot(e1, pv);
        if (std::fabs(det) < 1e-12f) continue;
        Vec3 tv = p - a;
        float u = dot(tv, pv) / det;
        if (u < 0 || u > 1) continue;
        Vec3 qv = cross(tv, e1);
        float v = dot(dir, qv) / det;
        if (v < 0 || u + v > 1) continue;
        float s = dot(e2, qv) / det;
        if (s > 1e-4f && s < 1.0f - 1e-4f) return true;
    }
    return false;
}

// Soft shadows, checked against an independent computation: for floor pixels the direct light
// (max depth 1) must equal rho/pi * E(p), with the irradiance E from the light quad integrated
// here on a stratified grid with explicit visibility. Pixels in the penumbra (partly visible
// light) must exist in numbers, and be rendered at the predicted, intermediate level.
TEST(RenderCornell, SoftShadowPenumbraMatchesIndependentDirectLighting) {
    Scene scene = Scene::builtin("cornell");
    const auto& d = scene.data();
    const int n = 96;
    RenderSettings s = small(n, n, 64);
    s.maxDepth = 1;
    RenderBuffers b = render(scene, s);
    int floorMesh = scene.meshId("floor");
    Vec3 rho = d.materials[scene.materialId("white")].albedo;
    auto isFloor = [&](int x, int y) { return x >= 0 && y >= 0 && x < n && y < n && b.ids(x, y, 0) == float(floorMesh) && b.normal(x, y, 1) > 0.99f; };
    const int g = 12;  // g x g stratified points per light triangle
    int penumbra = 0;
    double rendered = 0, predicted = 0, var = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            // Interior floor pixels only (no footprint shared with a box or wall).
            bool interior = true;
            for (int k = -1; k <= 1; ++k)
                for (int j = -1; j <= 1; ++j) interior = interior && isFloor(x + j, y + k);
            if (!interior) continue;
            Vec3 p(b.position(x, y, 0), b.position(x, y, 1), b.position(x, y, 2));
            double e = 0, visible = 0, total = 0;
            for (const auto& l : d.lights) {
                const uint32_t* idx = &d.indices[3 * l.triangle];
                Vec3 a = d.positions[idx[0]], bb = d.positions[idx[1]], c = d.positions[idx[2]];
                float area = 0.5f * length(cross(bb - a, c - a));
                Vec3 nl = normalize(cross(bb - a, c - a));
                for (int i = 0; i < g; ++i)
                    for (int j = 0; j < g; ++j) {
                        float b1, b2;
                        pt::uniformTriangle((i + 0.5f) / g, (j + 0.5f) / g, b1, b2);
                        Vec3 q = a * (1 - b1 - b2) + bb * b1 + c * b2;
                        Vec3 w = q - p;
                        float d2 = lengthSquared(w);
                        w = w / std::sqrt(d2);
                        double geo = std::max(0.0f, w.y) * std::max(0.0f, -dot(nl, w)) / d2 * area / (g * g);
                        total += geo;
                        if (!segmentBlocked(d, p, q)) {
                            e += geo;
                            visible += geo;
                        }
                    }
            }
            double frac = visible / total;
            if (frac > 0.1 && frac < 0.9) {
                ++penumbra;
                // Green channel: emission 12, rho_g.
                predicted += rho.y / kPi * 12.0 * e;
                rendered += b.color(x, y, 1);
                var += b.variance(x, y, 1);
            }
        }
    std::printf("penumbra pixels %d, rendered %.4f vs predicted %.4f (se %.4f)\n", penumbra, rendered / std::max(1, penumbra),
                predicted / std::max(1, penumbra), std::sqrt(var) / std::max(1, penumbra));
    EXPECT_GT(penumbra, 50);  // soft shadows (108 measured at 96x96): a band of partly lit floor, not a hard edge
    // The renderer averages over the pixel footprint and the prediction takes the footprint's
    // centre, which differs by the curvature of E over a pixel; with the 12x12 quadrature that
    // stays within a few percent. 5% + 5 standard errors.
    EXPECT_NEAR(rendered, predicted, 0.05 * predicted + 5 * std::sqrt(var));
}

// Next-event estimation with MIS and pure BSDF sampling estimate the same integral.
TEST(RenderLightSampling, NeeMisAgreesWithBsdfSampling) {
    Scene scene = Scene::builtin("cornell");
    RenderSettings s = small(16, 16, 256);
    s.maxDepth = 3;
    RenderBuffers mis = render(scene, s);
    s.lightSampling = false;
    s.seed = 99;
    RenderBuffers bsdf = render(scene, s);
    for (int c = 0; c < 3; ++c) {
        double m1 = 0, m2 = 0, v1 = 0, v2 = 0;
        size_t np = mis.color.plane();
        for (size_t i = 0; i < np; ++i) {
            m1 += mis.color.data()[c * np + i];
            m2 += bsdf.color.data()[c * np + i];
            v1 += mis.variance.data()[c * np + i];
            v2 += bsdf.variance.data()[c * np + i];
        }
        m1 /= np;
        m2 /= np;
        double se = std::sqrt(v1 + v2) / np;  // standard error of the difference of image means
        EXPECT_NEAR(m1, m2, 5.0 * se) << "channel " << c;
        EXPECT_LT(v1, v2) << "MIS should be the less noisy estimator";
    }
}

// The same agreement for the GGX lobes, whose MIS weights use bsdfPdf: rough conductor and rough
// plastic spheres under the environment map (furnace scene), NEE+MIS against BSDF sampling only.
TEST(RenderLightSampling, NeeMisAgreesWithBsdfSamplingOnGlossyMaterials) {
    test::TempDir tmp;
    Image env(32, 16, 3);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 32; ++x)
            for (int c = 0; c < 3; ++c) env(x, y, c) = (y < 8 ? 2.0f : 0.5f) * (x < 16 ? 1.0f : 0.25f);  // uneven
    atrous::writeImage(tmp / "env.exr", env);
    const std::string envJson = R"({"type": "environment", "file": ")" + (tmp / "env.exr") + R"("})";
    for (const char* material : {R"({"type": "conductor", "albedo": [0.9, 0.6, 0.3], "roughness": 0.3})",
                                 R"({"type": "plastic", "albedo": [0.2, 0.4, 0.8], "roughness": 0.15})"}) {
        Scene scene = furnaceScene(envJson, material);
        RenderSettings s = small(24, 24, 64);
        RenderBuffers a = render(scene, s);
        s.lightSampling = false;
        s.seed = 12345;
        RenderBuffers b = render(scene, s);
        for (int c = 0; c < 3; ++c) {
            double m1 = 0, m2 = 0, v = 0;
            size_t np = a.color.plane();
            for (size_t i = 0; i < np; ++i) {
                m1 += a.color.data()[c * np + i];
                m2 += b.color.data()[c * np + i];
                v += a.variance.data()[c * np + i] + b.variance.data()[c * np + i];
            }
            EXPECT_NEAR(m1 / np, m2 / np, 5.0 * std::sqrt(v) / np) << material << " channel " << c;
        }
    }
}

// ---- the math underneath ----

// For each non-delta BSDF: sample() reports the pdf that pdf() computes and the weight
// eval * cos / pdf; the directional albedo (mean weight) stays <= 1.
TEST(RenderBsdf, SampleEvalPdfConsistentAndEnergyConserving) {
    using namespace pt;
    for (MaterialType type : {MaterialType::Diffuse, MaterialType::Conductor, MaterialType::Plastic}) {
        for (float alpha : {0.05f, 0.3f, 0.8f}) {
            Bsdf b;
            b.type = type;
            b.albedo = Vec3(0.9f);
            b.alpha = alpha;
            Vec3 wo = normalize(Vec3(0.5f, 0.1f, 0.7f));
            Rng rng(1, 2, 3);
            double albedo = 0;
            const int N = 20000;
            for (int i = 0; i < N; ++i) {
                BsdfSample s = bsdfSample(b, wo, rng.next(), rng.next(), rng.next());
                if (!s.valid) continue;
                float pdf = bsdfPdf(b, wo, s.wi);
                ASSERT_NEAR(s.pdf, pdf, 1e-3f * pdf + 1e-5f);
                Vec3 w = bsdfEval(b, wo, s.wi) * (s.wi.z / pdf);
                ASSERT_NEAR(s.weight.x, w.x, 1e-3f * w.x + 1e-5f);
                albedo += s.weight.y;
            }
            albedo /= N;
            // Directional albedo <= 1 up to MC noise (weights are bounded by ~1, so the standard
            // error is < 1/sqrt(N) = 0.007).
            EXPECT_LE(albedo, 1.0 + 0.03) << int(type) << " alpha " << alpha;
            EXPECT_GT(albedo, 0.3) << int(type) << " alpha " << alpha;
        }
    }
}

// The environment map's sampling pdf integrates to one over the sphere and sampleEnv reports the
// same pdf as envPdf.
TEST(RenderEnvironment, PdfIntegratesToOneAndMatchesSampling) {
    Scene scene = Scene::builtin("sphere-env");
    pt::SceneView v = scene.data().view();
    ASSERT_EQ(v.env.type, pt::EnvType::Map);
    const pt::Texture& t = v.textures[v.env.texture];
    double integral = 0;
    for (int y = 0; y < t.height; ++y)
        for (int x = 0; x < t.width; ++x) {
            float u = (x + 0.5f) / t.width, vv = (y + 0.5f) / t.height;
            double dOmega = (2 * kPi / t.width) * (kPi / t.height) * std::sin(vv * kPi);
            integral += pt::envPdf(v, pt::latLongToDirection(u, vv)) * dOmega;
        }
    // Midpoint rule in theta: exact per texel up to O(1/h^2) ~ 1e-5.
    EXPECT_NEAR(integral, 1.0, 1e-3);
    Rng rng(5, 6, 7);
    for (int i = 0; i < 2000; ++i) {
        Vec3 dir;
        float pdf;
        ASSERT_TRUE(pt::sampleEnv(v, rng.next(), rng.next(), dir, pdf));
        float p2 = pt::envPdf(v, dir);
        // Directions exactly on a texel border may land in the neighbour texel: allow those.
        if (std::fabs(pdf - p2) > 1e-3f * pdf) {
            Vec2 uv = pt::directionToLatLong(dir);
            float fx = uv.x * t.width, fy = uv.y * t.height;
            EXPECT_TRUE(std::fabs(fx - std::round(fx)) < 1e-2f || std::fabs(fy - std::round(fy)) < 1e-2f);
        }
    }
}

TEST(RenderSettingsCheck, RejectsOutOfRange) {
    Scene scene = Scene::builtin("cornell");
    auto bad = [&](RenderSettings s) { EXPECT_THROW(render(scene, s), InputError); };
    RenderSettings s = small(8, 8, 1);
    s.spp = 0; bad(s);
    s = small(8, 8, 1); s.width = 0; bad(s);
    s = small(8, 8, 1); s.height = kMaxImageDim + 1; bad(s);
    s = small(8, 8, 1); s.maxDepth = -1; bad(s);
    s = small(8, 8, 1); s.threads = -2; bad(s);
}

}  // namespace
}  // namespace atrous

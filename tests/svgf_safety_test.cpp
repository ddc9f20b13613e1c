// SVGF's per-frame safety net (SvgfParams::safetyNet, src/filters/svgf_safety.h): where SVGF's
// output and the still default's of the frame alone disagree, the output becomes the still one's.
// Two sequences where SVGF alone does harm, each checked against the still default frame by frame:
// a reflected light moving over a static floor, with its emission in the emission buffer (the
// emission history, reprojected with the floor's zero motion, leaves a trail) and without one
// (the colour history drags the light's edge).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "atrous/denoise.h"
#include "atrous/svgf.h"
#include "core/parallel.h"
#include "filters/svgf_safety.h"
#include "svgf_test_util.h"

using namespace atrous;
using atrous::svgf_test::allFinite;

namespace {

constexpr int kW = 64, kH = 48;

// A static floor (albedo 0.5, lit 1) seen at 4 spp, flat normals, constant depth, no motion; a
// light of radiance kL over a 6x6 patch whose column moves by `speed` pixels a frame (0: static),
// its 1-pixel rim covered at random each frame (coverage noise). `withEmission`: the patch is
// also in the emission buffer (what atrous's renderer writes for a light seen in a mirror).
struct LightScene {
    float speed = 3.0f;
    bool withEmission = true;
    float noiseSigma = 0.08f;  // relative, on the floor's lighting
    float kL = 8.0f;
    Image color{kW, kH, 3}, albedo{kW, kH, 3}, normal{kW, kH, 3}, depth{kW, kH, 1}, ids{kW, kH, 1},
        motion{kW, kH, 2}, emission{kW, kH, 3}, truth{kW, kH, 3};
    void frame(int t) {
        std::mt19937 rng(1234u + unsigned(t));
        std::normal_distribution<float> noise(0.0f, noiseSigma);
        std::bernoulli_distribution cover(0.5);
        const float x0 = 6.0f + speed * float(t);
        const int y0 = 20;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const bool core = x >= x0 + 1 && x < x0 + 5 && y >= y0 + 1 && y < y0 + 5;
                const bool rim = !core && x >= x0 && x < x0 + 6 && y >= y0 && y < y0 + 6;
                const float eTrue = core ? kL : rim ? 0.5f * kL : 0.0f;
                const float e = core ? kL : rim && cover(rng) ? kL : 0.0f;
                const float n = noise(rng);
                for (int c = 0; c < 3; ++c) {
                    albedo(x, y, c) = 0.5f;
                    normal(x, y, c) = c == 2 ? 1.0f : 0.0f;
                    emission(x, y, c) = e;
                    truth(x, y, c) = 0.5f + eTrue;
                    color(x, y, c) = 0.5f * (1.0f + n) + e;
                }
                depth(x, y, 0) = 5.0f;
                ids(x, y, 0) = 1.0f;
                motion(x, y, 0) = motion(x, y, 1) = 0.0f;
            }
    }
    Frame inputs() const {
        Frame f;
        f.color = &color, f.albedo = &albedo, f.normal = &normal, f.depth = &depth, f.ids = &ids, f.motion = &motion;
        if (withEmission) f.emission = &emission;
        return f;
    }
};

double relMse(const Image& a, const Image& ref) {
    double s = 0;
    for (int y = 0; y < ref.height(); ++y)
        for (int x = 0; x < ref.width(); ++x)
            for (int c = 0; c < 3; ++c) {
                const double d = double(a(x, y, c)) - ref(x, y, c), r = ref(x, y, c);
                s += d * d / (r * r + 1e-2);
            }
    return s / double(ref.width() * ref.height() * 3);
}

struct Errors {
    double svgfAlone = 0, withNet = 0, still = 0;  // relMSE summed over frames 4..
};

Errors runScene(LightScene& scene, int frames) {
    SvgfParams alone;
    alone.safetyNet = 0.0f;
    SvgfDenoiser a(alone), b{SvgfParams{}};
    Errors r;
    for (int t = 0; t < frames; ++t) {
        scene.frame(t);
        const Frame f = scene.inputs();
        const Image oa = a.denoiseFrame(f), ob = b.denoiseFrame(f);
        const Image os = denoise(f, DenoiseOptions{});
        EXPECT_TRUE(allFinite(ob)) << "frame " << t;
        if (t < 4) continue;  // SVGF's first frames are its spatial estimate
        r.svgfAlone += relMse(oa, scene.truth);
        r.withNet += relMse(ob, scene.truth);
        r.still += relMse(os, scene.truth);
    }
    std::printf("[ measured ] relMSE (frames 4+): SVGF alone %.4f, with the safety net %.4f, still default %.4f\n",
                r.svgfAlone, r.withNet, r.still);
    return r;
}

}  // namespace

// The moving reflected light: SVGF alone keeps a trail (its emission history is reprojected with
// the floor's motion and the 3x3 clamp box still holds the light's edge); with the net the
// sequence is within 5% of the still default's error (the bar for SVGF).
TEST(SvgfSafetyNet, MovingReflectedLightLeavesNoTrail) {
    LightScene s;
    const Errors r = runScene(s, 12);
    EXPECT_GT(r.svgfAlone, 1.5 * r.still) << "the scene should show SVGF's trail";
    EXPECT_LE(r.withNet, 1.05 * r.still);
}

// A light with no emission buffer, seen in a mirror: it moves while the floor's motion vectors do
// not, and SVGF alone drags its edge along (the history clip keeps part of it); with the net the
// edges are the still default's (within 5% of its error).
TEST(SvgfSafetyNet, LightWithoutAnEmissionBufferKeepsItsEdges) {
    LightScene s;
    s.speed = 2.0f;  // the light seen in a mirror: it moves, the floor's motion vectors do not
    s.withEmission = false;
    const Errors r = runScene(s, 10);
    EXPECT_GT(r.svgfAlone, 1.5 * r.still) << "the scene should show SVGF's smear";
    EXPECT_LE(r.withNet, 1.05 * r.still);
}

// The give-way itself: equal inputs pass SVGF's output; a difference of tau or less keeps it; one
// of 2 tau or more gives the still one's; in between a linear blend.
TEST(SvgfSafetyNet, GivesWayBetweenTauAndTwiceTau) {
    const int w = 5, h = 5;
    Image s(w, h, 3), p(w, h, 3), rel(w, h, 1), out(w, h, 3);
    auto run = [&](float sv, float pv) {
        s.fill(sv), p.fill(pv);
        CpuExec ex;
        ex.forEachPixel(w, h, svgf::SafetyDifference{s.view(), p.view(), rel.view()});
        ex.forEachPixel(w, h, svgf::SafetyBlend{0.05f, s.view(), p.view(), rel.view(), out.view()});
        return out(2, 2, 0);
    };
    EXPECT_EQ(run(1.0f, 1.0f), 1.0f);
    EXPECT_FLOAT_EQ(run(1.04f, 1.0f), 1.04f);                 // d = 0.04/1.02 < tau: SVGF's
    EXPECT_FLOAT_EQ(run(2.0f, 1.0f), 1.0f);                   // d ~ 0.98 >= 2 tau: the still one's
    const float d = 0.0765f / 1.02f, t = (d - 0.05f) / 0.05f;  // between: the blend
    EXPECT_NEAR(run(1.0765f, 1.0f), 1.0765f + (1.0f - 1.0765f) * t, 1e-5);
    // Non-finite differences count as none (the still filter and SVGF never give NaN; a guard).
    s.fill(1.0f), p.fill(1.0f);
    s(2, 2, 0) = s(2, 2, 1) = s(2, 2, 2) = INFINITY;
    CpuExec ex;
    ex.forEachPixel(w, h, svgf::SafetyDifference{s.view(), p.view(), rel.view()});
    EXPECT_EQ(rel(2, 2, 0), 0.0f);
}

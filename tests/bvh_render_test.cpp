// The GPU renderer's code path (pt::PathTraceKernel with pt::BvhTracer over the flattened BVH),
// run on the CPU and compared with the Embree renderer (atrous::render) on the built-in scenes.
// Both use the same RNG streams, so their images differ only where the two intersectors round a
// hit differently; the comparisons below bound that.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "atrous/device.h"
#include "atrous/error.h"
#include "atrous/render.h"
#include "render/bvh_render.h"
#include "render_test_util.h"

namespace atrous {
namespace {

RenderSettings small(int w, int h, int spp) { return test::smallRender(w, h, spp, 3); }

struct Diff {
    double meanA = 0, meanB = 0;  // image means (all channels)
    double z2 = 0;                // mean of (a - b)^2 / (var_a + var_b) over pixels with variance
    double idsSame = 0;           // fraction of pixels whose mesh and material ids agree
    double maxDepthRel = 0;       // largest relative depth difference where both hit
    double emissionSame = 0;      // fraction of pixels whose primary-hit emission agrees
};

Diff compare(const RenderBuffers& a, const RenderBuffers& b) {
    Diff d;
    const int w = a.color.width(), h = a.color.height();
    long n = 0, nz = 0, same = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) {
                double ca = a.color(x, y, c), cb = b.color(x, y, c);
                d.meanA += ca;
                d.meanB += cb;
                ++n;
                double v = double(a.variance(x, y, c)) + double(b.variance(x, y, c));
                if (v > 1e-12) {
                    d.z2 += (ca - cb) * (ca - cb) / v;
                    ++nz;
                }
            }
            if (a.ids(x, y, 0) == b.ids(x, y, 0) && a.ids(x, y, 1) == b.ids(x, y, 1)) ++same;
            bool emissionSame = true;
            for (int c = 0; c < 3; ++c) emissionSame = emissionSame && a.emission(x, y, c) == b.emission(x, y, c);
            d.emissionSame += emissionSame;
            float da = a.depth(x, y, 0), db = b.depth(x, y, 0);
            if (da < kBackgroundDepth && db < kBackgroundDepth)
                d.maxDepthRel = std::max(d.maxDepthRel, double(std::fabs(da - db) / std::max(da, 1e-6f)));
        }
    d.meanA /= double(n);
    d.meanB /= double(n);
    d.z2 = nz ? d.z2 / double(nz) : 0.0;
    d.idsSame = double(same) / double(w * h);
    d.emissionSame /= double(w * h);
    return d;
}

}  // namespace

// Every built-in scene and the example JSON scene (OBJ mesh): the BVH renderer agrees with the
// Embree renderer.
TEST(BvhRender, MatchesEmbreeRendererOnBuiltinScenes) {
    std::vector<std::string> names = builtinSceneNames();
    names.push_back(std::string(ATROUS_SOURCE_DIR) + "/scenes/example.json");
    for (const std::string& name : names) {
        Scene scene = Scene::loadByNameOrFile(name);
        RenderSettings s = small(48, 36, 16);
        RenderBuffers embree = render(scene, s);
        RenderBuffers bvh = renderBvhCpu(scene, s);
        Diff d = compare(embree, bvh);
        std::printf("%s: mean %.6f vs %.6f, mean z^2 %.4f, ids same %.4f, emission same %.4f, max depth rel diff %.2e\n",
                    name.c_str(), d.meanA, d.meanB, d.z2, d.idsSame, d.emissionSame, d.maxDepthRel);
        // Independent renders would give E[z^2] = 1 (difference of two independent means over the
        // sum of their variances); sharing the RNG streams makes the difference far smaller. A
        // wrong intersector (missed or wrong surfaces) pushes z^2 to 1 or beyond. Bound: 0.25.
        EXPECT_LT(d.z2, 0.25) << name;
        // Image means: the same light transport; 1% allows a few paths that diverged.
        EXPECT_NEAR(d.meanB, d.meanA, 0.01 * d.meanA + 1e-6) << name;
        // Primary hits are the same surfaces (ids) at the same depth; sub-pixel jitter is shared,
        // so only pixels whose ray grazes an edge within rounding may differ: 0.5%.
        EXPECT_GE(d.idsSame, 0.995) << name;
        // The emission buffer (mean emitted radiance of the primary hits) follows the same hits.
        EXPECT_GE(d.emissionSame, 0.995) << name;
        // Depth is a mean of primary hit distances: both intersectors are accurate to ~1e-6.
        EXPECT_LT(d.maxDepthRel, 1e-3) << name;
    }
}

TEST(BvhRender, DeterministicAndValidatesSettings) {
    Scene scene = Scene::builtin("cornell-spheres");
    RenderSettings s = small(16, 16, 4);
    RenderBuffers a = renderBvhCpu(scene, s);
    s.threads = 1;
    RenderBuffers b = renderBvhCpu(scene, s);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
            for (int c = 0; c < 3; ++c) ASSERT_EQ(a.color(x, y, c), b.color(x, y, c));
    RenderSettings bad = small(16, 16, 0);
    EXPECT_THROW(renderBvhCpu(scene, bad), InputError);
    // Without a CUDA backend or GPU the CUDA renderer refuses with an InputError (CLI: exit 2).
    if (!cudaAvailable()) {
        EXPECT_THROW(renderBvhCuda(scene, small(16, 16, 4)), InputError);
        EXPECT_THROW(CudaBvhRenderer{scene}, InputError);
    }
}

}  // namespace atrous

// The toy still method: the whole of what a new method is, one registry row plus its cascade, written
// against the public headers alone (include/atrous), so that the same file builds as a plugin from
// an installed atrous (tests/plugin_package_test.sh; docs/decisions.md, "The toy plugin over the
// public API"). Linked into a program it is registered when the program starts; built as a plugin
// (ATROUS_TOY_PLUGIN, tests/toy_plugin.cpp's entry point) when the plugin is loaded.
#include "toy_method.h"

#include <cmath>

#include "atrous/image.h"

namespace atrous::toy {

namespace {

// One level of the toy stop (the policy of tests/toy_policy.h, written as plain loops): the B3
// à-trous at `step` with the weight h(q) exp(-(g_p - g_q)² invSigma2), taps outside the image
// dropped and the rest renormalised (the centre tap, h(0)² = (3/8)², is always there).
void toyLevel(const ImageView& in, const ImageView& guide, const ImageView& out, int step,
              float invSigma2) {
    static const float b3[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
    for (int y = 0; y < in.height; ++y)
        for (int x = 0; x < in.width; ++x) {
            float sum[4] = {0.0f, 0.0f, 0.0f, 0.0f};  // Σw, Σw c
            for (int tap = 0; tap < 25; ++tap) {      // row by row, left to right
                const int i = tap % 5, j = tap / 5;
                const int qx = x + (i - 2) * step, qy = y + (j - 2) * step;
                if (qx < 0 || qy < 0 || qx >= in.width || qy >= in.height) continue;
                const float d = guide(x, y, 0) - guide(qx, qy, 0);
                const float w = b3[i] * b3[j] * std::exp(-d * d * invSigma2);
                sum[0] += w;
                for (int c = 0; c < 3; ++c) sum[c + 1] += w * in(qx, qy, c);
            }
            for (int c = 0; c < 3; ++c) out(x, y, c) = sum[c + 1] / sum[0];
        }
}

}  // namespace

void toyCascade(const PreparedView& p, const DenoiseOptions&, const ImageView& out) {
    const int w = p.color.width, h = p.color.height;
    Image tmp = Image::uninitialized(w, h, 3);
    const bool guided = p.albedo.valid();
    const ImageView guide{guided ? p.albedo.channel(1) : p.color.channel(1), w, h, 1};
    // Levels 1, 2, 4: colour -> out -> tmp -> out.
    const ImageView from[3] = {p.color, out, tmp.view()}, to[3] = {out, tmp.view(), out};
    for (int i = 0; i < 3; ++i) toyLevel(from[i], guide, to[i], 1 << i, guided ? 100.0f : 0.0f);
}

void registerToy() {
    DenoiseMethodInfo row;
    row.name = "toy";
    row.summary = "a toy: three levels of a cross-bilateral a-trous on the albedo (tests/toy_method.cpp)";
    row.reads.buffers = {Buffer::Albedo};
    row.cpu = toyCascade;
    registerDenoiseMethod(row);
}

DenoiseMethod toyMethod() { return parseDenoiseMethod("toy"); }

#if !defined(ATROUS_TOY_PLUGIN)
namespace {
// Linked into a program (atrous_toy, toy_method_test): registered when it starts.
const bool kRegistered = (registerToy(), true);
}  // namespace
#endif

}  // namespace atrous::toy

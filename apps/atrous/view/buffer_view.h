// The viewer's buffer views (the --buffer flag, the panel's "buffer" list) and their tonemapping
// on the host into the RGBA8 display image. No GL: the display (display.h) uploads the result.
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "atrous/image.h"
#include "atrous/view_pipeline.h"

namespace atrous::view {

enum class BufferView {
    Result,
    Noisy,
    Variance,
    Albedo,
    Normal,
    Position,
    Depth,
    MeshIds,
    MaterialIds,
    Motion,
    Detail,
    SureFractions
};
// The panel's names and the --buffer flag's, in BufferView order.
inline constexpr const char* kViewNames[] = {"result (denoised)",
                                             "color (noisy input)",
                                             "variance (std dev)",
                                             "albedo",
                                             "normal",
                                             "position",
                                             "depth",
                                             "mesh ids",
                                             "material ids",
                                             "motion vectors (SVGF)",
                                             "detail d_i (per level)",
                                             "SURE fractions s_i"};
inline constexpr const char* kViewFlags[] = {"result",       "color",    "variance", "albedo",
                                             "normal",       "position", "depth",    "mesh-ids",
                                             "material-ids", "motion",   "detail",   "sure-s"};
constexpr int kViewCount = int(sizeof(kViewNames) / sizeof(kViewNames[0]));

// A --buffer flag value; InputError naming the flag and the choices otherwise.
BufferView parseBufferView(const std::string& s);

// Linear [0, 1] to 8-bit sRGB through a table, and back (exact at 8 bits).
struct SrgbLut {
    unsigned char enc[4096];  // linear [0,1] -> 8-bit sRGB
    float dec[256];           // 8-bit sRGB -> linear
    SrgbLut() {
        for (int i = 0; i < 4096; ++i) {
            const float v = float(i) / 4095.0f;
            const float s =
                v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
            enc[i] = (unsigned char)std::lround(std::clamp(s, 0.0f, 1.0f) * 255.0f);
        }
        for (int i = 0; i < 256; ++i) {
            const float s = float(i) / 255.0f;
            dec[i] = s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f);
        }
    }
    unsigned char operator()(float v) const {
        if (!(v > 0.0f)) return 0;  // also NaN
        if (v >= 1.0f) return 255;
        return enc[int(v * 4095.0f + 0.5f)];
    }
};
const SrgbLut& lut();

// Writes columns [x0, x1) of the display image (RGBA8, width x height of the pipeline, rows
// top-down) for `view`; `result` is the slot's result for the result view (may be null or empty),
// `level` the level of the per-level views. Returns a note for the UI when the view has nothing to
// show.
std::string tonemap(const ViewPipeline& pl, BufferView view, const Image* result, float exposure,
                    int level, int x0, int x1, std::vector<unsigned char>& rgba);

}  // namespace atrous::view

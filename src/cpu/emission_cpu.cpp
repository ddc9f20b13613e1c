// CPU path of the emission filter (filters::EmissionLevel, runEmissionFilter). A pixel the
// functor copies (no emission, or a variance below 1e-4 of its energy: fully covered lights, the
// sky, ~99% of pixels) keeps its value, so it is copied at every level: its test depends on its
// own value, which the copy keeps. So the first level writes every pixel (the copies into both
// buffers) and lists the pixels that need the taps; the other levels run the functor on those
// alone. The functor (the same per-pixel code as before) decides every listed pixel; a pixel is
// listed unless it is certainly a copy: all three channels 0, or an energy above 1e-30 whose
// variance is below half the functor's threshold (a margin for the contraction of e² into
// multiply-adds, which may differ from the functor's in the last bit). Outputs bit-equal
// (tests/filter_rows_test.cpp). Before, each level read 6 planes and wrote 3 for every pixel.
#include "atrous/platform.h"
ATROUS_NO_TRAPPING_MATH

#include <algorithm>
#include <vector>

#include "core/parallel.h"
#include "core/isa_dispatch.h"
#include "filters/emission_filter.h"

namespace atrous::filters {

namespace {

// The first level: every pixel of rows [y0, y1) copied into f.eOut and `also` (when valid), the
// listed ones through the functor into f.eOut; their x appended to list[y].
void firstLevelRows(const EmissionLevel& g, const ImageView& also, int y0, int y1, std::vector<std::vector<int>>& list) {
    const int w = g.eIn.width;
    std::vector<unsigned char> cand(static_cast<size_t>(w));
    for (int y = y0; y < y1; ++y) {
        const size_t o = size_t(y) * size_t(w);
        const float* ATROUS_RESTRICT r = g.eIn.channel(0) + o;
        const float* ATROUS_RESTRICT gg = g.eIn.channel(1) + o;
        const float* ATROUS_RESTRICT b = g.eIn.channel(2) + o;
        const float* ATROUS_RESTRICT v0 = g.variance.channel(0) + o;
        const float* ATROUS_RESTRICT v1 = g.variance.channel(1) + o;
        const float* ATROUS_RESTRICT v2 = g.variance.channel(2) + o;
        float* ATROUS_RESTRICT o0 = g.eOut.channel(0) + o;
        float* ATROUS_RESTRICT o1 = g.eOut.channel(1) + o;
        float* ATROUS_RESTRICT o2 = g.eOut.channel(2) + o;
        unsigned char* ATROUS_RESTRICT c = cand.data();
        int any = 0;
#pragma omp simd reduction(| : any)
        for (int x = 0; x < w; ++x) {
            const float er = r[x], eg = gg[x], eb = b[x];
            o0[x] = er, o1[x] = eg, o2[x] = eb;
            const float vp = v0[x] + v1[x] + v2[x];
            const float e2 = er * er + eg * eg + eb * eb;
            const bool zero = (er == 0.0f) & (eg == 0.0f) & (eb == 0.0f);
            const bool quiet = (e2 > 1e-30f) & (vp <= 0.5e-4f * e2);
            const int k = (zero | quiet) ? 0 : 1;
            c[x] = static_cast<unsigned char>(k);
            any |= k;
        }
        if (also.valid() && also.data != g.eIn.data) {
            // (`also` may be the input itself: then it holds these values already.)
            for (int ch = 0; ch < 3; ++ch)
                std::copy(g.eIn.channel(ch) + o, g.eIn.channel(ch) + o + w, also.channel(ch) + o);
        }
        if (!any) continue;
        for (int x = 0; x < w; ++x)
            if (c[x]) {
                g(x, y);
                list[size_t(y)].push_back(x);
            }
    }
}

}  // namespace

void runEmissionLevel(const CpuExec&, const EmissionLevel& f) {
    const int h = f.eIn.height;
    std::vector<std::vector<int>> list(static_cast<size_t>(h));
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 4, [&](int y0, int y1) { firstLevelRows(f, ImageView{}, y0, y1, list); });
}

ImageView runEmissionFilter(const CpuExec&, int levels, float k, ImageView variance, ImageView input, ImageView a,
                            ImageView b) {
    const int h = input.height;
    std::vector<std::vector<int>> list(static_cast<size_t>(h));
    EmissionLevel f;
    f.step = 1;
    f.sigmaMul = 2.0f * k;
    f.eIn = input, f.eOut = a, f.variance = variance;
    // Level 0 over every pixel; the copies into b too, which later levels write only at listed
    // pixels.
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 4,
                        [&](int y0, int y1) { firstLevelRows(f, levels > 1 ? b : ImageView{}, y0, y1, list); });
    ImageView cur = a, nxt = b;
    float mul = 2.0f * k;
    for (int i = 1; i < levels; ++i) {
        mul *= 0.25f;  // σ halved per level, as runEmissionFilter's
        EmissionLevel g;
        g.step = 1 << i;
        g.sigmaMul = mul;
        g.eIn = cur, g.eOut = nxt, g.variance = variance;
        cpu::parallelForIsa(cpu::activeIsa(), 0, h, 16, [&](int y0, int y1) {
            const EmissionLevel l = g;
            for (int y = y0; y < y1; ++y)
                for (int x : list[size_t(y)]) l(x, y);
        });
        cur = nxt;
        nxt = cur.data == a.data ? b : a;
    }
    return cur;
}

}  // namespace atrous::filters

// Edge-avoiding filtering of the emission buffer (docs/denoising.md, "Emission").
//
// The denoisers filter color − emission and add the emission back. Emission itself is noisy only
// where a pixel is partly covered by an emitter (the edge of a visible area light, the rim of a
// sun): its value there is the coverage fraction times the emitted radiance, estimated from n
// random sub-pixel positions (std ~ sqrt(f(1 − f)/n) of the radiance). Those edge pixels carry
// most of the error left after denoising where a light is seen (docs/decisions.md, "Still filters").
// Neighbouring edge pixels along the same edge have nearly the same coverage, so an à-trous
// cascade whose colour stop uses 2·min(var_p, var_q) (as EAW's automatic σ_c) averages edge pixels
// with each other while fully covered or uncovered pixels (variance ~0 in one of the pair) take
// no weight across the edge. Pixels with no emission at all are left at exactly 0, and pixels
// whose relative variance is below 1e-4 are copied (see EmissionLevel).
//
//   e_{i+1}(p) = Σ_q h(q) w(p,q) e_i(p + 2^i q) / Σ_q h(q) w(p,q)
//   w(p,q) = exp(−|e_i(p) − e_i(q)|² / (k · 2·min(V_p, V_q) · 4^−i)),  V = Σ_channels var
//
// Taps outside the image are dropped (normalisation keeps the weights summing to 1).
#pragma once
#include "atrous/image.h"
#include "filters/filter_math.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::filters {

struct EmissionLevel {
    int step = 1;
    float sigmaMul = 1.0f;  // k · 2 · 4^−i
    ImageView eIn, eOut, variance;
    // Forced inline on the host: with the one fastExp (itself forced inline) the functor grew past
    // GCC's inlining limit, became a call per pixel from the CPU row loop, and the pixels that
    // take the early exit below (nearly all) paid the call and reloaded the views each time
    // (docs/decisions.md, "Speed").
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float er = eIn(x, y, 0), eg = eIn(x, y, 1), eb = eIn(x, y, 2);
        const float vp = variance(x, y, 0) + variance(x, y, 1) + variance(x, y, 2);
        // No emitter sample (stays exactly 0), or a pixel whose colour is known to better than 1%
        // (relative variance < 1e-4: fully covered lights, the smooth sky): every neighbour that
        // differs by more than ~3.5% (σ² = 12·min(V_p, V_q) at most) gets no weight, and the
        // B3 average of those within it is that of a locally linear signal, i.e. e_p. Copying
        // skips 25 taps per sky pixel (docs/decisions.md, "Speed").
        const float e2 = er * er + eg * eg + eb * eb;
        if (e2 == 0.0f || !(vp > 1e-4f * e2)) {
            eOut(x, y, 0) = er;
            eOut(x, y, 1) = eg;
            eOut(x, y, 2) = eb;
            return;
        }
        const int w = eIn.width, h = eIn.height;
        float ws = 0.0f, ar = 0.0f, ag = 0.0f, ab = 0.0f;
        for (int qy = -2; qy <= 2; ++qy) {
            const int yq = y + qy * step;
            if (yq < 0 || yq >= h) continue;
            for (int qx = -2; qx <= 2; ++qx) {
                const int xq = x + qx * step;
                if (xq < 0 || xq >= w) continue;
                const float r = eIn(xq, yq, 0), g = eIn(xq, yq, 1), b = eIn(xq, yq, 2);
                const float d2 = sq(er - r) + sq(eg - g) + sq(eb - b);
                const float vq = variance(xq, yq, 0) + variance(xq, yq, 1) + variance(xq, yq, 2);
                const float s2 = sigmaMul * minSel(vp, vq);
                // d2 == 0 gives weight 1 whatever σ is (also σ = 0); otherwise σ = 0 gives 0.
                const float e = d2 > 0.0f ? (s2 > 0.0f ? d2 / s2 : 1e30f) : 0.0f;
                const float wt = b3(qx) * b3(qy) * fastExp(-e);
                ws += wt;
                ar += wt * r;
                ag += wt * g;
                ab += wt * b;
            }
        }
        // ws ≥ b3(0)² > 0: the centre tap always has weight 1 · h(0).
        const float inv = 1.0f / ws;
        eOut(x, y, 0) = ar * inv;
        eOut(x, y, 1) = ag * inv;
        eOut(x, y, 2) = ab * inv;
    }
};

// One level on `exec`. The CpuExec overload (src/cpu/emission_cpu.cpp) copies rows with a
// vectorised loop and runs the functor only on the pixels that may need the taps: the generic
// path's `omp simd` x loop would evaluate all 25 taps of every pixel under a mask, so the early
// exit (the sky, non-emitters: nearly every emissive pixel; docs/decisions.md, "Speed") saved nothing.
template <class Exec>
void runEmissionLevel(const Exec& exec, const EmissionLevel& f) {
    exec.forEachPixel(f.eIn.width, f.eIn.height, f);
}
void runEmissionLevel(const CpuExec& exec, const EmissionLevel& f);

// Runs `levels` (>= 1) levels on `exec` from `input` (not modified), ping-ponging between `a` and
// `b`; returns the view holding the result.
template <class Exec>
ImageView runEmissionFilter(const Exec& exec, int levels, float k, ImageView variance, ImageView input, ImageView a,
                            ImageView b) {
    ImageView cur = input, nxt = a;
    float mul = 2.0f * k;
    for (int i = 0; i < levels; ++i) {
        EmissionLevel f;
        f.step = 1 << i;
        f.sigmaMul = mul;
        f.eIn = cur;
        f.eOut = nxt;
        f.variance = variance;
        runEmissionLevel(exec, f);
        cur = nxt;  // the buffer just written is the next level's input
        nxt = cur.data == a.data ? b : a;
        mul *= 0.25f;  // σ halved per level, as EAW's σ_c
    }
    return cur;
}
// The CpuExec overload (src/cpu/emission_cpu.cpp): the first level over every pixel, the others
// over the pixels that need the taps only (a copied pixel is copied at every level); same values.
ImageView runEmissionFilter(const CpuExec& exec, int levels, float k, ImageView variance, ImageView input, ImageView a,
                            ImageView b);

}  // namespace atrous::filters

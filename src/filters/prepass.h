// Per-pixel passes that prepare the cascade's inputs (shared by CPU and CUDA): non-finite
// samples, fireflies (docs/denoising.md, "Fireflies"), albedo demodulation, the colour scale of the automatic
// σ_c, the pixel footprint of the automatic σ_x, and the final recombination.
#pragma once
#include "atrous/image.h"
#include "filters/filter_math.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::filters {

// Largest magnitude a feature keeps; squares of differences then stay finite in float.
constexpr float kFeatureClamp = 1e18f;

// NaN/Inf colour or variance samples are missing data: replaced by the mean of the finite values
// of the same channel in the 5×5 neighbourhood (0 when there are none), so they never spread.
struct SanitizeColor {
    ImageView colorIn, varIn;    // user buffers (varIn may be a constant estimate, or invalid: none)
    ImageView colorOut, varOut;  // c_0, var(c_0) (varOut invalid with varIn)
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int c = 0; c < 3; ++c) {
            colorOut(x, y, c) = fix(colorIn, x, y, c);
            if (varIn.valid()) varOut(x, y, c) = fix(varIn, x, y, c);
        }
    }
    ATROUS_HOST_DEVICE static float fix(const ImageView& v, int x, int y, int c) {
        const float a = v(x, y, c);
        if (finite(a)) return a;
        float s = 0;
        int n = 0;
        for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
                const int xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= v.width || yy >= v.height) continue;
                const float b = v(xx, yy, c);
                if (finite(b)) {
                    s += b;
                    ++n;
                }
            }
        return n > 0 ? s / float(n) : 0.0f;
    }
};

// Runs SanitizeColor on `exec`; the CpuExec overload (src/cpu/prepass_cpu.cpp) copies whole rows
// with a vectorised finiteness test and calls fix() only where a value is not finite. There an
// output may be its input (colorOut = colorIn, varOut = varIn): the image is then only scanned, and
// the few repairs are computed from the unrepaired values before any is written.
template <class Exec>
void runSanitizeColor(const Exec& exec, const SanitizeColor& f) {
    exec.forEachPixel(f.colorIn.width, f.colorIn.height, f);
}
void runSanitizeColor(const CpuExec& exec, const SanitizeColor& f);

// Copies a feature buffer, mapping non-finite values to 0 and clamping to ±kFeatureClamp.
// (Selects instead of fminf/fmaxf, which do not vectorise under strict IEEE flags.)
ATROUS_INLINE float sanitizeFeature(float a) {
    float b = a < -kFeatureClamp ? -kFeatureClamp : a;
    b = b > kFeatureClamp ? kFeatureClamp : b;
    return finite(a) ? b : 0.0f;
}
struct SanitizeFeature {
    ImageView in, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        if (out.channels >= 1) out(x, y, 0) = sanitizeFeature(in(x, y, 0));
        if (out.channels >= 2) out(x, y, 1) = sanitizeFeature(in(x, y, 1));
        if (out.channels >= 3) out(x, y, 2) = sanitizeFeature(in(x, y, 2));
    }
};

// The view the filters read for one feature buffer: a sanitised copy of the first `channels`
// channels of `in` kept in `storage`, or zeros when `in` is absent (its terms then vanish). The
// CpuExec overload (src/cpu/prepass_cpu.cpp) returns `in` itself, with no copy, when every value
// is already finite and within ±kFeatureClamp: the copy would equal it bit for bit.
template <class Exec>
ImageView sanitizedFeature(const Exec& exec, ImageView in, int width, int height, int channels, Image& storage) {
    storage = Image(width, height, channels, exec.device());
    if (in.valid()) exec.forEachPixel(width, height, SanitizeFeature{in, storage.view()});
    return storage.view();
}
ImageView sanitizedFeature(const CpuExec& exec, ImageView in, int width, int height, int channels, Image& storage);

// The rim albedo (docs/algorithms.md, "Albedo demodulation near black albedo"; the figures:
// docs/decisions.md, "Still filters"). Other renderers write albedo 0
// for the sky, mirrors and lights. A pixel beside such a black pixel (a 3x3 neighbour's largest
// channel below `black`, kBlackAlbedoFraction times the albedo floor) whose own largest channel
// m_p is below the neighbourhood's largest m_x is partly covered by the black surface: a thin
// slat's edge against the sky, whose colour is then mostly the sky's. Its albedo is the covered
// part's, so dividing its colour by it put values 10-30x the colour into the demodulated image,
// which the noise estimate read as noise around them and the cascade spread into the sky. The
// uncovered part counts as albedo k (the black surface is divided by nothing), each channel
// getting k (1 - m_p / m_x) added, where k = min(L_b / L_p, 1) weighs how much of the pixel's
// colour the black surface can explain: L_p its own reflected colour (colour - emission, mean of
// the channels), L_b the brightest black neighbour's (not the darkest's: docs/decisions.md, "Still
// filters", the rim albedo). A
// sky or a light without an emission buffer gives k = 1; a black void (colour 0), or a light whose
// radiance the emission buffer holds, k = 0: its colour is the covered part's alone and the albedo
// explains it as it is. `out` must not be `in`.
ATROUS_INLINE float rimReflected(const ImageView& color, const ImageView& emission, int x, int y) {
    float l = 0.0f;
    for (int c = 0; c < 3; ++c) {
        const float e = emission.valid() ? emission(x, y, c) : 0.0f;
        l += color(x, y, c) - (finite(e) ? e : 0.0f);
    }
    return maxSel(l * (1.0f / 3.0f), 0.0f);
}
ATROUS_INLINE float rimAdd(float mp, float mn, float mx, float lp, float lb, float black) {
    const float k = lp > 0.0f ? minSel(lb / lp, 1.0f) : 0.0f;
    return mp > 0.0f && mn < black ? k * (1.0f - mp / mx) : 0.0f;  // mx >= mp > 0
}
struct RimAlbedo {
    ImageView in, out, color, emission;  // color: sanitised; emission: optional
    float black = 0.0f;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float mp = maxChannel(in(x, y, 0), in(x, y, 1), in(x, y, 2));
        float mn = 3.0e38f, mx = 0.0f, lb = 0.0f;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int xx = clampIdx(x + dx, in.width - 1), yy = clampIdx(y + dy, in.height - 1);
                const float m = maxChannel(in(xx, yy, 0), in(xx, yy, 1), in(xx, yy, 2));
                mn = minSel(mn, m);
                mx = maxSel(mx, m);
                lb = maxSel(lb, m < black ? rimReflected(color, emission, xx, yy) : 0.0f);
            }
        const float add = rimAdd(mp, mn, mx, rimReflected(color, emission, x, y), lb, black);
        for (int c = 0; c < 3; ++c) out(x, y, c) = in(x, y, c) + add;
    }
};

// The albedo the filters read, with the rim albedo applied (sanitised input, 3 channels), kept in
// `storage`. The CpuExec overload (src/cpu/prepass_cpu.cpp) computes the same values row by row
// and returns `in` itself, with no copy, when the rule changes no pixel.
template <class Exec>
ImageView rimAlbedo(const Exec& exec, const RimAlbedo& f, Image& storage) {
    storage = Image(f.in.width, f.in.height, 3, exec.device());
    RimAlbedo g = f;
    g.out = storage.view();
    exec.forEachPixel(f.in.width, f.in.height, g);
    return storage.view();
}
ImageView rimAlbedo(const CpuExec& exec, const RimAlbedo& f, Image& storage);

// Plain copy of the first N channels.
template <int N>
struct CopyChannels {
    ImageView in, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int c = 0; c < N; ++c) out(x, y, c) = in(x, y, c);
    }
};
using Copy3 = CopyChannels<3>;

// out = in, 3 channels; the CpuExec overload copies rows with memcpy.
template <class Exec>
void runCopy3(const Exec& exec, const ImageView& in, const ImageView& out) {
    exec.forEachPixel(in.width, in.height, Copy3{in, out});
}
void runCopy3(const CpuExec& exec, const ImageView& in, const ImageView& out);

// Firefly suppression: L(p) above m + k·sqrt(s² + v̄) is scaled down to that bound, where m and s²
// are the mean and variance of the 3×3 neighbours' luminance without the brightest neighbour (so
// a two-pixel firefly does not vouch for itself) and v̄ is their mean luminance variance (the
// noise the renderer reported there). The variance is scaled by the same factor squared.
// A firefly is a rare huge sample, so it also inflates its own pixel's variance: a mean raised by
// E through one outlier among n samples has a standard deviation of about E (j outliers: about
// E·sqrt((1 - j/n)/j): 0.66 for 2 of 16, 0.58 for 2 of 4). A bright pixel whose own standard
// deviation is below half its excess over m (the sun seen directly, partly covering the pixel at
// 16 spp: ~0.2) is signal, not a firefly, and is kept. The two overlap at very low spp: at 4 spp
// the directly seen sun in sphere-env (2 of 4 samples) is clamped; a looser bound that keeps it
// keeps 2-sample fireflies at 16 spp (docs/decisions.md). With an estimated (constant)
// variance this test is off (ownVariance = 0).
constexpr float kFireflyOwnStd = 0.5f;  // see FireflyClamp

// Variance of a pixel's luminance from its per-channel variances, taking the channels' noise as
// fully correlated (Monte Carlo noise is: every sample's path carries all three): σ_L = Σ w_c σ_c.
// (Σ w_c² v_c, the independent-channel form, understated a white firefly's σ_L by a quarter, so
// that the own-variance test below kept it as a highlight.)
ATROUS_INLINE float lumVariance(float vr, float vg, float vb) {
    const float s = lum(sqrtf(maxSel(vr, 0.0f)), sqrtf(maxSel(vg, 0.0f)), sqrtf(maxSel(vb, 0.0f)));
    return s * s;
}
// Σ w_c² v_c: the neighbours' v̄ of the bound keeps this form; the correlated form there raised the
// bound and clamped fewer fireflies (docs/decisions.md).
ATROUS_INLINE float lumVarianceIndependent(float vr, float vg, float vb) {
    return lum(lum(1, 0, 0) * vr, lum(0, 1, 0) * vg, lum(0, 0, 1) * vb);
}

struct FireflyClamp {
    float k = 4.0f;
    int ownVariance = 1;
    ImageView cIn, vIn, cOut, vOut;
    ImageView flag;  // 1 channel: 1 where clamped (for the report), may be invalid
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = cIn.width, h = cIn.height;
        float l[8], lv[8];
        int n = 0;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                if (dx == 0 && dy == 0) continue;
                const int xx = clampIdx(x + dx, w - 1), yy = clampIdx(y + dy, h - 1);
                l[n] = lum(cIn(xx, yy, 0), cIn(xx, yy, 1), cIn(xx, yy, 2));
                lv[n] = lumVarianceIndependent(vIn(xx, yy, 0), vIn(xx, yy, 1), vIn(xx, yy, 2));
                ++n;
            }
        const float clamped = apply(x, y, l, lv);
        if (flag.valid()) flag(x, y, 0) = clamped;
    }
    // Everything after the neighbourhood gather; l, lv: the 8 neighbours' luminance and luminance
    // variance in row order (dy = -1: dx = -1, 0, 1; dy = 0: -1, 1; dy = 1: -1, 0, 1). Shared
    // with the CPU row loop (src/cpu/prepass_cpu.cpp). Returns 1 where the pixel was clamped, else 0.
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE float apply(int x, int y, const float (&l)[8], const float (&lv)[8]) const {
        bool clamp;
        const float scale = scaleOf(x, y, l, lv, clamp);
        for (int c = 0; c < 3; ++c) {
            cOut(x, y, c) = cIn(x, y, c) * scale;
            vOut(x, y, c) = vIn(x, y, c) * scale * scale;
        }
        return clamp ? 1.0f : 0.0f;
    }
    // The decision alone: the factor the pixel's colour is multiplied by (1 where it is kept) and
    // whether it was clamped.
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE float scaleOf(int x, int y, const float (&l)[8], const float (&lv)[8],
                                                          bool& clampOut) const {
        // The brightest neighbour (the first one on ties) and the others' sums, with selects
        // rather than branches so the x loop vectorises; same order of summation as before.
        int imax = 0;
        float lmax = l[0];
        for (int i = 1; i < 8; ++i) {
            const bool more = l[i] > lmax;
            imax = more ? i : imax;
            lmax = more ? l[i] : lmax;
        }
        float m = 0, m2 = 0, vm = 0;
        for (int i = 0; i < 8; ++i) {
            const bool keep = i != imax;
            const float li2 = l[i] * l[i];  // outside the select: GCC keeps a branch around FP math
            m += keep ? l[i] : 0.0f;
            m2 += keep ? li2 : 0.0f;
            vm += keep ? lv[i] : 0.0f;
        }
        m /= 7.0f;
        vm /= 7.0f;
        const float s2 = maxSel(m2 / 7.0f - m * m, 0.0f);
        const float bound = maxSel(m, 0.0f) + k * sqrtf(s2 + maxSel(vm, 0.0f));
        const float L = lum(cIn(x, y, 0), cIn(x, y, 1), cIn(x, y, 2));
        const float ownStd = sqrtf(lumVariance(vIn(x, y, 0), vIn(x, y, 1), vIn(x, y, 2)));
        // Bitwise & and | on the tests (not && and ||): no branches in the vectorised x loop.
        const bool noisy = (ownVariance == 0) | (ownStd > kFireflyOwnStd * (L - m));
        const bool clamp = (L > bound) & (L > 0.0f) & noisy;
        const float ratio = bound / L;  // unused (maybe inf) where not clamped
        clampOut = clamp;
        return clamp ? ratio : 1.0f;
    }
};

// Runs the firefly pass on `exec`; the CpuExec overload (src/cpu/prepass_cpu.cpp) computes the
// neighbours' luminances once per row and runs a vectorised x loop with the same math (its values
// agree with the functor's to a few ulps: GCC contracts the bound's multiply-adds differently in
// the two; the decisions are the same). There `clamped`, when given, receives the number of pixels
// clamped (the report's count, without a flag plane).
template <class Exec>
void runFireflyClamp(const Exec& exec, const FireflyClamp& f, int* clamped = nullptr) {
    (void)clamped;  // the GPU driver counts its flag plane
    exec.forEachPixel(f.cIn.width, f.cIn.height, f);
}
void runFireflyClamp(const CpuExec& exec, const FireflyClamp& f, int* clamped = nullptr);

// Dense fireflies (docs/algorithms-eaw-sure.md, "The firefly pass"): where many pixels of a
// neighbourhood were clamped, the bright samples are the image's light (sun patches reached by one
// bounce in an interior at a few spp), not rare outliers, and clamping them all takes the light
// away. After the pass, each pixel whose (2R+1)² window (R = kFireflyDenseRadius) holds a fraction
// ρ of clamped pixels above kFireflyDenseLo is decided again from the unclamped colour with the
// bound's k raised to k (1 + t), t = min((ρ - lo) / (hi - lo), 1): twice the deviations where ρ
// reaches kFireflyDenseHi. An isolated firefly (ρ about 1/225) is untouched. The thresholds:
// docs/decisions.md, "Still filters" (dense fireflies).
constexpr int kFireflyDenseRadius = 7;
constexpr float kFireflyDenseLo = 0.06f, kFireflyDenseHi = 0.12f;
struct FireflyDense {
    FireflyClamp pass;  // the pass as it ran: cIn/vIn unclamped, cOut/vOut/flag its results
    ImageView sums;     // 1 channel: the window sums of pass.flag (BoxSum, radius kFireflyDenseRadius)
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        // A pixel the pass kept is kept at any larger k (the bound only grows with k): as it was.
        if (!(pass.flag(x, y, 0) > 0.5f)) return;
        decide(x, y, sums(x, y, 0));
    }
    // A clamped pixel whose window holds `windowSum` clamped pixels (shared with the CPU overload).
    ATROUS_HOST_DEVICE void decide(int x, int y, float windowSum) const {
        const int w = pass.cIn.width, h = pass.cIn.height;
        const float rho = windowSum / boxTaps(kFireflyDenseRadius, x, y, w, h);
        const float t = minSel((rho - kFireflyDenseLo) * (1.0f / (kFireflyDenseHi - kFireflyDenseLo)), 1.0f);
        if (!(t > 0.0f)) return;  // the first decision stands
        FireflyClamp g = pass;
        g.k = pass.k * (1.0f + t);
        g(x, y);  // from cIn again: writes cOut, vOut and the flag
    }
};
// The dense-firefly step after runFireflyClamp (f.flag must be a valid 1-channel plane); tmp and
// sums: 1-channel scratch planes of the image's size.
// The CpuExec overload (src/cpu/prepass_cpu.cpp) slides the window sums along rows and columns
// (exact: sums of 0/1 flags) and decides again only where the window is dense: the same decisions,
// the values to a few ulps (the functor's instantiations contract the bound's multiply-add
// differently, as in runFireflyClamp), at a fraction of the cost; it leaves `sums` unwritten.
template <class Exec>
void runFireflyDense(const Exec& exec, const FireflyClamp& f, const ImageView& tmp, const ImageView& sums) {
    runBoxSum(exec, BoxSum<false>{kFireflyDenseRadius, f.flag, tmp});
    runBoxSum(exec, BoxSum<true>{kFireflyDenseRadius, tmp, sums});
    exec.forEachPixel(f.cIn.width, f.cIn.height, FireflyDense{f, sums});
}
void runFireflyDense(const CpuExec& exec, const FireflyClamp& f, const ImageView& tmp, const ImageView& sums);

// Per-pixel colour scale S of the automatic σ_c: k_c² · (3×3 [1 2 1]² / 16 prefilter of the
// channel-summed variance, without its largest neighbour, renormalised) — prefiltered because a
// few-sample variance estimate is itself noisy, and without the largest neighbour so that one
// very noisy bright pixel (the sun seen directly) does not raise the scale of the quiet pixels
// around it. With a raw σ_c, S = σ_c²/2 so that 2 min(S(p), S(q)) = σ_c².
struct ColorScale {
    float rawSigma = 0;  // > 0: the paper's constant σ_c
    float k2 = 1;
    ImageView var, S;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        if (rawSigma > 0) {
            S(x, y, 0) = 0.5f * rawSigma * rawSigma;
            return;
        }
        float v[9];
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int xx = clampIdx(x + dx, var.width - 1), yy = clampIdx(y + dy, var.height - 1);
                v[(dy + 1) * 3 + dx + 1] = var(xx, yy, 0) + var(xx, yy, 1) + var(xx, yy, 2);
            }
        S(x, y, 0) = scale(v);
    }
    // S from the 3×3 channel-summed variances v in row order (v[4] the centre); shared with the
    // CPU row loop (src/cpu/prepass_cpu.cpp). Selects, not branches, so that loop vectorises.
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE float scale(const float (&v)[9]) const {
        float s = 0, vmax = -1, wmax = 0;
        for (int i = 0; i < 9; ++i) {
            const float wt = (i % 3 == 1 ? 2.0f : 1.0f) * (i / 3 == 1 ? 2.0f : 1.0f) * (1.0f / 16.0f);
            s += wt * v[i];
            const bool more = (i != 4) & (v[i] > vmax);  // the largest neighbour, the first on ties
            vmax = more ? v[i] : vmax;
            wmax = more ? wt : wmax;
        }
        return k2 * (s - wmax * vmax) / (1.0f - wmax);
    }
};

// Runs ColorScale on `exec`; the CpuExec overload sums the variance channels of three rows once
// per row and runs a vectorised x loop over the interior with the shared ColorScale::scale.
template <class Exec>
void runColorScale(const Exec& exec, const ColorScale& f) {
    exec.forEachPixel(f.var.width, f.var.height, f);
}
void runColorScale(const CpuExec& exec, const ColorScale& f);

// Distance that stands for a neighbour outside the image in the footprint's per-axis minimum.
constexpr float kFootprintBorder = 3.0e38f;

// invX = 1/σ_x² per pixel and invZ = 1/z. Automatic σ_x: k_x · F(p), F the world-space size of a
// pixel at p: per axis the smaller of the forward and backward position differences (the smaller,
// so a silhouette next to p does not inflate it), then the larger of the two axes (so a surface
// seen at a grazing angle still passes along its long axis). The tap's pixel offset multiplies
// σ_x later (eawPositionTapScale).
struct Footprint {
    int hasPosition = 0;
    float rawSigma = 0;  // > 0: constant σ_x
    float k2 = 1;
    ImageView position, depth, invX, invZ;  // invZ (and depth) invalid: no depth stop, not written
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        if (invZ.valid()) invZ(x, y, 0) = 1.0f / maxSel(fabsf(depth(x, y, 0)), 1e-6f);
        if (!hasPosition) {
            invX(x, y, 0) = 0.0f;
            return;
        }
        if (rawSigma > 0) {
            invX(x, y, 0) = 1.0f / (rawSigma * rawSigma);
            return;
        }
        const int w = position.width, h = position.height;
        invX(x, y, 0) = invXOf(dist2(x, y, clampIdx(x + 1, w - 1), y), dist2(x, y, clampIdx(x - 1, w - 1), y),
                               dist2(x, y, x, clampIdx(y + 1, h - 1)), dist2(x, y, x, clampIdx(y - 1, h - 1)));
    }
    ATROUS_HOST_DEVICE float dist2(int x0, int y0, int x1, int y1) const {
        if (x0 == x1 && y0 == y1) return kFootprintBorder;  // image border: use the other side only
        return sq(position(x0, y0, 0) - position(x1, y1, 0)) + sq(position(x0, y0, 1) - position(x1, y1, 1)) +
               sq(position(x0, y0, 2) - position(x1, y1, 2));
    }
    // 1/σ_x² from the squared position distances to the right, left, lower and upper neighbours
    // (kFootprintBorder where that neighbour is outside the image); shared with the CPU row loop.
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE float invXOf(float dxp, float dxm, float dyp, float dym) const {
        const float fx = minSel(dxp, dxm);
        const float fy = minSel(dyp, dym);
        const float f2 = maxSel(fx, fy);
        // 1e-20 keeps the inverse finite (1e20) on degenerate footprints (e.g. background).
        return 1.0f / (k2 * f2 + 1e-20f);
    }
};

// Runs Footprint on `exec`; the CpuExec overload runs vectorised row loops with the shared
// Footprint::invXOf (the automatic σ_x; the other modes go through the functor).
template <class Exec>
void runFootprint(const Exec& exec, const Footprint& f) {
    exec.forEachPixel(f.invX.width, f.invX.height, f);
}
void runFootprint(const CpuExec& exec, const Footprint& f);

// c_0 -= emission (the emission itself is noise-free given the pixel's samples).
struct SubtractEmission {
    ImageView emission, color;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        color(x, y, 0) -= emission(x, y, 0);
        color(x, y, 1) -= emission(x, y, 1);
        color(x, y, 2) -= emission(x, y, 2);
    }
};

}  // namespace atrous::filters

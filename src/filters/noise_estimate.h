// Per-pixel noise variance when the renderer gave none (docs/algorithms.md, "Noise without a
// variance buffer"): Blender Cycles and Mitsuba write no variance pass. One number for the whole
// image (Donoho's MAD) takes a caustic or a speckled rough metal for signal, since their noise is
// many times the image's typical level. Here the variance at p is the mean energy of the finest
// B3 detail d_0 = c - B3 * c (of the demodulated colour, so texture edges do not count) over the
// quietest of the four (r+1)² quadrants that have p as a corner: a geometric edge through p
// leaves at least one quadrant on one side, while dense noise (a caustic) fills all four. An
// isolated firefly fills one, so it is left to the firefly pass. Floored at the global estimate
// (the local one only raises it where the noise is higher) and capped at kNoiseCapMul times it. Shared by CPU and CUDA (the driver runs it on its executor).
#pragma once
#include <cmath>

#include "atrous/image.h"
#include "filters/filter_math.h"
#include "filters/modulation.h"

namespace atrous {
struct CpuExec;
struct CudaExec;
}

namespace atrous::filters {

// The median of the finite values of a 1-channel image (`none` when it has none; +Inf and NaN
// are skipped), reordering the image: the global noise estimate's per-channel median of the B3
// details and the safety net's calibration. CPU: nth_element (src/filters/denoise.cpp); CUDA: a
// device sort (src/cuda/cuda_denoise.cu).
float medianFinite(const CpuExec& exec, const ImageView& v, float none);
float medianFinite(const CudaExec& exec, const ImageView& v, float none);

// The local estimate is capped at this many times the global one. A visible light's edge or a
// sun's rim reads as noise thousands of times the image's, and the colour stop then opened across
// it. 128: the best cap on the corpus's geometric mean (docs/decisions.md).
constexpr float kNoiseCapMul = 128.0f;
// DetailEnergy leaves out a tap whose colour differs from p's by more than sqrt(kNoiseEdgeSigmas2
// · kNoiseCapMul) global standard deviations (68: 6 times the largest local deviation the cap
// allows): an edge in the colour itself, such as a visible light in a wall of the same normal and
// depth, whose B3 detail otherwise raised the estimate on both sides and opened the colour stop
// across the light's edge (RobustInputs.VisibleLightWithoutEmissionBufferKeepsItsEdge). A smaller
// bound loses glass caustics, a larger one that light edge (docs/decisions.md).
constexpr float kNoiseEdgeSigmas2 = 36.0f;
// The variance of a background pixel (a zero normal), as a fraction of the global estimate, in
// place of the local estimate. The global estimate is of the image's surfaces, and the local one
// reads a sky's gradient toward the horizon as noise: with either, the filter smoothed the sky
// and, on Cycles' sky below the horizon, pulled the horizon's bright rows into the dark ones
// (docs/decisions.md).
constexpr float kNoiseBackgroundFloor = 0.01f;

// var(d_0) = σ² (1 + Σ h² - 2 h(0)) for white noise under the 5×5 B3 kernel (see estimateNoiseSigma).
constexpr float kDetailVarFactor = float(1.0 + (70.0 / 256.0) * (70.0 / 256.0) - 2.0 * (6 / 16.0) * (6 / 16.0));

// Donoho's finest B3 detail |v − (B3 ∗ v)(p)| per channel of v (the demodulated colour:
// Demodulate (modulation.h) into a copy, so that texture, which the filters never see, does not read as noise), over
// clamped borders in double sums: the global estimate's input on the CPU (estimateNoiseSigma) and
// the GPU (estimateNoiseSigmaCuda) alike. Pixels with a non-finite value in their 5×5 window get
// +Inf (sorted after every detail).
struct MadDetail {
    ImageView color, detail;  // color: v; detail: 3 planes
    ATROUS_HOST_DEVICE float value(int x, int y, int c) const { return color(x, y, c); }
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = color.width, h = color.height;
        for (int c = 0; c < 3; ++c) {
            float d = INFINITY;
            const float v = value(x, y, c);
            if (finite(v)) {
                double s = 0, ws = 0;
                bool ok = true;
                for (int qy = -2; qy <= 2 && ok; ++qy)
                    for (int qx = -2; qx <= 2; ++qx) {
                        const float u = value(clampIdx(x + qx, w - 1), clampIdx(y + qy, h - 1), c);
                        if (!finite(u)) {
                            ok = false;
                            break;
                        }
                        s += double(b3(qx) * b3(qy)) * u;
                        ws += b3(qx) * b3(qy);
                    }
                if (ok) d = fabsf(float(v - s / ws));
            }
            detail(x, y, c) = d;
        }
    }
};

// Donoho's global estimate on `exec`, per channel: σ_c = median |d_0,c| / 0.6745 /
// sqrt(kDetailVarFactor) over the pixels whose 5×5 window is finite (0 when none is), of `color`
// divided by a' when `albedo` is valid. estimateNoiseSigma (CPU) and estimateNoiseSigmaCuda.
// The CpuExec overload (src/cpu/noise_cpu.cpp): the demodulation and the 25 double taps in row
// loops (the same sums in the same order), the median by a radix histogram and a selection within
// one bin, not a partition of the whole plane: the same σ, several times faster.
template <class Exec>
void globalNoiseSigma(const Exec& exec, const ImageView& color, const ImageView& albedo, float eps, float floor,
                      float sigma[3]) {
    const int w = color.width, h = color.height;
    Image detail(w, h, 3, exec.device()), demod;
    if (albedo.valid()) {
        demod = Image(w, h, 3, exec.device());
        Demodulate d;  // c / a', the still filters' rule (modulation.h)
        d.rule.eps = eps, d.rule.floor = floor;
        d.albedo = albedo, d.in = color, d.out = demod.view();
        exec.forEachPixel(w, h, d);
    }
    exec.forEachPixel(w, h, MadDetail{albedo.valid() ? demod.view() : color, detail.view()});
    exec.synchronize();
    for (int c = 0; c < 3; ++c) {
        const float mid = medianFinite(exec, ImageView{detail.view().channel(c), w, h, 1}, 0.0f);
        sigma[c] = float(double(mid) / 0.6745 / std::sqrt(double(kDetailVarFactor)));
    }
}
void globalNoiseSigma(const CpuExec& exec, const ImageView& color, const ImageView& albedo, float eps, float floor,
                      float sigma[3]);
// The same with its 3-plane detail image in `scratch` (the caller's planes, written over).
void globalNoiseSigma(const CpuExec& exec, const ImageView& color, const ImageView& albedo, float eps, float floor,
                      float sigma[3], const ImageView& scratch);

// e_c(p) = d_0,c(p)² / kDetailVarFactor: an unbiased per-pixel estimate of σ_c² on white noise.
// The B3 taps across a geometric edge (normals further apart than kNoiseNormalDist, or depths
// more than kNoiseDepthRel apart relative to p's) are left out and the rest renormalised, so a
// light's edge or a one-pixel strip of wall beside it does not read as noise.
constexpr float kNoiseNormalDist2 = 0.1f;  // |n_p - n_q|² (about 18 degrees)
constexpr float kNoiseDepthRel = 0.05f;
// DetailEnergy's albedo fit needs this much albedo variance over the taps (a standard deviation
// of 0.003): below it the albedo is flat and explains nothing.
constexpr float kNoiseFitMinVar = 1e-5f;
struct DetailEnergy {
    ImageView color, energy;  // color: c_0 demodulated (Demodulate into a copy), energy: out (3 ch)
    ImageView normal, depth;  // sanitised; invalid when absent (read as 0: no geometric edge)
    // A tap further from p than this (squared, per channel) is across an edge in the colour itself
    // (a visible light in a wall of the same normal and depth), left out as a geometric edge is.
    float maxDiff2[3] = {3.0e38f, 3.0e38f, 3.0e38f};
    // Optional, off while invalid (the driver does not set it yet): the albedo buffer. The part of
    // the detail that the albedo's own detail explains (a least-squares fit of c on a, per
    // channel, over the same taps) is signal, not noise: a component the albedo does not multiply
    // (a dielectric's specular layer over a fine texture) leaves the demodulation c / a' with the
    // texture's pattern, and read as noise it opened the colour stop across the texture. It wins at
    // 16 spp and loses at 4 (the fit also takes pure noise's energy where the albedo varies:
    // tests/noise_fit_test.cpp), so it is off until the whole table says it pays (and the learned
    // filter's training planes, which use this estimate, agree): docs/decisions.md.
    ImageView albedo;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = color.width, h = color.height;
        const bool hasN = normal.valid(), hasZ = depth.valid();
        const float nx = hasN ? normal(x, y, 0) : 0.0f, ny = hasN ? normal(x, y, 1) : 0.0f,
                    nz = hasN ? normal(x, y, 2) : 0.0f, zp = hasZ ? depth(x, y, 0) : 0.0f;
        const float cp[3] = {color(x, y, 0), color(x, y, 1), color(x, y, 2)};
        float s[3] = {0, 0, 0}, ws = 0, w2 = 0;
        float sa[3] = {0, 0, 0}, saa[3] = {0, 0, 0}, sac[3] = {0, 0, 0};
        const bool fit = albedo.valid();
        for (int qy = -2; qy <= 2; ++qy)
            for (int qx = -2; qx <= 2; ++qx) {
                const int xx = clampIdx(x + qx, w - 1), yy = clampIdx(y + qy, h - 1);
                const float dn = hasN ? sq(nx - normal(xx, yy, 0)) + sq(ny - normal(xx, yy, 1)) + sq(nz - normal(xx, yy, 2))
                                      : 0.0f;
                const float dz = hasZ ? fabsf(zp - depth(xx, yy, 0)) : 0.0f;
                const bool near = (sq(color(xx, yy, 0) - cp[0]) <= maxDiff2[0]) & (sq(color(xx, yy, 1) - cp[1]) <= maxDiff2[1]) &
                                  (sq(color(xx, yy, 2) - cp[2]) <= maxDiff2[2]);
                const bool same = (dn <= kNoiseNormalDist2) & (dz <= kNoiseDepthRel * fabsf(zp)) & near;
                const float wt = same ? b3(qx) * b3(qy) : 0.0f;
                ws += wt;
                w2 += wt * wt;
                for (int c = 0; c < 3; ++c) s[c] += wt * color(xx, yy, c);
                if (fit)
                    for (int c = 0; c < 3; ++c) {
                        const float a = albedo(xx, yy, c);
                        const float af = finite(a) ? a : 0.0f;
                        sa[c] += wt * af;
                        saa[c] += wt * af * af;
                        sac[c] += wt * af * color(xx, yy, c);
                    }
            }
        // var(c_p - Σ w_q c_q / W) = σ² (1 - 2 w_p/W + Σ w_q²/W²) for white noise: the same
        // unbiasing as kDetailVarFactor, for the renormalised weights.
        const float wp = b3(0) * b3(0);
        const float factor = 1.0f - 2.0f * wp / ws + w2 / (ws * ws);
        for (int c = 0; c < 3; ++c) {
            float d = color(x, y, c) - s[c] / ws;
            if (fit) {
                const float ma = sa[c] / ws, va = saa[c] / ws - ma * ma;
                const float ap = albedo(x, y, c);
                if (va > kNoiseFitMinVar && finite(ap)) d -= (sac[c] / ws - ma * s[c] / ws) / va * (ap - ma);
            }
            energy(x, y, c) = factor > 1e-3f ? d * d / factor : 0.0f;
        }
    }
};

// The global estimate in the colour's units: var_c(p) = floorVar_c · a'_c(p)² (the floor is of the
// demodulated colour). The variance the firefly pass and the emission filter see before the local
// estimate replaces it.
struct GlobalVariance {
    float floorVar[3] = {0, 0, 0};
    float eps = 1e-3f, floor = 0.0f;
    ImageView albedo, var;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float m[3];
        pixelModulationAlbedo(albedo, x, y, eps, floor, m);
        for (int c = 0; c < 3; ++c) {
            const float a = m[c];
            var(x, y, c) = floorVar[c] * a * a;
        }
    }
};

// Runs GlobalVariance on `exec`; the CpuExec overload (src/cpu/modulation_cpu.cpp) is a row loop.
template <class Exec>
void runGlobalVariance(const Exec& exec, const GlobalVariance& f) {
    exec.forEachPixel(f.var.width, f.var.height, f);
}
void runGlobalVariance(const CpuExec& exec, const GlobalVariance& f);

// Row half-sums of the energy: left(p) = Σ_{i=0..r} e(x - i, y), right(p) = Σ_{i=0..r} e(x + i, y)
// (inside the image), per channel, and their tap counts: the first pass of the quadrant sums.
// rows: 8 channels (left rgb, right rgb, left count, right count).
struct QuadrantRows {
    int radius = 5;
    ImageView energy, rows;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = energy.width;
        float l[3] = {0, 0, 0}, r[3] = {0, 0, 0};
        int nl = 0, nr = 0;
        for (int i = 0; i <= radius; ++i) {
            if (x - i >= 0) {
                for (int c = 0; c < 3; ++c) l[c] += energy(x - i, y, c);
                ++nl;
            }
            if (x + i < w) {
                for (int c = 0; c < 3; ++c) r[c] += energy(x + i, y, c);
                ++nr;
            }
        }
        for (int c = 0; c < 3; ++c) rows(x, y, c) = l[c], rows(x, y, 3 + c) = r[c];
        rows(x, y, 6) = float(nl);
        rows(x, y, 7) = float(nr);
    }
};

// var_c(p) = max(a'_c² × mean of e_c over the quadrant of least total energy, floorVar_c), in the
// colour's units (a' the modulation albedo): column sums of QuadrantRows over the rows y - r..y
// and y..y + r. Writes `var` (3 ch).
struct LocalVariance {
    int radius = 5;
    float floorVar[3] = {0, 0, 0};  // in the demodulated colour's units (as the energy)
    float capMul = 3.0e38f;  // the estimate is at most capMul × floorVar
    float eps = 1e-3f, floor = 0.0f;
    ImageView rows, albedo, var;
    // A pixel whose normal is 0 sees the background (no surface: the sky, an environment map),
    // which renderers look up directly for camera rays, so it is as good as noise-free: its
    // variance is kNoiseBackgroundFloor times the global estimate. Invalid (no normal buffer): no
    // pixel is background.
    ImageView normal;
    // Also demodulate the estimate: var_c /= a'_c² (as Demodulate's var *= (1/a')², after it), for
    // a driver that demodulated the colour first.
    int divide = 0;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int h = rows.height;
        const bool bg = normal.valid() && normal(x, y, 0) == 0.0f && normal(x, y, 1) == 0.0f && normal(x, y, 2) == 0.0f;
        const float fm = bg ? kNoiseBackgroundFloor : 1.0f;
        float q[4][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};  // up-left, up-right, down-left, down-right: rgb, n
        for (int j = 0; j <= radius; ++j) {
            for (int half = 0; half < 2; ++half) {  // 0: up (y - j), 1: down (y + j)
                const int yy = half == 0 ? y - j : y + j;
                if (yy < 0 || yy >= h) continue;
                for (int side = 0; side < 2; ++side) {  // 0: left, 1: right
                    float* t = q[2 * half + side];
                    for (int c = 0; c < 3; ++c) t[c] += rows(x, yy, 3 * side + c);
                    t[3] += rows(x, yy, 6 + side);
                }
            }
        }
        int best = 0;
        float bestMean = 3.0e38f;
        for (int k = 0; k < 4; ++k) {
            const float m = (q[k][0] + q[k][1] + q[k][2]) / q[k][3];  // q[k][3] >= 1: the pixel itself
            if (m < bestMean) bestMean = m, best = k;
        }
        float m[3];
        pixelModulationAlbedo(albedo, x, y, eps, floor, m);
        for (int c = 0; c < 3; ++c) {
            const float a = m[c];
            const float local = bg ? 0.0f : q[best][c] / q[best][3];
            const float v = minSel(maxSel(local, fm * floorVar[c]), capMul * floorVar[c]) * a * a;
            const float out = finite(v) ? v : floorVar[c] * a * a;
            if (divide) {
                const float ia = 1.0f / a;
                var(x, y, c) = out * (ia * ia);
            } else {
                var(x, y, c) = out;
            }
        }
    }
};

// The local estimate of the driver (step 2, without a variance buffer): `var` ← the per-pixel
// variance of `color`, the firefly-clamped colour already demodulated (Demodulate, the still
// rule), in the demodulated colour's units: DetailEnergy, QuadrantRows and LocalVariance (divide
// on), the colour-edge threshold maxDiff2 = kNoiseEdgeSigmas2 · kNoiseCapMul · floorVar.
struct LocalNoise {
    int radius = 5;
    float floorVar[3] = {0, 0, 0};
    float maxDiff2[3] = {3.0e38f, 3.0e38f, 3.0e38f};
    float capMul = kNoiseCapMul;
    float eps = 1e-3f, floor = 0.0f;
    ImageView color;           // 3 ch, demodulated
    ImageView normal, depth;   // sanitised, invalid when not given (normal: also the background test)
    ImageView albedo;          // sanitised, invalid without demodulation
    ImageView var;             // out, 3 ch
    ImageView scratch;         // optional, 3 ch: planes the caller has no use for (the CPU's energy)
};

// On `exec`: the three functors through image-sized temporaries (energy 3 planes, row sums 8). The
// CpuExec overload (src/cpu/noise_cpu.cpp) runs the energy as a vectorised row loop into one
// 3-plane temporary, and the row sums and the quadrant choice per band of rows from a ring of row
// sums (no 8-plane temporary); the same sums in the same order, so the same values.
template <class Exec>
void runLocalNoise(const Exec& exec, const LocalNoise& f) {
    const int w = f.color.width, h = f.color.height;
    const Device dev = exec.device();
    Image energy = Image::uninitialized(w, h, 3, dev), rows = Image::uninitialized(w, h, 8, dev);
    DetailEnergy de;
    de.color = f.color, de.energy = energy.view(), de.normal = f.normal, de.depth = f.depth;  // albedo fit off
    for (int c = 0; c < 3; ++c) de.maxDiff2[c] = f.maxDiff2[c];
    exec.forEachPixel(w, h, de);
    exec.forEachPixel(w, h, QuadrantRows{f.radius, energy.view(), rows.view()});
    LocalVariance lv;
    lv.radius = f.radius;
    lv.capMul = f.capMul;
    for (int c = 0; c < 3; ++c) lv.floorVar[c] = f.floorVar[c];
    lv.eps = f.eps;
    lv.floor = f.floor;
    lv.rows = rows.view();
    lv.albedo = f.albedo;
    lv.var = f.var;
    lv.normal = f.normal;
    lv.divide = 1;
    exec.forEachPixel(w, h, lv);
    exec.synchronize();  // before the temporaries die
}
void runLocalNoise(const CpuExec& exec, const LocalNoise& f);

}  // namespace atrous::filters

// The learned filter v4's per-pixel math (docs/learned.md), host and device: the network's shape,
// its parameters, the input transfers, the MLP and its output transfers. Written once; the
// functors of filters/learned.h (the GPU, and the CPU reference) and the CPU row loops of
// src/cpu/learned_cpu.cpp call these same functions. Lane-parallel where it matters: learnedMlp<N>
// runs N pixels at once with the pixel index innermost (N = 1 in a functor, 16 in the CPU rows,
// where the compiler turns the lane loops into vector instructions).
//
// The transcendental functions are branch-free polynomials (learnedLog, and fastExp of
// filters/atrous_math.h) spelled out with fmaf, so the CPU row loops vectorise them (libm's do not
// without -ffast-math) and host and device compute the same values.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstring>

#include "filters/atrous_math.h"

namespace atrous::filters {

constexpr int kLearnedIn = 15, kLearnedHidden = 24, kLearnedFeat = 8, kLearnedLevels = 5;
constexpr int kLearnedOut = kLearnedFeat + 4 * kLearnedLevels + (kLearnedLevels + 1);  // 34
// Output slices, in the weight file's order: f, a_i, m_i, b_i, c_i, beta_j.
constexpr int kLearnedOutA = kLearnedFeat, kLearnedOutM = kLearnedOutA + kLearnedLevels,
              kLearnedOutB = kLearnedOutM + kLearnedLevels, kLearnedOutC = kLearnedOutB + kLearnedLevels,
              kLearnedOutBeta = kLearnedOutC + kLearnedLevels;
constexpr float kLearnedDepthMin = 1e-3f, kLearnedDepthMax = 1e4f, kLearnedKappaEps = 0.01f;
// nu's floor relative to the pixel's brightness 0.01 + mean_c d^2 (model.py's NU_REL): with v >= 0
// it keeps nu's denominator >= 1e-5.
constexpr float kLearnedNuRel = 0.001f;

// The context branch (version 4; filters/learned_context.h): 13 cell inputs at a quarter of the
// resolution, convolutions of kLearnedCtx channels, and a 1x1 layer to the first hidden layer.
constexpr int kLearnedCell = 4, kLearnedCtxIn = 13, kLearnedCtx = 16;
// Its parameters, the weight file's order: kernels HWIO (k[((ky * 3 + kx) * in + i) * out + o]).
struct LearnedCtxNet {
    float k1[9 * kLearnedCtxIn * kLearnedCtx], kb1[kLearnedCtx];
    float k2[9 * kLearnedCtx * kLearnedCtx], kb2[kLearnedCtx];
    float k3[9 * kLearnedCtx * kLearnedCtx], kb3[kLearnedCtx];
    float k4[9 * 2 * kLearnedCtx * kLearnedCtx], kb4[kLearnedCtx];
    float kz[kLearnedCtx * kLearnedHidden], kbz[kLearnedHidden];
};

// The network's parameters, the weight file's order (row-major: w1[i * kLearnedHidden + j] maps
// input i to unit j), then the context branch's. context: false for a version-3 file (ctx all
// zero: the context changes nothing and is not computed).
struct LearnedNet {
    float w1[kLearnedIn * kLearnedHidden], b1[kLearnedHidden];
    float w2[kLearnedHidden * kLearnedHidden], b2[kLearnedHidden];
    float w3[kLearnedHidden * kLearnedOut], b3[kLearnedOut];
    LearnedCtxNet ctx;
    bool context;
};
constexpr int kLearnedMlpParams = 1834;
constexpr int kLearnedCtxParams = int(sizeof(LearnedCtxNet) / sizeof(float));
constexpr int kLearnedParams = kLearnedMlpParams + kLearnedCtxParams;
static_assert(offsetof(LearnedNet, ctx) == kLearnedMlpParams * sizeof(float), "the MLP has 1834 parameters");
static_assert(kLearnedCtxParams == 11560, "the context branch has 11560 parameters");

ATROUS_FORCE_INLINE ATROUS_INLINE float learnedFinite(float v) { return selectF(finite(v), v, 0.0f); }
// maxSel/minSel (the same values, NaN a gives b) as bit selects: after learnedFinite's select GCC
// turned their `?:` into a branch and left the pass-A loop scalar.
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedMax(float a, float b) { return selectF(a > b, a, b); }
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedMin(float a, float b) { return selectF(a < b, a, b); }

// ln x for finite x > 0 (normal floats; no special cases): Cephes' logf, branch-free. x = m 2^e with
// m in [sqrt(1/2), sqrt(2)), ln x = e ln 2 + ln m, ln(1 + t) by a degree-9 polynomial (relative error
// below 1e-7 on that range); ln 2 in two parts, so e ln 2 adds no rounding.
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedLog(float x) {
    int bits;
    std::memcpy(&bits, &x, sizeof(float));
    int e = ((bits >> 23) & 0xff) - 126;  // x = m 2^e, m in [0.5, 1)
    bits = (bits & 0x007fffff) | 0x3f000000;
    float m;
    std::memcpy(&m, &bits, sizeof(float));
    const bool lo = m < 0.707106781186547524f;
    e -= int(lo);
    const float t = (m + selectF(lo, m, 0.0f)) - 1.0f;  // exact: 2m - 1 or m - 1
    const float z = t * t;
    float y = 7.0376836292e-2f;
    y = fmaf(y, t, -1.1514610310e-1f);
    y = fmaf(y, t, 1.1676998740e-1f);
    y = fmaf(y, t, -1.2420140846e-1f);
    y = fmaf(y, t, 1.4249322787e-1f);
    y = fmaf(y, t, -1.6668057665e-1f);
    y = fmaf(y, t, 2.0000714765e-1f);
    y = fmaf(y, t, -2.4999993993e-1f);
    y = fmaf(y, t, 3.3333331174e-1f);
    y = y * t * z;
    const float fe = float(e);
    y = fmaf(fe, -2.12194440e-4f, y);
    y = fmaf(z, -0.5f, y);
    return fmaf(fe, 0.693359375f, t + y);
}

// ln(1 + x) for finite x >= 0: ln u · x / (u - 1) with u = 1 + x corrects the rounding of 1 + x
// (x itself where u rounds to 1).
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedLog1p(float x) {
    const float u = 1.0f + x, d = u - 1.0f;
    return selectF(d == 0.0f, x, learnedLog(u) * (x / d));
}

// softplus(x) = max(x, 0) + ln(1 + e^-|x|) (e^-|x| by fastExp: 0 below -80, where it adds < 1e-34).
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedSoftplus(float x) {
    return learnedMax(x, 0.0f) + learnedLog1p(fastExp(-fabsf(x)));
}

// The brightness 0.01 + mean_c d_c^2 of the level's colour at the centre, and kappa = 1 / it.
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedBright(float r, float g, float b) {
    return kLearnedKappaEps + (r * r + g * g + b * b) * (1.0f / 3.0f);
}
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedKappa(float r, float g, float b) {
    return 1.0f / learnedBright(r, g, b);
}
// The noise-relative term's floor at the centre: v(p) + NU_REL (0.01 + mean_c d_c^2) (> 0 for v >= 0);
// nu(p, q) = 1 / (it + v(q)).
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedNuFloor(float v, float r, float g, float b) {
    return v + kLearnedNuRel * learnedBright(r, g, b);
}

// The input transfers (docs/learned.md, "Network inputs"); non-finite plane values read as 0.
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedLogColour(float d) { return learnedLog1p(learnedMax(learnedFinite(d), 0.0f)); }
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedLum(float r, float g, float b) {
    return learnedLog1p(learnedMax((learnedFinite(r) + learnedFinite(g) + learnedFinite(b)) * (1.0f / 3.0f), 0.0f));
}
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedAlbedoIn(float a) { return learnedMin(learnedMax(learnedFinite(a), 0.0f), 1.0f); }
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedDepthIn(float z) {
    return learnedLog(learnedMin(learnedMax(learnedFinite(z), kLearnedDepthMin), kLearnedDepthMax));
}
// The cascade's noise plane v = max(mean_c var_c, 0), non-finite var read as 0 (features.variance_plane).
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedVariance(float r, float g, float b) {
    return learnedMax((learnedFinite(r) + learnedFinite(g) + learnedFinite(b)) * (1.0f / 3.0f), 0.0f);
}
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedNoiseIn(float r, float g, float b) {
    return learnedLog1p(sqrtf(learnedVariance(r, g, b)));
}
// The 3x3 box of one quantity from its three column sums (left, centre, right; 0 outside the
// image), inv = 1 / the number of taps inside the image.
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedBox(float l, float c, float r, float inv) { return ((l + c) + r) * inv; }
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedLocalStd(float meanL, float meanL2) {
    return sqrtf(learnedMax(meanL2 - meanL * meanL, 0.0f));
}

// ATROUS_LANES (the lane loops: `omp simd` on the host) and ATROUS_DEVICE_UNROLL (a layer's unit
// loop unrolled by nvcc) are defined in atrous/platform.h, the one place that asks which compiler.

// One dense layer on N pixels: y[j][l] = act(b[j] + sum_i x[i][l] w[i * NO + j]), the sum from the
// bias in the order of i, one unit per pass over x (the multiply-adds, not the loads, bound it:
// docs/decisions.md, "Speed").
// shift (kShift): a per-lane addition to the bias, shift[j][l] (the context's, layer 1).
template <int NI, int NO, bool kRelu, int N, bool kShift = false>
ATROUS_FORCE_INLINE ATROUS_INLINE void learnedLayer(const float* w, const float* b, const float (&x)[NI][N],
                                                    float (&y)[NO][N], const float (*shift)[N] = nullptr) {
    ATROUS_DEVICE_UNROLL
    for (int j = 0; j < NO; ++j) {
        float a[N];
        const float bj = b[j];
        ATROUS_LANES
        for (int l = 0; l < N; ++l) a[l] = bj;
        if constexpr (kShift) {
            ATROUS_LANES
            for (int l = 0; l < N; ++l) a[l] += shift[j][l];
        }
        for (int i = 0; i < NI; ++i) {
            const float wij = w[i * NO + j];
            ATROUS_LANES
            for (int l = 0; l < N; ++l) a[l] = fmaf(x[i][l], wij, a[l]);
        }
        ATROUS_LANES
        for (int l = 0; l < N; ++l) y[j][l] = kRelu ? learnedMax(a[l], 0.0f) : a[l];
    }
}

// The MLP on N pixels: x[i][l] input i of lane l -> y[j][l] the 34 raw (linear) outputs; kShift:
// shift[j][l] (the context's up4(z)) added to the first hidden layer's pre-activation.
template <int N, bool kShift = false>
ATROUS_FORCE_INLINE ATROUS_INLINE void learnedMlp(const LearnedNet& net, const float (&x)[kLearnedIn][N],
                                                  float (&y)[kLearnedOut][N], const float (*shift)[N] = nullptr) {
    float h1[kLearnedHidden][N], h2[kLearnedHidden][N];
    learnedLayer<kLearnedIn, kLearnedHidden, true, N, kShift>(net.w1, net.b1, x, h1, shift);
    learnedLayer<kLearnedHidden, kLearnedHidden, true>(net.w2, net.b2, h1, h2);
    learnedLayer<kLearnedHidden, kLearnedOut, false>(net.w3, net.b3, h2, y);
}

}  // namespace atrous::filters

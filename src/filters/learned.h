// The learned à-trous filter's per-pixel math (docs/learned.md), host and device: LearnedPrepare
// (the inputs, albedo demodulation and the per-pixel network), LearnedStop (the edge-stop policy of
// the shared à-trous level, filters/atrous_level.h) and LearnedFinish (remodulation). The same math
// as python/atrous/learn/model.py; tests/learned_test.cpp holds the two equal on a fixture.
#pragma once
#include <cmath>

#include "atrous/image.h"
#include "filters/atrous_level.h"
#include "filters/filter_math.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::filters {

constexpr int kLearnedIn = 11, kLearnedHidden = 16, kLearnedFeat = 8, kLearnedLevels = 5;
constexpr int kLearnedOut = kLearnedFeat + 2 * kLearnedLevels;
constexpr float kLearnedAlbedoEps = 1e-3f, kLearnedAlbedoFloor = 0.05f;  // DenoiseOptions' defaults
constexpr float kLearnedDepthMin = 1e-3f, kLearnedDepthMax = 1e4f;

// The network's parameters (row-major: w1[i * kLearnedHidden + j] maps input i to unit j).
struct LearnedNet {
    float w1[kLearnedIn * kLearnedHidden], b1[kLearnedHidden];
    float w2[kLearnedHidden * kLearnedHidden], b2[kLearnedHidden];
    float w3[kLearnedHidden * kLearnedOut], b3[kLearnedOut];
};
constexpr int kLearnedParams = int(sizeof(LearnedNet) / sizeof(float));

ATROUS_INLINE float learnedFinite(float v) { return finite(v) ? v : 0.0f; }
ATROUS_INLINE float learnedSoftplus(float x) { return maxSel(x, 0.0f) + log1pf(expf(-fabsf(x))); }

// Per pixel: d = max(c - e, 0) / a' (a' of pixelModulationAlbedo), the inputs
// x = [log1p d (3), clamp(albedo, 0, 1) (3), normal (3), log clamp(depth), log1p sqrt(mean(var / a'²))]
// and the network's f (feat, kLearnedFeat planes), a_i (band) and m_i (cw, centre weights), softplus,
// kLearnedLevels planes each.
struct LearnedPrepare {
    const LearnedNet* net;  // on the executor's device
    ImageView color, variance, albedo, normal, depth, emission;  // inputs (variance/albedo/normal/depth/emission may be invalid)
    ImageView d, alb, feat, band, cw;  // outputs: 3, 3, kLearnedFeat, kLearnedLevels, kLearnedLevels channels

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float a[3];
        pixelModulationAlbedo(albedo, x, y, kLearnedAlbedoEps, kLearnedAlbedoFloor, a);
        float in[kLearnedIn], v = 0.0f;
        for (int c = 0; c < 3; ++c) {
            const float e = emission.valid() ? learnedFinite(emission(x, y, c)) : 0.0f;
            const float dc = maxSel(learnedFinite(color(x, y, c)) - e, 0.0f) / a[c];
            d(x, y, c) = dc;
            alb(x, y, c) = a[c];
            in[c] = log1pf(dc);
            in[3 + c] = albedo.valid() ? minSel(maxSel(learnedFinite(albedo(x, y, c)), 0.0f), 1.0f) : 1.0f;
            in[6 + c] = normal.valid() ? learnedFinite(normal(x, y, c)) : 0.0f;
            if (variance.valid()) v += maxSel(learnedFinite(variance(x, y, c)), 0.0f) / (a[c] * a[c]);
        }
        const float z = depth.valid() ? learnedFinite(depth(x, y, 0)) : 1.0f;
        in[9] = logf(minSel(maxSel(z, kLearnedDepthMin), kLearnedDepthMax));
        in[10] = log1pf(sqrtf(v / 3.0f));
        float h1[kLearnedHidden], h2[kLearnedHidden];
        for (int j = 0; j < kLearnedHidden; ++j) {
            float s = 0.0f;
            for (int i = 0; i < kLearnedIn; ++i) s += in[i] * net->w1[i * kLearnedHidden + j];
            h1[j] = maxSel(s + net->b1[j], 0.0f);
        }
        for (int j = 0; j < kLearnedHidden; ++j) {
            float s = 0.0f;
            for (int i = 0; i < kLearnedHidden; ++i) s += h1[i] * net->w2[i * kLearnedHidden + j];
            h2[j] = maxSel(s + net->b2[j], 0.0f);
        }
        for (int j = 0; j < kLearnedOut; ++j) {
            float s = 0.0f;
            for (int i = 0; i < kLearnedHidden; ++i) s += h2[i] * net->w3[i * kLearnedOut + j];
            s += net->b3[j];
            if (j < kLearnedFeat) feat(x, y, j) = s;
            else if (j < kLearnedFeat + kLearnedLevels) band(x, y, j - kLearnedFeat) = learnedSoftplus(s);
            else cw(x, y, j - kLearnedFeat - kLearnedLevels) = learnedSoftplus(s);
        }
    }
};

// Level i: w = h(q) exp(-a_i(p) |f_p - f_q|²), the centre tap h(0)² (1 + m_i(p)).
struct LearnedStop {
    int step_ = 1, level = 0;
    ImageView dIn, dOut, feat, band, cw;

    static constexpr int kSums = 4;  // Σw, Σw d (3)
    static constexpr bool kCentreTap = true, kRowPartialSums = false, kScalarTaps = false;
    struct Row {
        const float *r, *g, *b, *a, *m;
        const float* f[kLearnedFeat];
        float *oR, *oG, *oB;
    };
    struct Centre {
        float f[kLearnedFeat];
        float a, m;
    };
    struct TapRow {};

    ATROUS_HOST_DEVICE int width() const { return dIn.width; }
    ATROUS_HOST_DEVICE int height() const { return dIn.height; }
    ATROUS_HOST_DEVICE int step() const { return step_; }
    ATROUS_HOST_DEVICE Row row(int y) const {
        const size_t o = size_t(y) * size_t(dIn.width);
        Row R;
        R.r = dIn.channel(0) + o, R.g = dIn.channel(1) + o, R.b = dIn.channel(2) + o;
        R.a = band.channel(level) + o, R.m = cw.channel(level) + o;
        for (int k = 0; k < kLearnedFeat; ++k) R.f[k] = feat.channel(k) + o;
        R.oR = dOut.channel(0) + o, R.oG = dOut.channel(1) + o, R.oB = dOut.channel(2) + o;
        return R;
    }
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE Centre centre(const Row& R, int x) const {
        Centre c;
        for (int k = 0; k < kLearnedFeat; ++k) c.f[k] = R.f[k][x];
        c.a = R.a[x], c.m = R.m[x];
        return c;
    }
    ATROUS_HOST_DEVICE TapRow tapRow(int) const { return TapRow{}; }
    template <int QX, bool kCentre>
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void tap(const Row& R, const Centre& c, AtrousSums<kSums>& s, ptrdiff_t q,
                                                    float hxy, const TapRow&) const {
        float w;
        if constexpr (kCentre) {
            w = hxy * (1.0f + c.m);
        } else {
            float d2 = 0.0f;
            for (int k = 0; k < kLearnedFeat; ++k) d2 += sq(c.f[k] - R.f[k][q]);
            w = hxy * fastExp(-c.a * d2);
        }
        s.s[0] += w;
        s.s[1] += w * R.r[q];
        s.s[2] += w * R.g[q];
        s.s[3] += w * R.b[q];
    }
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void finish(const Row& R, int x, int, const AtrousSums<kSums>& s) const {
        const float inv = 1.0f / s.s[0];  // > 0: the centre tap's weight is at least h(0)²
        R.oR[x] = s.s[1] * inv;
        R.oG[x] = s.s[2] * inv;
        R.oB[x] = s.s[3] * inv;
    }
};

// One level through the functor (the GPU; any executor) or, on the CPU, the row engine
// (src/cpu/learned_cpu.cpp).
template <class Exec>
void runLearnedLevel(const Exec& exec, const LearnedStop& stop) {
    runAtrousLevelFunctor(exec, stop);
}
void runLearnedLevel(const CpuExec& exec, const LearnedStop& stop);

// out = d a' + e, non-finite values written as 0.
struct LearnedFinish {
    ImageView d, alb, emission, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int c = 0; c < 3; ++c) {
            const float e = emission.valid() ? learnedFinite(emission(x, y, c)) : 0.0f;
            out(x, y, c) = learnedFinite(d(x, y, c) * alb(x, y, c) + e);
        }
    }
};

// The cascade on exec: prepare, kLearnedLevels levels (ping-pong d <-> tmp), finish. Every view
// is on exec's device; `d` ends holding the filtered, demodulated colour.
template <class Exec>
void runLearnedCascade(const Exec& exec, const LearnedPrepare& prep, const ImageView& tmp, const ImageView& out) {
    exec.forEachPixel(prep.color.width, prep.color.height, prep);
    ImageView a = prep.d, b = tmp;
    for (int i = 0; i < kLearnedLevels; ++i) {
        runLearnedLevel(exec, LearnedStop{1 << i, i, a, b, prep.feat, prep.band, prep.cw});
        ImageView t = a;
        a = b, b = t;
    }
    exec.forEachPixel(out.width, out.height, LearnedFinish{a, prep.alb, prep.emission, out});
}

}  // namespace atrous::filters

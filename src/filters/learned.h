// The learned filter v4 (docs/learned.md) on the still driver's prepared planes: the functors of
// its passes, host and device, and the two entry points runLearned (CpuExec: src/cpu/learned_cpu.cpp;
// CudaExec: src/cuda/learned.cu). The same math as python/atrous/learn/model.py and features.py;
// tests/learned_test.cpp holds them equal on tests/learned_fixture.bin.
//
//   pass A  LearnedLogPass      lg = log1p(max(d, 0)) (3), L = log1p(max(mean_c d_c, 0)),
//                               v = max(mean_c var_c, 0) (the noise plane, every level's)
//   context                     (version 4) filters/learned_context.h: z, the first hidden layer's shift
//                               at 1/4 resolution, upsampled per pixel in pass B
//   pass B  LearnedNetPixel     the 15 inputs (3x3 box statistics of lg and L), the MLP, and from its
//                               outputs f, a_i, m_i, b_i (b_0 kappa_0), c_i, softmax(beta); acc = beta_0 d_0
//   level i LearnedStop<kLast>  an edge-stop policy of the shared à-trous level (atrous_level.h):
//                               w = h(q) exp(-a_i |f_p - f_q|^2 - (b_i kappa_i + c_i nu_i(p, q)) D),
//                               D = sum_c (d_i(q) - d_i(p))^2, nu_i = 1 / (v(p) + v(q) + 0.001 (0.01 +
//                               mean_c d_i(p)^2)), centre h(0)^2 (1 + m_i); its finish writes d_{i+1},
//                               acc += beta_{i+1} d_{i+1} and b_{i+1} kappa_{i+1} (kappa of d_{i+1}, for
//                               the next level)
// The output is acc. On the CPU, pass B runs row-wise with 16 pixels per MLP call and the levels
// through the row engine (src/cpu/learned_cpu.cpp); the functors are its reference.
#pragma once
#include <cstddef>
#include <memory>

#include "atrous/denoise.h"
#include "atrous/image.h"
#include "atrous/learned.h"
#include "filters/atrous_level.h"
#include "filters/learned_context.h"
#include "filters/learned_math.h"

namespace atrous {
struct CpuExec;
struct CudaExec;

struct LearnedWeights::Impl {
    filters::LearnedNet net;
};
}  // namespace atrous

namespace atrous::filters {

// The prepared planes the network reads (PreparedView, atrous/denoise.h: views on the executor's
// device, colour's size): colour and variance 3 channels; albedo, normal 3 channels and depth
// (channel 0) invalid views when absent. The rest of the view is not read.
inline PreparedView preparedView(ImageView color, ImageView variance, ImageView albedo, ImageView normal, ImageView depth) {
    PreparedView p;
    p.color = color, p.variance = variance, p.albedo = albedo, p.normal = normal, p.depth = depth;
    return p;
}

// Per-stage times of one runLearned call on the CPU (seconds; the bench's breakdown): wall clock,
// and process CPU time (std::clock, all threads: what counts on a shared machine).
struct LearnedStageTimes {
    double allocate = 0, context = 0, logs = 0, network = 0, levels = 0;
    double cpuContext = 0, cpuLogs = 0, cpuNetwork = 0, cpuLevels = 0;
};

struct LearnedCache;

// d_out, the filtered demodulated colour, into `out` (3 channels, exec's device); temporaries are
// allocated on exec's device, or kept in *cache between calls. Throws InputError for missing or
// mismatched planes.
void runLearned(const CpuExec& exec, const LearnedWeights& w, const PreparedView& in, const ImageView& out,
                LearnedStageTimes* times = nullptr, LearnedCache* cache = nullptr);
void runLearned(const CudaExec& exec, const LearnedWeights& w, const PreparedView& in, const ImageView& out,
                LearnedStageTimes* times = nullptr, LearnedCache* cache = nullptr);
// The context branch on the CPU (src/cpu/learned_context_cpu.cpp: oneDNN's convolutions): C.z of
// the planes P.
void runLearnedContextCpu(const CpuExec& exec, const LearnedCtxNet& net, const PreparedView& P,
                          const LearnedCtxPlanes& C);
// The CPU entry point's bands of rows (src/cpu/learned_cpu.cpp): 0 (default) = by size (above 4 Mpixels,
// without a cache), > 0 = bands of that many rows whenever the image is taller (tests), < 0 = never.
int& learnedCpuBandRows();
// The checks both entry points make (src/filters/learned_weights.cpp).
void checkLearnedPlanes(const LearnedWeights& w, const PreparedView& in, const ImageView& out);

// The cascade's temporaries, carved from one block of kLearnedTempChannels planes.
struct LearnedTemps {
    ImageView lg;    // 4: log1p d (3), L; after pass B its first 3 channels hold d_1, d_3
    ImageView feat;  // kLearnedFeat: f
    ImageView a, m;  // kLearnedLevels each
    ImageView bk;    // kLearnedLevels: b_i, scaled to b_i kappa_i before level i
    ImageView c;     // kLearnedLevels: c_i
    ImageView beta;  // kLearnedLevels + 1: softmax(beta)
    ImageView buf;   // 3: d_2, d_4
    ImageView v;     // 1: the noise plane v
};
// What runLearned keeps between calls of one caller (SVGF, frame after frame) instead of allocating
// the temporaries and, on CUDA, uploading the network every call: made on the first call, remade
// when the size or the weights change. One cache per executor (its memory is that device's).
struct LearnedCache {
    int width = 0, height = 0;
    std::shared_ptr<const LearnedWeights::Impl> weights;  // the weights `net` is a copy of
    std::shared_ptr<void> store;                          // owns the temporaries (and CUDA's copy of the net)
    LearnedTemps temps;
    const LearnedNet* net = nullptr;                      // on the executor's device
    LearnedCtxPlanes ctx;                                 // the context branch's planes (invalid: no context)
    bool holds(const LearnedWeights& w, int width_, int height_) const {
        return store && weights == w.impl && width == width_ && height == height_;
    }
};

constexpr int kLearnedTempChannels = 4 + kLearnedFeat + 4 * kLearnedLevels + (kLearnedLevels + 1) + 3 + 1;
inline LearnedTemps learnedTemps(float* base, int w, int h) {
    const size_t plane = size_t(w) * size_t(h);
    LearnedTemps t;
    int o = 0;
    auto take = [&](int ch) {
        ImageView v{base + size_t(o) * plane, w, h, ch};
        o += ch;
        return v;
    };
    t.lg = take(4), t.feat = take(kLearnedFeat), t.a = take(kLearnedLevels), t.m = take(kLearnedLevels);
    t.bk = take(kLearnedLevels), t.c = take(kLearnedLevels), t.beta = take(kLearnedLevels + 1), t.buf = take(3);
    t.v = take(1);
    return t;
}

// Pass A.
struct LearnedLogPass {
    ImageView d, var, lg, v;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float r = d(x, y, 0), g = d(x, y, 1), b = d(x, y, 2);
        lg(x, y, 0) = learnedLogColour(r);
        lg(x, y, 1) = learnedLogColour(g);
        lg(x, y, 2) = learnedLogColour(b);
        lg(x, y, 3) = learnedLum(r, g, b);
        v(x, y, 0) = learnedVariance(var(x, y, 0), var(x, y, 1), var(x, y, 2));
    }
};

// Inputs 0-10 of the pixels i0 .. i0 + n - 1 (flat index within a row), into lanes 0 .. n - 1;
// lanes n .. N - 1 are zeroed. iP: the same pixels' index in P's planes (the CPU's bands of rows
// index the temporaries from the band's first row, P from the image's).
template <int N>
ATROUS_FORCE_INLINE ATROUS_INLINE void learnedPointInputs(const PreparedView& P, const ImageView& lg, size_t i0,
                                                               int n, float (&x)[kLearnedIn][N], size_t iP) {
    if (n < N)
        for (int k = 0; k < kLearnedIn; ++k)
            for (int l = 0; l < N; ++l) x[k][l] = 0.0f;
    for (int c = 0; c < 3; ++c) {
        const float* s = lg.channel(c) + i0;
        for (int l = 0; l < n; ++l) x[c][l] = s[l];
    }
    for (int c = 0; c < 3; ++c) {
        if (P.albedo.valid()) {
            const float* s = P.albedo.channel(c) + iP;
            for (int l = 0; l < n; ++l) x[3 + c][l] = learnedAlbedoIn(s[l]);
        } else {
            for (int l = 0; l < n; ++l) x[3 + c][l] = 1.0f;
        }
        if (P.normal.valid()) {
            const float* s = P.normal.channel(c) + iP;
            for (int l = 0; l < n; ++l) x[6 + c][l] = learnedFinite(s[l]);
        } else {
            for (int l = 0; l < n; ++l) x[6 + c][l] = 0.0f;
        }
    }
    if (P.depth.valid()) {
        const float* s = P.depth.channel(0) + iP;
        for (int l = 0; l < n; ++l) x[9][l] = learnedDepthIn(s[l]);
    } else {
        for (int l = 0; l < n; ++l) x[9][l] = 0.0f;  // log 1
    }
    const float *vr = P.variance.channel(0) + iP, *vg = P.variance.channel(1) + iP, *vb = P.variance.channel(2) + iP;
    for (int l = 0; l < n; ++l) x[10][l] = learnedNoiseIn(vr[l], vg[l], vb[l]);
}

// The box quantities: log1p d (3), L, L^2.
constexpr int kLearnedBoxQ = 5;

// Inputs 11-14 of lanes 0 .. n - 1 from column sums: V[k][l], V[k][l + 1], V[k][l + 2] are box
// quantity k summed over the rows inside the image in the columns left of, at and right of lane
// l's pixel (0 outside the image); inv[l] = 1 / the number of taps inside.
template <int N>
ATROUS_FORCE_INLINE ATROUS_INLINE void learnedBoxInputs(const float* const (&V)[kLearnedBoxQ], const float* inv,
                                                             int n, float (&x)[kLearnedIn][N]) {
    for (int c = 0; c < 3; ++c) {
        const float* v = V[c];
        for (int l = 0; l < n; ++l) x[11 + c][l] = learnedBox(v[l], v[l + 1], v[l + 2], inv[l]);
    }
    const float *vL = V[3], *vL2 = V[4];
    for (int l = 0; l < n; ++l)
        x[14][l] = learnedLocalStd(learnedBox(vL[l], vL[l + 1], vL[l + 2], inv[l]),
                                   learnedBox(vL2[l], vL2[l + 1], vL2[l + 2], inv[l]));
}

// From the raw outputs y of lanes 0 .. n - 1 (pixels i0 ..): f, a_i, m_i, b_i (b_0 kappa_0 of d), c_i,
// softmax(beta), acc = beta_0 d. Non-finite outputs (only from absurd weights) read as 0.
template <int N>
ATROUS_FORCE_INLINE ATROUS_INLINE void learnedWriteOutputs(const float (&y)[kLearnedOut][N], const ImageView& d,
                                                                const LearnedTemps& T, const ImageView& acc,
                                                                size_t i0, int n, size_t iD) {
    for (int k = 0; k < kLearnedFeat; ++k) {
        float* o = T.feat.channel(k) + i0;
        for (int l = 0; l < n; ++l) o[l] = learnedFinite(y[k][l]);
    }
    const float *dr = d.channel(0) + iD, *dg = d.channel(1) + iD, *db = d.channel(2) + iD;  // d's own index
    for (int i = 0; i < kLearnedLevels; ++i) {
        float *oa = T.a.channel(i) + i0, *om = T.m.channel(i) + i0, *ob = T.bk.channel(i) + i0,
              *oc = T.c.channel(i) + i0;
        for (int l = 0; l < n; ++l) oa[l] = learnedSoftplus(learnedFinite(y[kLearnedOutA + i][l]));
        for (int l = 0; l < n; ++l) om[l] = learnedSoftplus(learnedFinite(y[kLearnedOutM + i][l]));
        for (int l = 0; l < n; ++l) oc[l] = learnedSoftplus(learnedFinite(y[kLearnedOutC + i][l]));
        if (i == 0)
            for (int l = 0; l < n; ++l)
                ob[l] = learnedSoftplus(learnedFinite(y[kLearnedOutB][l])) * learnedKappa(dr[l], dg[l], db[l]);
        else
            for (int l = 0; l < n; ++l) ob[l] = learnedSoftplus(learnedFinite(y[kLearnedOutB + i][l]));
    }
    constexpr int J = kLearnedLevels + 1;
    float e[J][N], mx[N], sum[N];
    for (int l = 0; l < n; ++l) mx[l] = learnedFinite(y[kLearnedOutBeta][l]);
    for (int j = 1; j < J; ++j)
        for (int l = 0; l < n; ++l) mx[l] = learnedMax(mx[l], learnedFinite(y[kLearnedOutBeta + j][l]));
    for (int l = 0; l < n; ++l) sum[l] = 0.0f;
    for (int j = 0; j < J; ++j)
        for (int l = 0; l < n; ++l) {
            e[j][l] = fastExp(learnedFinite(y[kLearnedOutBeta + j][l]) - mx[l]);
            sum[l] += e[j][l];
        }
    for (int l = 0; l < n; ++l) sum[l] = 1.0f / sum[l];  // >= 1: the largest logit's term is 1
    for (int j = 0; j < J; ++j) {
        float* o = T.beta.channel(j) + i0;
        for (int l = 0; l < n; ++l) o[l] = e[j][l] * sum[l];
    }
    float *ar = acc.channel(0) + i0, *ag = acc.channel(1) + i0, *ab = acc.channel(2) + i0;
    const float* b0 = T.beta.channel(0) + i0;
    for (int l = 0; l < n; ++l) {
        ar[l] = b0[l] * dr[l];
        ag[l] = b0[l] * dg[l];
        ab[l] = b0[l] * db[l];
    }
}

// Pass B per pixel (the GPU, and the CPU reference of the row-wise pass in learned_cpu.cpp).
struct LearnedNetPixel {
    const LearnedNet* net;  // on the executor's device
    PreparedView P;
    LearnedTemps T;
    ImageView acc;
    LearnedTensor z;  // the context's z (1/4 resolution); invalid: no context

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = P.color.width, h = P.color.height;
        const size_t i = P.color.index(x, y);
        float in[kLearnedIn][1];
        learnedPointInputs<1>(P, T.lg, i, 1, in, i);
        // Column sums of the 3x3 box, in the row loop's order (rows y - 1, y, y + 1 from 0).
        float cs[kLearnedBoxQ][3];
        for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx;
            for (int k = 0; k < kLearnedBoxQ; ++k) cs[k][dx + 1] = 0.0f;
            if (xx < 0 || xx >= w) continue;
            for (int dy = -1; dy <= 1; ++dy) {
                const int yy = y + dy;
                if (yy < 0 || yy >= h) continue;
                const size_t j = P.color.index(xx, yy);
                for (int c = 0; c < 4; ++c) cs[c][dx + 1] += T.lg.channel(c)[j];
                const float L = T.lg.channel(3)[j];
                cs[4][dx + 1] += L * L;
            }
        }
        const int ny = 1 + (y > 0) + (y < h - 1), nx = 1 + (x > 0) + (x < w - 1);
        const float inv = 1.0f / float(nx * ny);
        const float* V[kLearnedBoxQ] = {cs[0], cs[1], cs[2], cs[3], cs[4]};
        learnedBoxInputs<1>(V, &inv, 1, in);
        float out[kLearnedOut][1];
        if (z.valid()) {
            float shift[kLearnedHidden][1];
            for (int j = 0; j < kLearnedHidden; ++j) shift[j][0] = learnedCtxShift(z, x, y, j);
            learnedMlp<1, true>(*net, in, out, shift);
        } else {
            learnedMlp<1>(*net, in, out);
        }
        learnedWriteOutputs<1>(out, P.color, T, acc, i, 1, i);
    }
};

// Level i: the edge-stop policy (filters/atrous_level.h). kLast: the level that ends the cascade
// (writes only acc, finite-guarded; no d_{i+1}, no next kappa).
template <bool kLast>
struct LearnedStop {
    int step_ = 1;
    ImageView dIn, dOut, feat, acc;
    // The CPU's bands of rows (src/cpu/learned_cpu.cpp): the level's height when not dIn's (0), and
    // where dIn's rows start relative to the band's (level 0 reads d from the image's planes).
    int height_ = 0;
    ptrdiff_t dInShift = 0;
    // The level's planes; beta_{i+1}; v, the noise plane (every level's).
    const float *a = nullptr, *m = nullptr, *bk = nullptr, *c = nullptr, *beta = nullptr, *v = nullptr;
    float* bkNext = nullptr;  // b_{i+1}, scaled in place by kappa of d_{i+1} (not when kLast)

    static constexpr int kSums = 4;  // Σw, Σw d (3)
    static constexpr bool kCentreTap = true, kRowPartialSums = false, kScalarTaps = false;
    struct Row {
        const float *r, *g, *b, *a, *m, *bk, *c, *beta, *v;
        const float* f[kLearnedFeat];
        float *oR, *oG, *oB, *accR, *accG, *accB, *bkNext;
    };
    struct Centre {
        float f[kLearnedFeat];
        float a, m, bk, c, vf, r, g, b;  // vf: nu's floor v(p) + NU_REL (0.01 + mean d_i(p)^2)
    };
    struct TapRow {};

    ATROUS_HOST_DEVICE int width() const { return dIn.width; }
    ATROUS_HOST_DEVICE int height() const { return height_ ? height_ : dIn.height; }
    ATROUS_HOST_DEVICE int step() const { return step_; }
    ATROUS_HOST_DEVICE Row row(int y) const {
        const size_t o = size_t(y) * size_t(dIn.width);
        Row R;
        R.r = dIn.channel(0) + dInShift + o, R.g = dIn.channel(1) + dInShift + o, R.b = dIn.channel(2) + dInShift + o;
        R.a = a + o, R.m = m + o, R.bk = bk + o, R.c = c + o, R.beta = beta + o, R.v = v + o;
        for (int k = 0; k < kLearnedFeat; ++k) R.f[k] = feat.channel(k) + o;
        R.accR = acc.channel(0) + o, R.accG = acc.channel(1) + o, R.accB = acc.channel(2) + o;
        if constexpr (kLast) {
            R.oR = R.oG = R.oB = R.bkNext = nullptr;
        } else {
            R.oR = dOut.channel(0) + o, R.oG = dOut.channel(1) + o, R.oB = dOut.channel(2) + o;
            R.bkNext = bkNext + o;
        }
        return R;
    }
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE Centre centre(const Row& R, int x) const {
        Centre c;
        for (int k = 0; k < kLearnedFeat; ++k) c.f[k] = R.f[k][x];
        c.a = R.a[x], c.m = R.m[x], c.bk = R.bk[x], c.c = R.c[x];
        c.r = R.r[x], c.g = R.g[x], c.b = R.b[x];
        c.vf = learnedNuFloor(R.v[x], c.r, c.g, c.b);
        return c;
    }
    ATROUS_HOST_DEVICE TapRow tapRow(int) const { return TapRow{}; }
    template <int QX, bool kCentre>
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void tap(const Row& R, const Centre& c, AtrousSums<kSums>& s, ptrdiff_t q,
                                                    float hxy, const TapRow&) const {
        const float r = R.r[q], g = R.g[q], b = R.b[q];
        float w;
        if constexpr (kCentre) {
            w = hxy * (1.0f + c.m);
        } else {
            float df = 0.0f;
            for (int k = 0; k < kLearnedFeat; ++k) df += sq(c.f[k] - R.f[k][q]);
            const float dc = sq(r - c.r) + sq(g - c.g) + sq(b - c.b);
            // c.vf > 0 and v(q) >= 0: the division is finite (or c / inf = 0 for an infinite v).
            const float cnu = c.c / (c.vf + R.v[q]);  // c_i nu_i(p, q)
            w = hxy * fastExp(-(c.a * df + (c.bk + cnu) * dc));  // NaN (0 · inf, absurd weights) gives 0
        }
        s.s[0] += w;
        s.s[1] += w * r;
        s.s[2] += w * g;
        s.s[3] += w * b;
    }
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void finish(const Row& R, int x, int, const AtrousSums<kSums>& s) const {
        const float inv = 1.0f / s.s[0];  // > 0: the centre tap's weight is at least h(0)^2
        const float r = s.s[1] * inv, g = s.s[2] * inv, b = s.s[3] * inv, bt = R.beta[x];
        if constexpr (kLast) {
            R.accR[x] = learnedFinite(R.accR[x] + bt * r);
            R.accG[x] = learnedFinite(R.accG[x] + bt * g);
            R.accB[x] = learnedFinite(R.accB[x] + bt * b);
        } else {
            R.oR[x] = r, R.oG[x] = g, R.oB[x] = b;
            R.accR[x] += bt * r;
            R.accG[x] += bt * g;
            R.accB[x] += bt * b;
            R.bkNext[x] *= learnedKappa(r, g, b);
        }
    }
};

// Level i's policy: reads d_i (d, then lg's first channels and buf alternately), writes d_{i+1}.
template <bool kLast>
LearnedStop<kLast> learnedStop(const PreparedView& P, const LearnedTemps& T, const ImageView& acc, int i) {
    const ImageView lg3{T.lg.data, T.lg.width, T.lg.height, 3};
    LearnedStop<kLast> s;
    s.step_ = 1 << i;
    s.dIn = i == 0 ? P.color : (i % 2 == 1 ? lg3 : T.buf);
    s.dOut = i % 2 == 0 ? lg3 : T.buf;
    s.feat = T.feat, s.acc = acc;
    s.a = T.a.channel(i), s.m = T.m.channel(i), s.bk = T.bk.channel(i), s.c = T.c.channel(i);
    s.beta = T.beta.channel(i + 1), s.v = T.v.channel(0);
    s.bkNext = kLast ? nullptr : T.bk.channel(i + 1);
    return s;
}

// The whole cascade through the functors on exec (the GPU; the CPU reference): every view on
// exec's device, net too. C: the context's planes, invalid when the weights have none.
template <class Exec>
void runLearnedFunctors(const Exec& exec, const LearnedNet* net, const PreparedView& P, const LearnedTemps& T,
                        const ImageView& acc, const LearnedCtxPlanes& C) {
    const int w = P.color.width, h = P.color.height;
    if (C.valid()) runLearnedContextFunctors(exec, &net->ctx, P.color, P.variance, P.albedo, P.normal, P.depth, C);
    exec.forEachPixel(w, h, LearnedLogPass{P.color, P.variance, T.lg, T.v});
    exec.forEachPixel(w, h, LearnedNetPixel{net, P, T, acc, C.z});
    for (int i = 0; i + 1 < kLearnedLevels; ++i) runAtrousLevelFunctor(exec, learnedStop<false>(P, T, acc, i));
    runAtrousLevelFunctor(exec, learnedStop<true>(P, T, acc, kLearnedLevels - 1));
}

}  // namespace atrous::filters

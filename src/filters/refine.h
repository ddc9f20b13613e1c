// The refine stage (docs/learned.md, "Refine"; issue 47): after a still method, a small U-Net
// predicts a correction of the image, a residual r in log space, so that an output pixel is no
// longer a convex combination of its neighbourhood (a stripe can get its contrast back, a highlight
// its energy): refined = max(expm1(log1p(max(base, 0)) + clamp(r, +-kRefineMaxResidual)), 0), then scaled
// by the energy gain (per 64-pixel block, smooth, so that the stage moves light within a block
// but keeps the method's light at that scale).
// python/atrous/learn/refine.py is the same math in NumPy/JAX (training, export, the reference).
//
// Inputs, 15 per pixel (RefineFeatures): log1p of the method's output (3) and of the noisy colour
// (3), the albedo (3, clamped to [0, 1]), the normal (3, clamped to [-1, 1]), and a noise level (3):
// the 7x7 mean of |log1p(noisy) - log1p(output)| (what the method took away), edges replicated.
// The image is padded to a multiple of 4 a side by replicating its last row and column.
//
//   e1 = relu conv3(relu conv3(x: 15 -> 16) 16 -> 16)                      full
//   e2 = relu conv3(relu conv3(pool2 e1: 16 -> 24) 24 -> 24)               1/2
//   e3 = relu conv3(relu conv3(pool2 e2: 24 -> 32) 32 -> 32)               1/4
//   d2 = relu conv3(cat(up2 e3, e2): 56 -> 24)                             1/2
//   d1 = relu conv3(cat(up2 d2, e1): 40 -> 16)                             full
//   r  = conv1(d1: 16 -> 3)
// pool2: the mean of 2x2; up2: nearest; conv3: 3x3, zero padding (cross-correlation, HWIO kernels).
// About 16 400 multiply-adds a pixel, 47 323 parameters.
//
// The functors here are the GPU's path and the CPU's reference; the CPU runs the convolutions
// through oneDNN (src/cpu/refine_cpu.cpp, src/cpu/dnnl_conv.h).
#pragma once
#include <cmath>
#include <cstddef>
#include <cstring>

#include "atrous/image.h"
#include "filters/atrous_math.h"
#include "filters/learned_context.h"

namespace atrous {
class RefineWeights;
struct CpuExec;
struct CudaExec;
}

namespace atrous::filters {

constexpr int kRefineIn = 15, kRefineC1 = 16, kRefineC2 = 24, kRefineC3 = 32, kRefineOut = 3;
constexpr int kRefineNoiseRadius = 3;      // the noise level's window: 7 x 7
constexpr float kRefineMaxResidual = 3.0f;  // |r| in log space (a factor of e^3 either way)
// The energy gain (RefineGainRows below): blocks, fixed-point steps, eps, the largest factor.
constexpr int kRefineEnergyBlock = 64, kRefineGainIterations = 3;
constexpr float kRefineGainEps = 1e-4f, kRefineGainMax = 4.0f;
static_assert(kRefineC3 <= kLearnedConvMaxOut && kRefineC2 <= kLearnedConvMaxOut, "LearnedConv's accumulators");

// The network's parameters, the weight file's order (kernels HWIO: k[((ky 3 + kx) cin + i) cout + o]).
struct RefineNet {
    float k1[9 * kRefineIn * kRefineC1], b1[kRefineC1];
    float k1b[9 * kRefineC1 * kRefineC1], b1b[kRefineC1];
    float k2[9 * kRefineC1 * kRefineC2], b2[kRefineC2];
    float k2b[9 * kRefineC2 * kRefineC2], b2b[kRefineC2];
    float k3[9 * kRefineC2 * kRefineC3], b3[kRefineC3];
    float k3b[9 * kRefineC3 * kRefineC3], b3b[kRefineC3];
    float ku2[9 * (kRefineC3 + kRefineC2) * kRefineC2], bu2[kRefineC2];
    float ku1[9 * (kRefineC2 + kRefineC1) * kRefineC1], bu1[kRefineC1];
    float ko[kRefineC1 * kRefineOut], bo[kRefineOut];
};
constexpr int kRefineParams = int(sizeof(RefineNet) / sizeof(float));
static_assert(kRefineParams == 47323, "the refine network's size (python/atrous/learn/refine.py)");

// The network's tensors for a padded image of W x H (multiples of 4), channels-last, carved from
// one block. Full resolution: three regions reused (x then cat1 in X; e1a then d1 in A; e1 in B;
// r in X once cat1 is read).
struct RefinePlanes {
    LearnedTensor x, e1a, e1, cat1, d1, r;        // full
    LearnedTensor p1, e2a, e2, cat2, d2;          // 1/2
    LearnedTensor p2, e3a, e3;                    // 1/4
    LearnedTensor gain;                           // 3: a sample per energy block
    LearnedTensor gainRows;                       // 6: block columns x the image's rows
    bool valid() const { return x.valid(); }
};
inline int refinePadded(int n) { return (n + 3) / 4 * 4; }
inline size_t refineFloats(int w, int h) {
    const size_t W = size_t(refinePadded(w)), H = size_t(refinePadded(h));
    const size_t full = W * H, half = full / 4, quarter = full / 16;
    const size_t blocks = size_t(learnedCeilDiv(w, kRefineEnergyBlock)) * size_t(learnedCeilDiv(h, kRefineEnergyBlock));
    return full * (kRefineC2 + 3 * kRefineC1) + half * (kRefineC1 + 2 * kRefineC2 + kRefineC3 + kRefineC2 + kRefineC2) +
           quarter * (kRefineC2 + 2 * kRefineC3) + blocks * 3 +
           size_t(learnedCeilDiv(w, kRefineEnergyBlock)) * size_t(h) * 6;
}
inline RefinePlanes refinePlanes(float* base, int w, int h) {
    const int W = refinePadded(w), H = refinePadded(h);
    RefinePlanes p;
    auto take = [&](int ww, int hh, int ch) {
        LearnedTensor v{base, ww, hh, ch};
        base += size_t(ww) * size_t(hh) * size_t(ch);
        return v;
    };
    // X holds x (15), then cat1 (40), then r (3).
    const LearnedTensor X = take(W, H, kRefineC2 + kRefineC1);
    p.x = LearnedTensor{X.data, W, H, kRefineIn}, p.cat1 = X, p.r = LearnedTensor{X.data, W, H, kRefineOut};
    p.e1a = take(W, H, kRefineC1), p.d1 = LearnedTensor{p.e1a.data, W, H, kRefineC1};
    p.e1 = take(W, H, kRefineC1);
    p.p1 = take(W / 2, H / 2, kRefineC1), p.e2a = take(W / 2, H / 2, kRefineC2), p.e2 = take(W / 2, H / 2, kRefineC2);
    p.cat2 = take(W / 2, H / 2, kRefineC3 + kRefineC2), p.d2 = take(W / 2, H / 2, kRefineC2);
    p.p2 = take(W / 4, H / 4, kRefineC2), p.e3a = take(W / 4, H / 4, kRefineC3), p.e3 = take(W / 4, H / 4, kRefineC3);
    p.gain = take(learnedCeilDiv(w, kRefineEnergyBlock), learnedCeilDiv(h, kRefineEnergyBlock), 3);
    p.gainRows = take(p.gain.width, h, 6);
    return p;
}

ATROUS_FORCE_INLINE ATROUS_INLINE float refineLog(float v) { return log1pf(finite(v) && v > 0.0f ? v : 0.0f); }
ATROUS_FORCE_INLINE ATROUS_INLINE float refineClamp(float v, float lo, float hi) {
    return finite(v) ? (v < lo ? lo : (v > hi ? hi : v)) : 0.0f;
}

// lc = log1p of the noisy colour (taken before the preparation sanitises it in place).
struct RefineLogColour {
    ImageView color, lc;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int k = 0; k < 3; ++k) lc(x, y, k) = refineLog(color(x, y, k));
    }
};

// The noise level's first steps: d = |lc - log1p(base)| per pixel, then t(x, y) = the sum of d over
// |dx| <= R (columns clamped to the image).
struct RefineNoiseDiff {
    ImageView lc, base, d;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int k = 0; k < 3; ++k) d(x, y, k) = fabsf(lc(x, y, k) - refineLog(base(x, y, k)));
    }
};
struct RefineNoiseRows {
    ImageView d, t;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = d.width;
        for (int k = 0; k < 3; ++k) {
            float s = 0.0f;
            for (int dx = -kRefineNoiseRadius; dx <= kRefineNoiseRadius; ++dx)
                s += d(x + dx < 0 ? 0 : (x + dx >= w ? w - 1 : x + dx), y, k);
            t(x, y, k) = s;
        }
    }
};

// The inputs of padded pixel (x, y) (the image's pixel at the clamped coordinates): the noise
// level is the column sum of t over |dy| <= R (rows clamped) over 49.
struct RefineFeatures {
    ImageView base, lc, albedo, normal, t;
    LearnedTensor x;
    ATROUS_HOST_DEVICE void operator()(int X, int Y) const {
        const int w = base.width, h = base.height;
        const int px = X < w ? X : w - 1, py = Y < h ? Y : h - 1;
        float* o = &x(X, Y, 0);
        for (int k = 0; k < 3; ++k) {
            o[k] = refineLog(base(px, py, k));
            o[3 + k] = lc(px, py, k);
            o[6 + k] = refineClamp(albedo(px, py, k), 0.0f, 1.0f);
            o[9 + k] = refineClamp(normal(px, py, k), -1.0f, 1.0f);
            float s = 0.0f;
            for (int dy = -kRefineNoiseRadius; dy <= kRefineNoiseRadius; ++dy) {
                const int yy = py + dy < 0 ? 0 : (py + dy >= h ? h - 1 : py + dy);
                s += t(px, yy, k);
            }
            constexpr float inv = 1.0f / float((2 * kRefineNoiseRadius + 1) * (2 * kRefineNoiseRadius + 1));
            o[12 + k] = s * inv;
        }
    }
};

// up = up2 lo (nearest): lo's channels at (x / 2, y / 2) into the first of up's. Alone, the CPU's
// concatenation-free decoder (src/cpu/refine_cpu.cpp convolves up and the skip tensor apart and
// sums); in RefineUp2Cat, the concatenation's first part.
struct RefineUp2 {
    LearnedTensor lo, up;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        memcpy(&up(x, y, 0), lo.at(x / 2, y / 2), sizeof(float) * size_t(lo.channels));
    }
};

// cat = (up2 lo, skip): RefineUp2 into cat's first channels, then skip's at (x, y).
struct RefineUp2Cat {
    LearnedTensor lo, skip, cat;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        RefineUp2{lo, cat}(x, y);
        memcpy(&cat(x, y, lo.channels), skip.at(x, y), sizeof(float) * size_t(skip.channels));
    }
};

// r := the refined value max(expm1(log1p(max(out, 0)) + clamp(r)), 0) at the image's pixels (a
// non-finite one: the method's output, which is finite).
struct RefineResidual {
    LearnedTensor r;
    ImageView out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int k = 0; k < 3; ++k) {
            const float b = out(x, y, k);
            const float v = expm1f(refineLog(b) + refineClamp(r(x, y, k), -kRefineMaxResidual, kRefineMaxResidual));
            r(x, y, k) = finite(v) ? (v > 0.0f ? v : 0.0f) : b;
        }
    }
};

// The energy gain (docs/refine.md, "Energy"): a gain g_b per block of kRefineEnergyBlock pixels a
// side and channel, upsampled bilinearly (half-pixel centres, clamped: weights w_b(p), a partition
// of unity), out = refined G with G(p) = sum_b w_b(p) g_b, chosen so that for every block
// sum_p w_b(p) out(p) = sum_p w_b(p) base(p): the refined image keeps the method's light at that
// scale (which the firefly restore keeps within a few percent of the reference's; summed over b,
// the whole image's light exactly) and the network decides only how it is laid out. Solved by
// kRefineGainIterations fixed-point steps from g = 1, g_b *= (sum w_b base + eps) / (sum w_b out + eps),
// clamped to [1/4, 4]. Separable: per row the weighted sums of each block column, then per block.
// w_b(x) along one axis: the weight output x's bilinear taps give block b.
ATROUS_FORCE_INLINE ATROUS_INLINE float refineHat(int x, int b, int nBlocks) {
    const LearnedUpTap t = learnedUpTap(x, kRefineEnergyBlock, nBlocks);
    return (t.i0 == b ? 1.0f - t.t : 0.0f) + (t.i1 == b ? t.t : 0.0f);
}
// G(x, y), channel k.
ATROUS_FORCE_INLINE ATROUS_INLINE float refineGainAt(const LearnedTensor& gain, int x, int y, int k) {
    const LearnedUpTap ty = learnedUpTap(y, kRefineEnergyBlock, gain.height), tx = learnedUpTap(x, kRefineEnergyBlock, gain.width);
    const float a = gain(tx.i0, ty.i0, k) * (1.0f - ty.t) + gain(tx.i0, ty.i1, k) * ty.t;
    const float b = gain(tx.i1, ty.i0, k) * (1.0f - ty.t) + gain(tx.i1, ty.i1, k) * ty.t;
    return a * (1.0f - tx.t) + b * tx.t;
}

// rows(b, y) = sum_x w_b(x) base(x, y) (channels 0-2) and sum_x w_b(x) refined(x, y) G(x, y) (3-5)
// over the columns block b's weights reach.
struct RefineGainRows {
    LearnedTensor refined, gain, rows;
    ImageView base;
    ATROUS_HOST_DEVICE void operator()(int b, int y) const {
        constexpr int B = kRefineEnergyBlock;
        const int x0 = b * B - B / 2 > 0 ? b * B - B / 2 : 0, x1 = (b + 1) * B + B / 2 < base.width ? (b + 1) * B + B / 2 : base.width;
        double sb[3] = {0, 0, 0}, sr[3] = {0, 0, 0};
        for (int x = x0; x < x1; ++x) {
            const float w = refineHat(x, b, gain.width);
            for (int k = 0; k < 3; ++k) {
                sb[k] += double(w * base(x, y, k));
                sr[k] += double(w * refined(x, y, k) * refineGainAt(gain, x, y, k));
            }
        }
        for (int k = 0; k < 3; ++k) rows(b, y, k) = float(sb[k]), rows(b, y, 3 + k) = float(sr[k]);
    }
};

// g_b *= the ratio of the column sums of rows over the rows block b's weights reach.
struct RefineGainStep {
    LearnedTensor rows, gain;
    ATROUS_HOST_DEVICE void operator()(int bx, int by) const {
        constexpr int B = kRefineEnergyBlock;
        const int h = rows.height;
        const int y0 = by * B - B / 2 > 0 ? by * B - B / 2 : 0, y1 = (by + 1) * B + B / 2 < h ? (by + 1) * B + B / 2 : h;
        double sb[3] = {0, 0, 0}, sr[3] = {0, 0, 0};
        for (int y = y0; y < y1; ++y) {
            const float w = refineHat(y, by, gain.height);
            for (int k = 0; k < 3; ++k) sb[k] += double(w) * double(rows(bx, y, k)), sr[k] += double(w) * double(rows(bx, y, 3 + k));
        }
        for (int k = 0; k < 3; ++k) {
            const float g = gain(bx, by, k) * float((sb[k] + kRefineGainEps) / (sr[k] + kRefineGainEps));
            gain(bx, by, k) = refineClamp(g, 1.0f / kRefineGainMax, kRefineGainMax);
        }
    }
};

struct RefineGainInit {
    LearnedTensor gain;
    ATROUS_HOST_DEVICE void operator()(int bx, int by) const {
        for (int k = 0; k < 3; ++k) gain(bx, by, k) = 1.0f;
    }
};

// out = refined G.
struct RefineApply {
    LearnedTensor refined, gain;
    ImageView out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int k = 0; k < 3; ++k) out(x, y, k) = refined(x, y, k) * refineGainAt(gain, x, y, k);
    }
};

// The views the stage reads and writes (the executor's device, the image's size): lc and t are 3
// channels the caller owns (lc filled by RefineLogColour before the preparation), out the method's
// finished output, refined in place.
struct RefineViews {
    ImageView lc, t, albedo, normal, out;
};

// A decoder convolution, out = relu conv3(cat(up2 lo, skip)) with the kernel k over the
// concatenation's channels, through the functors: Up2Cat into `cat`, then conv (the GPU's form and
// the CPU's reference).
template <class Exec, class Conv>
struct RefineCatConv {
    const Exec& exec;
    Conv& conv;
    void operator()(const LearnedTensor& lo, const LearnedTensor& skip, const LearnedTensor& cat, const LearnedTensor& out,
                    const float* k, const float* b) const {
        exec.forEachPixel(cat.width, cat.height, RefineUp2Cat{lo, skip, cat});
        conv(cat, out, k, b, 3, true);
    }
};

// Everything before the network and the convolutions' order, through the functors (conv: the
// executor's convolution, LearnedConv's signature; catConv: a decoder convolution, RefineCatConv's
// signature).
template <class Exec, class Conv, class CatConv>
void runRefinePasses(const Exec& exec, const RefineNet* net, const RefineViews& v, const RefinePlanes& P, Conv conv,
                     CatConv catConv) {
    const int w = v.out.width, h = v.out.height;
    const ImageView d{P.e1a.data, w, h, 3};  // e1a's storage, free until the first convolution
    exec.forEachPixel(w, h, RefineNoiseDiff{v.lc, v.out, d});
    exec.forEachPixel(w, h, RefineNoiseRows{d, v.t});
    exec.forEachPixel(P.x.width, P.x.height, RefineFeatures{v.out, v.lc, v.albedo, v.normal, v.t, P.x});
    conv(P.x, P.e1a, net->k1, net->b1, 3, true);
    conv(P.e1a, P.e1, net->k1b, net->b1b, 3, true);
    exec.forEachPixel(P.p1.width, P.p1.height, LearnedPool2{P.e1, P.p1});
    conv(P.p1, P.e2a, net->k2, net->b2, 3, true);
    conv(P.e2a, P.e2, net->k2b, net->b2b, 3, true);
    exec.forEachPixel(P.p2.width, P.p2.height, LearnedPool2{P.e2, P.p2});
    conv(P.p2, P.e3a, net->k3, net->b3, 3, true);
    conv(P.e3a, P.e3, net->k3b, net->b3b, 3, true);
    catConv(P.e3, P.e2, P.cat2, P.d2, net->ku2, net->bu2);
    catConv(P.d2, P.e1, P.cat1, P.d1, net->ku1, net->bu1);
    conv(P.d1, P.r, net->ko, net->bo, 1, false);
    exec.forEachPixel(w, h, RefineResidual{P.r, v.out});
    exec.forEachPixel(P.gain.width, P.gain.height, RefineGainInit{P.gain});
    for (int i = 0; i < kRefineGainIterations; ++i) {
        exec.forEachPixel(P.gainRows.width, P.gainRows.height, RefineGainRows{P.r, P.gain, P.gainRows, v.out});
        exec.forEachPixel(P.gain.width, P.gain.height, RefineGainStep{P.gainRows, P.gain});
    }
    exec.forEachPixel(w, h, RefineApply{P.r, P.gain, v.out});
}

// The whole stage through the functors (the GPU; the CPU's reference).
template <class Exec>
void runRefineFunctors(const Exec& exec, const RefineNet* net, const RefineViews& v, const RefinePlanes& P) {
    auto conv = [&](const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu) {
        exec.forEachPixel(out.width, out.height, LearnedConv{in, out, k, b, ks, relu});
    };
    runRefinePasses(exec, net, v, P, conv, RefineCatConv<Exec, decltype(conv)>{exec, conv});
}

// The network's parameters of `w` (the built-in ones when it is empty; refine_weights.cpp).
const RefineNet& refineNet(const RefineWeights& w);

// The stage on each executor (src/cpu/refine_cpu.cpp, src/cuda/refine.cu). functors: the CPU's
// reference path (direct convolutions) instead of oneDNN.
void runRefine(const CpuExec& exec, const RefineWeights& weights, const RefineViews& v, bool functors = false);
void runRefine(const CudaExec& exec, const RefineWeights& weights, const RefineViews& v);

}  // namespace atrous::filters

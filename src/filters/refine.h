// The refine stage (docs/learned.md, "Refine"; issue 47): after a still method, a small U-Net
// predicts a correction of the image, a residual r in log space, so that an output pixel is no
// longer a convex combination of its neighbourhood (a stripe can get its contrast back, a highlight
// its energy): out = expm1(log1p(max(base, 0)) + clamp(r, +-kRefineMaxResidual)).
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
    bool valid() const { return x.valid(); }
};
inline int refinePadded(int n) { return (n + 3) / 4 * 4; }
inline size_t refineFloats(int w, int h) {
    const size_t W = size_t(refinePadded(w)), H = size_t(refinePadded(h));
    const size_t full = W * H, half = full / 4, quarter = full / 16;
    return full * (kRefineC2 + 3 * kRefineC1) + half * (kRefineC1 + 2 * kRefineC2 + kRefineC3 + kRefineC2 + kRefineC2) +
           quarter * (kRefineC2 + 2 * kRefineC3);
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

// The noise level's first step: t(x, y) = the sum over |dx| <= R (columns clamped to the image) of
// |lc - log1p(base)|.
struct RefineNoiseRows {
    ImageView lc, base, t;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = lc.width;
        for (int k = 0; k < 3; ++k) {
            float s = 0.0f;
            for (int dx = -kRefineNoiseRadius; dx <= kRefineNoiseRadius; ++dx) {
                const int xx = x + dx < 0 ? 0 : (x + dx >= w ? w - 1 : x + dx);
                s += fabsf(lc(xx, y, k) - refineLog(base(xx, y, k)));
            }
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

// cat = (up2 lo, skip): lo's channels at (x / 2, y / 2) (nearest), then skip's at (x, y).
struct RefineUp2Cat {
    LearnedTensor lo, skip, cat;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float* a = lo.at(x / 2, y / 2);
        const float* b = skip.at(x, y);
        float* o = &cat(x, y, 0);
        for (int c = 0; c < lo.channels; ++c) o[c] = a[c];
        for (int c = 0; c < skip.channels; ++c) o[lo.channels + c] = b[c];
    }
};

// out = expm1(log1p(max(out, 0)) + clamp(r)), in place (a non-finite result keeps the method's
// output, which is finite).
struct RefineApply {
    LearnedTensor r;
    ImageView out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int k = 0; k < 3; ++k) {
            const float b = out(x, y, k);
            const float v = expm1f(refineLog(b) + refineClamp(r(x, y, k), -kRefineMaxResidual, kRefineMaxResidual));
            out(x, y, k) = finite(v) ? v : b;
        }
    }
};

// The views the stage reads and writes (the executor's device, the image's size): lc and t are 3
// channels the caller owns (lc filled by RefineLogColour before the preparation), out the method's
// finished output, refined in place.
struct RefineViews {
    ImageView lc, t, albedo, normal, out;
};

// Everything before the network and the convolutions' order, through the functors (conv: the
// executor's convolution, LearnedConv's signature).
template <class Exec, class Conv>
void runRefinePasses(const Exec& exec, const RefineNet* net, const RefineViews& v, const RefinePlanes& P, Conv conv) {
    const int w = v.out.width, h = v.out.height;
    exec.forEachPixel(w, h, RefineNoiseRows{v.lc, v.out, v.t});
    exec.forEachPixel(P.x.width, P.x.height, RefineFeatures{v.out, v.lc, v.albedo, v.normal, v.t, P.x});
    conv(P.x, P.e1a, net->k1, net->b1, 3, true);
    conv(P.e1a, P.e1, net->k1b, net->b1b, 3, true);
    exec.forEachPixel(P.p1.width, P.p1.height, LearnedPool2{P.e1, P.p1});
    conv(P.p1, P.e2a, net->k2, net->b2, 3, true);
    conv(P.e2a, P.e2, net->k2b, net->b2b, 3, true);
    exec.forEachPixel(P.p2.width, P.p2.height, LearnedPool2{P.e2, P.p2});
    conv(P.p2, P.e3a, net->k3, net->b3, 3, true);
    conv(P.e3a, P.e3, net->k3b, net->b3b, 3, true);
    exec.forEachPixel(P.cat2.width, P.cat2.height, RefineUp2Cat{P.e3, P.e2, P.cat2});
    conv(P.cat2, P.d2, net->ku2, net->bu2, 3, true);
    exec.forEachPixel(P.cat1.width, P.cat1.height, RefineUp2Cat{P.d2, P.e1, P.cat1});
    conv(P.cat1, P.d1, net->ku1, net->bu1, 3, true);
    conv(P.d1, P.r, net->ko, net->bo, 1, false);
    exec.forEachPixel(w, h, RefineApply{P.r, v.out});
}

// The whole stage through the functors (the GPU; the CPU's reference).
template <class Exec>
void runRefineFunctors(const Exec& exec, const RefineNet* net, const RefineViews& v, const RefinePlanes& P) {
    runRefinePasses(exec, net, v, P,
                    [&](const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu) {
                        exec.forEachPixel(out.width, out.height, LearnedConv{in, out, k, b, ks, relu});
                    });
}

// The stage on each executor (src/cpu/refine_cpu.cpp, src/cuda/refine.cu). functors: the CPU's
// reference path (direct convolutions) instead of oneDNN.
void runRefine(const CpuExec& exec, const RefineWeights& weights, const RefineViews& v, bool functors = false);
void runRefine(const CudaExec& exec, const RefineWeights& weights, const RefineViews& v);

}  // namespace atrous::filters

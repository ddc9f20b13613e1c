// The learned filter v4's context branch (docs/learned.md, "Context"; python/atrous/learn/context.py
// is the same math in JAX): a small convolutional network at 1/4 and 1/8 of the resolution whose
// output z (kLearnedHidden channels at 1/4) is upsampled bilinearly and added to the per-pixel MLP's
// first hidden layer.
//
//   cells  LearnedCellPass   13 inputs per 4x4 cell (means over the cell's pixels inside the image)
//   c1     conv3x3 13 -> 16, ReLU
//   pool   LearnedPool2      mean over each 2x2 block's cells inside
//   c2, c3 conv3x3 16 -> 16, ReLU          (1/8)
//   cat    LearnedUp2Cat     c1, then the bilinear x2 of c3 (32 channels)
//   c4     conv3x3 32 -> 16, ReLU          (1/4)
//   z      1x1 16 -> kLearnedHidden, linear
//
// The tensors are channels-last (LearnedTensor). The functors here are the GPU's path and the CPU's
// reference (LearnedConv is a direct convolution); the CPU runs the convolutions through oneDNN
// (src/cpu/learned_context_cpu.cpp).
#pragma once
#include <cmath>
#include <cstddef>

#include "atrous/image.h"
#include "filters/learned_math.h"

namespace atrous::filters {

ATROUS_INLINE int learnedCeilDiv(int n, int f) { return (n + f - 1) / f; }
// The most output channels LearnedConv computes (its accumulators; the refine stage's 32).
constexpr int kLearnedConvMaxOut = 32;

// A channels-last tensor (HWC: sample (x, y)'s channels are adjacent): the branch's layout, so that
// a band of rows is one dense block (oneDNN's nhwc; the CPU convolves the image's halves apart).
struct LearnedTensor {
    float* data = nullptr;
    int width = 0, height = 0, channels = 0;
    ATROUS_INLINE float& operator()(int x, int y, int c) const {
        return data[(size_t(y) * size_t(width) + size_t(x)) * size_t(channels) + size_t(c)];
    }
    ATROUS_INLINE const float* at(int x, int y) const {
        return data + (size_t(y) * size_t(width) + size_t(x)) * size_t(channels);
    }
    ATROUS_INLINE bool valid() const { return data != nullptr; }
};

// The branch's tensors (on the executor's device).
struct LearnedCtxPlanes {
    LearnedTensor cells;  // kLearnedCtxIn, 1/4
    LearnedTensor c1;     // kLearnedCtx, 1/4
    LearnedTensor cat;    // 2 kLearnedCtx, 1/4: c1, then up2(c3)
    LearnedTensor pool;   // kLearnedCtx, 1/8
    LearnedTensor c2, c3; // kLearnedCtx, 1/8
    LearnedTensor c4;     // kLearnedCtx, 1/4
    LearnedTensor z;      // kLearnedHidden, 1/4
    bool valid() const { return z.valid(); }
};
// Floats of the tensors for a w x h image, and the tensors carved from `base`.
inline size_t learnedCtxFloats(int w, int h) {
    const size_t q = size_t(learnedCeilDiv(w, 4)) * size_t(learnedCeilDiv(h, 4));
    const size_t e = size_t(learnedCeilDiv(w, 8)) * size_t(learnedCeilDiv(h, 8));
    return q * (kLearnedCtxIn + 4 * kLearnedCtx + kLearnedHidden) + e * 3 * kLearnedCtx;
}
inline LearnedCtxPlanes learnedCtxPlanes(float* base, int w, int h) {
    const int w4 = learnedCeilDiv(w, 4), h4 = learnedCeilDiv(h, 4), w8 = learnedCeilDiv(w, 8), h8 = learnedCeilDiv(h, 8);
    LearnedCtxPlanes p;
    auto take = [&](int ww, int hh, int ch) {
        LearnedTensor v{base, ww, hh, ch};
        base += size_t(ww) * size_t(hh) * size_t(ch);
        return v;
    };
    p.cells = take(w4, h4, kLearnedCtxIn), p.c1 = take(w4, h4, kLearnedCtx), p.cat = take(w4, h4, 2 * kLearnedCtx);
    p.c4 = take(w4, h4, kLearnedCtx), p.z = take(w4, h4, kLearnedHidden);
    p.pool = take(w8, h8, kLearnedCtx), p.c2 = take(w8, h8, kLearnedCtx), p.c3 = take(w8, h8, kLearnedCtx);
    return p;
}

// Bilinear upsampling by f with half-pixel centres: output index X reads the source samples i0, i1
// (clamped to [0, n)) with weights 1 - t, t; the source position is (X + 0.5) / f - 0.5.
struct LearnedUpTap {
    int i0, i1;
    float t;
};
ATROUS_FORCE_INLINE ATROUS_INLINE LearnedUpTap learnedUpTap(int X, int f, int n) {
    const float s = (float(X) + 0.5f) / float(f) - 0.5f;
    const float fl = floorf(s);
    int i0 = int(fl), i1 = i0 + 1;
    i0 = i0 < 0 ? 0 : (i0 > n - 1 ? n - 1 : i0);
    i1 = i1 < 0 ? 0 : (i1 > n - 1 ? n - 1 : i1);
    return LearnedUpTap{i0, i1, s - fl};
}

// The 15 per-pixel quantities the cells average: log1p d (3), L, L^2, the albedo input (3), its mean
// a, a^2, the normal (3), the depth input, the noise input.
constexpr int kLearnedCellQ = 15;
ATROUS_FORCE_INLINE ATROUS_INLINE void learnedCellQuantities(float r, float g, float b, float ar, float ag, float ab,
                                                             float nx, float ny, float nz, float z, float vr, float vg,
                                                             float vb, bool hasAlbedo, bool hasNormal, bool hasDepth,
                                                             float (&q)[kLearnedCellQ]) {
    q[0] = learnedLogColour(r), q[1] = learnedLogColour(g), q[2] = learnedLogColour(b);
    const float L = learnedLum(r, g, b);
    q[3] = L, q[4] = L * L;
    q[5] = hasAlbedo ? learnedAlbedoIn(ar) : 1.0f;
    q[6] = hasAlbedo ? learnedAlbedoIn(ag) : 1.0f;
    q[7] = hasAlbedo ? learnedAlbedoIn(ab) : 1.0f;
    const float a = (q[5] + q[6] + q[7]) * (1.0f / 3.0f);
    q[8] = a, q[9] = a * a;
    q[10] = hasNormal ? learnedFinite(nx) : 0.0f;
    q[11] = hasNormal ? learnedFinite(ny) : 0.0f;
    q[12] = hasNormal ? learnedFinite(nz) : 0.0f;
    q[13] = hasDepth ? learnedDepthIn(z) : 0.0f;
    q[14] = learnedNoiseIn(vr, vg, vb);
}
// The cell's 13 inputs from the sums of its quantities over its n pixels.
ATROUS_FORCE_INLINE ATROUS_INLINE void learnedCellFinish(const float (&s)[kLearnedCellQ], int n,
                                                         const LearnedTensor& cells, int cx, int cy) {
    const float inv = 1.0f / float(n);
    float m[kLearnedCellQ];
    for (int k = 0; k < kLearnedCellQ; ++k) m[k] = s[k] * inv;
    cells(cx, cy, 0) = m[0], cells(cx, cy, 1) = m[1], cells(cx, cy, 2) = m[2];
    cells(cx, cy, 3) = learnedLocalStd(m[3], m[4]);
    cells(cx, cy, 4) = m[5], cells(cx, cy, 5) = m[6], cells(cx, cy, 6) = m[7];
    cells(cx, cy, 7) = learnedLocalStd(m[8], m[9]);
    for (int k = 0; k < 5; ++k) cells(cx, cy, 8 + k) = m[10 + k];
}

// The 13 cell inputs of cell (cx, cy): means over its pixels inside the image of log1p d (3), the
// albedo input (3), the normal (3), the depth input, the noise input (the MLP's inputs 0-10), and
// the standard deviations within the cell of L = log1p(mean_c d) and of the mean albedo input.
// Summed per column over the cell's rows, then the columns left to right (the CPU's row loop,
// src/cpu/learned_context_cpu.cpp, adds in the same order).
struct LearnedCellPass {
    ImageView d, var, albedo, normal, depth;
    LearnedTensor cells;
    ATROUS_HOST_DEVICE void operator()(int cx, int cy) const {
        float s[kLearnedCellQ];
        for (int k = 0; k < kLearnedCellQ; ++k) s[k] = 0.0f;
        const int x0 = cx * kLearnedCell, y0 = cy * kLearnedCell;
        const int x1 = x0 + kLearnedCell < d.width ? x0 + kLearnedCell : d.width;
        const int y1 = y0 + kLearnedCell < d.height ? y0 + kLearnedCell : d.height;
        const bool ha = albedo.valid(), hn = normal.valid(), hd = depth.valid();
        for (int x = x0; x < x1; ++x) {
            float col[kLearnedCellQ];
            for (int k = 0; k < kLearnedCellQ; ++k) col[k] = 0.0f;
            for (int y = y0; y < y1; ++y) {
                float q[kLearnedCellQ];
                learnedCellQuantities(d(x, y, 0), d(x, y, 1), d(x, y, 2), ha ? albedo(x, y, 0) : 0.0f,
                                      ha ? albedo(x, y, 1) : 0.0f, ha ? albedo(x, y, 2) : 0.0f,
                                      hn ? normal(x, y, 0) : 0.0f, hn ? normal(x, y, 1) : 0.0f,
                                      hn ? normal(x, y, 2) : 0.0f, hd ? depth(x, y, 0) : 0.0f, var(x, y, 0),
                                      var(x, y, 1), var(x, y, 2), ha, hn, hd, q);
                for (int k = 0; k < kLearnedCellQ; ++k) col[k] += q[k];
            }
            for (int k = 0; k < kLearnedCellQ; ++k) s[k] += col[k];
        }
        learnedCellFinish(s, (x1 - x0) * (y1 - y0), cells, cx, cy);
    }
};

// A 3x3 (ks 3) or 1x1 (ks 1) convolution with zero padding (cross-correlation, as JAX's and
// oneDNN's), bias, optional ReLU: out(x, y, o) = b[o] + sum_{ky, kx, i} in(x + kx - p, y + ky - p, i)
// k[((ky ks + kx) cin + i) cout + o], p = ks / 2. The GPU's convolution and the CPU's reference (the
// CPU runs oneDNN's).
struct LearnedConv {
    LearnedTensor in, out;
    const float *k, *b;
    int ks;
    bool relu;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int cin = in.channels, cout = out.channels, p = ks / 2;
        float acc[kLearnedConvMaxOut];
        for (int o = 0; o < cout; ++o) acc[o] = b[o];
        for (int ky = 0; ky < ks; ++ky) {
            const int yy = y + ky - p;
            if (yy < 0 || yy >= in.height) continue;
            for (int kx = 0; kx < ks; ++kx) {
                const int xx = x + kx - p;
                if (xx < 0 || xx >= in.width) continue;
                const float* kk = k + size_t(ky * ks + kx) * size_t(cin) * size_t(cout);
                const float* v = in.at(xx, yy);
                for (int i = 0; i < cin; ++i)
                    for (int o = 0; o < cout; ++o) acc[o] = fmaf(v[i], kk[i * cout + o], acc[o]);
            }
        }
        for (int o = 0; o < cout; ++o) out(x, y, o) = relu ? learnedMax(acc[o], 0.0f) : acc[o];
    }
};

// pool = the mean over each 2x2 block's samples inside `in`.
struct LearnedPool2 {
    LearnedTensor in, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int x1 = 2 * x + 1 < in.width ? 2 * x + 1 : 2 * x, y1 = 2 * y + 1 < in.height ? 2 * y + 1 : 2 * y;
        const float inv = 1.0f / float((x1 - 2 * x + 1) * (y1 - 2 * y + 1));
        for (int c = 0; c < out.channels; ++c) {
            float s = 0.0f;
            for (int yy = 2 * y; yy <= y1; ++yy)
                for (int xx = 2 * x; xx <= x1; ++xx) s += in(xx, yy, c);
            out(x, y, c) = s * inv;
        }
    }
};

// cat = c1, then bilinear x2 of c3 (cat's size; rows first, then columns, as context.upsample).
struct LearnedUp2Cat {
    LearnedTensor c1, c3, cat;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int c = 0; c < c1.channels; ++c) cat(x, y, c) = c1(x, y, c);
        const LearnedUpTap ty = learnedUpTap(y, 2, c3.height), tx = learnedUpTap(x, 2, c3.width);
        for (int c = 0; c < c3.channels; ++c) {
            const float a = c3(tx.i0, ty.i0, c) * (1.0f - ty.t) + c3(tx.i0, ty.i1, c) * ty.t;
            const float b = c3(tx.i1, ty.i0, c) * (1.0f - ty.t) + c3(tx.i1, ty.i1, c) * ty.t;
            cat(x, y, c1.channels + c) = a * (1.0f - tx.t) + b * tx.t;
        }
    }
};

// The shift up4(z) of the first hidden layer at full-resolution pixel (x, y), unit j.
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedCtxShift(const LearnedTensor& z, int x, int y, int j) {
    const LearnedUpTap ty = learnedUpTap(y, kLearnedCell, z.height), tx = learnedUpTap(x, kLearnedCell, z.width);
    const float a = z(tx.i0, ty.i0, j) * (1.0f - ty.t) + z(tx.i0, ty.i1, j) * ty.t;
    const float b = z(tx.i1, ty.i0, j) * (1.0f - ty.t) + z(tx.i1, ty.i1, j) * ty.t;
    return a * (1.0f - tx.t) + b * tx.t;
}

// One row of up4's columns step: out[x] for x in [0, w) from a row r of zw samples (already
// interpolated between z's rows), the same values as learnedCtxShift's. Output 4X + k reads
// samples X - 1, X (k = 0, 1; t = 5/8, 7/8) or X, X + 1 (k = 2, 3; t = 1/8, 3/8), clamped.
ATROUS_FORCE_INLINE ATROUS_INLINE void learnedUp4Row(const float* r, int zw, float* out, int w) {
    static_assert(kLearnedCell == 4, "learnedUp4Row is written for cells of 4");
    auto generic = [&](int x) {
        const LearnedUpTap t = learnedUpTap(x, kLearnedCell, zw);
        out[x] = r[t.i0] * (1.0f - t.t) + r[t.i1] * t.t;
    };
    // Interior cells: no clamping, the weights are constants (1 - t exact in binary).
    const int X1 = (w / 4 < zw - 1 ? w / 4 : zw - 1);
    for (int x = 0; x < 4 && x < w; ++x) generic(x);
    for (int X = 1; X < X1; ++X) {
        const float a = r[X - 1], b = r[X], c = r[X + 1];
        float* o = out + 4 * X;
        o[0] = a * 0.375f + b * 0.625f;
        o[1] = a * 0.125f + b * 0.875f;
        o[2] = b * 0.875f + c * 0.125f;
        o[3] = b * 0.625f + c * 0.375f;
    }
    for (int x = (X1 > 1 ? 4 * X1 : 4); x < w; ++x) generic(x);
}

// The whole branch through the functors (the GPU; the CPU's reference). net: the context's
// parameters on exec's device.
template <class Exec>
void runLearnedContextFunctors(const Exec& exec, const LearnedCtxNet* net, const ImageView& d, const ImageView& var,
                               const ImageView& albedo, const ImageView& normal, const ImageView& depth,
                               const LearnedCtxPlanes& C) {
    const int w4 = C.cells.width, h4 = C.cells.height, w8 = C.pool.width, h8 = C.pool.height;
    exec.forEachPixel(w4, h4, LearnedCellPass{d, var, albedo, normal, depth, C.cells});
    exec.forEachPixel(w4, h4, LearnedConv{C.cells, C.c1, net->k1, net->kb1, 3, true});
    exec.forEachPixel(w8, h8, LearnedPool2{C.c1, C.pool});
    exec.forEachPixel(w8, h8, LearnedConv{C.pool, C.c2, net->k2, net->kb2, 3, true});
    exec.forEachPixel(w8, h8, LearnedConv{C.c2, C.c3, net->k3, net->kb3, 3, true});
    exec.forEachPixel(w4, h4, LearnedUp2Cat{C.c1, C.c3, C.cat});
    exec.forEachPixel(w4, h4, LearnedConv{C.cat, C.c4, net->k4, net->kb4, 3, true});
    exec.forEachPixel(w4, h4, LearnedConv{C.c4, C.z, net->kz, net->kbz, 1, false});
}

}  // namespace atrous::filters

// The learned filter v4's context branch (docs/learned.md, "Context"; python/atrous/learn/context.py
// is the same math in JAX): a small convolutional network at 1/4 and 1/8 of the resolution whose
// output z (kLearnedHidden channels at 1/4) is upsampled bilinearly and added to the per-pixel MLP's
// first hidden layer.
//
//   cells  LearnedCellPass   13 inputs per 4x4 cell (means over the cell's pixels inside the image)
//   c1     conv3x3 13 -> 16, ReLU          (into cat's channels 0-15)
//   pool   LearnedPool2      mean over each 2x2 block's cells inside
//   c2, c3 conv3x3 16 -> 16, ReLU          (1/8)
//   up     LearnedUp2        bilinear x2 of c3 into cat's channels 16-31
//   c4     conv3x3 32 -> 16, ReLU          (1/4)
//   z      1x1 16 -> kLearnedHidden, linear
//
// The functors here are the GPU's path and the CPU's reference (LearnedConv3 is a direct
// convolution); the CPU runs the convolutions through oneDNN (src/cpu/learned_context_cpu.cpp).
#pragma once
#include <cmath>
#include <cstddef>

#include "atrous/image.h"
#include "filters/learned_math.h"

namespace atrous::filters {

ATROUS_INLINE int learnedCeilDiv(int n, int f) { return (n + f - 1) / f; }

// The branch's planes (on the executor's device).
struct LearnedCtxPlanes {
    ImageView cells;  // kLearnedCtxIn, 1/4
    ImageView cat;    // 2 kLearnedCtx, 1/4: c1, then up2(c3)
    ImageView pool;   // kLearnedCtx, 1/8
    ImageView c2, c3; // kLearnedCtx, 1/8
    ImageView c4;     // kLearnedCtx, 1/4
    ImageView z;      // kLearnedHidden, 1/4
    bool valid() const { return z.valid(); }
};
// Floats of the planes for a w x h image, and the views carved from `base`.
inline size_t learnedCtxFloats(int w, int h) {
    const size_t q = size_t(learnedCeilDiv(w, 4)) * size_t(learnedCeilDiv(h, 4));
    const size_t e = size_t(learnedCeilDiv(w, 8)) * size_t(learnedCeilDiv(h, 8));
    return q * (kLearnedCtxIn + 3 * kLearnedCtx + kLearnedHidden) + e * 3 * kLearnedCtx;
}
inline LearnedCtxPlanes learnedCtxPlanes(float* base, int w, int h) {
    const int w4 = learnedCeilDiv(w, 4), h4 = learnedCeilDiv(h, 4), w8 = learnedCeilDiv(w, 8), h8 = learnedCeilDiv(h, 8);
    LearnedCtxPlanes p;
    auto take = [&](int ww, int hh, int ch) {
        ImageView v{base, ww, hh, ch};
        base += size_t(ww) * size_t(hh) * size_t(ch);
        return v;
    };
    p.cells = take(w4, h4, kLearnedCtxIn), p.cat = take(w4, h4, 2 * kLearnedCtx), p.c4 = take(w4, h4, kLearnedCtx);
    p.z = take(w4, h4, kLearnedHidden);
    p.pool = take(w8, h8, kLearnedCtx), p.c2 = take(w8, h8, kLearnedCtx), p.c3 = take(w8, h8, kLearnedCtx);
    return p;
}
// Channels [c0, c0 + n) of a planar view (a planar tensor's channels are contiguous planes).
ATROUS_INLINE ImageView learnedChannels(const ImageView& v, int c0, int n) {
    return ImageView{v.channel(c0), v.width, v.height, n};
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

// The 13 cell inputs of cell (cx, cy): means over its pixels inside the image of log1p d (3), the
// albedo input (3), the normal (3), the depth input, the noise input (the MLP's inputs 0-10), and
// the standard deviations within the cell of L = log1p(mean_c d) and of the mean albedo input.
struct LearnedCellPass {
    ImageView d, var, albedo, normal, depth, cells;
    ATROUS_HOST_DEVICE void operator()(int cx, int cy) const {
        float s[15];
        for (int k = 0; k < 15; ++k) s[k] = 0.0f;
        const int x0 = cx * kLearnedCell, y0 = cy * kLearnedCell;
        const int x1 = x0 + kLearnedCell < d.width ? x0 + kLearnedCell : d.width;
        const int y1 = y0 + kLearnedCell < d.height ? y0 + kLearnedCell : d.height;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                const float r = d(x, y, 0), g = d(x, y, 1), b = d(x, y, 2);
                s[0] += learnedLogColour(r), s[1] += learnedLogColour(g), s[2] += learnedLogColour(b);
                const float L = learnedLum(r, g, b);
                s[3] += L, s[4] += L * L;
                float al = 0.0f;
                for (int c = 0; c < 3; ++c) {
                    const float a = albedo.valid() ? learnedAlbedoIn(albedo(x, y, c)) : 1.0f;
                    s[5 + c] += a;
                    al += a;
                }
                al *= 1.0f / 3.0f;
                s[8] += al, s[9] += al * al;
                for (int c = 0; c < 3; ++c) s[10 + c] += normal.valid() ? learnedFinite(normal(x, y, c)) : 0.0f;
                s[13] += depth.valid() ? learnedDepthIn(depth(x, y, 0)) : 0.0f;
                s[14] += learnedNoiseIn(var(x, y, 0), var(x, y, 1), var(x, y, 2));
            }
        const float inv = 1.0f / float((x1 - x0) * (y1 - y0));
        for (int k = 0; k < 15; ++k) s[k] *= inv;
        cells(cx, cy, 0) = s[0], cells(cx, cy, 1) = s[1], cells(cx, cy, 2) = s[2];
        cells(cx, cy, 3) = learnedLocalStd(s[3], s[4]);
        cells(cx, cy, 4) = s[5], cells(cx, cy, 5) = s[6], cells(cx, cy, 6) = s[7];
        cells(cx, cy, 7) = learnedLocalStd(s[8], s[9]);
        for (int k = 0; k < 5; ++k) cells(cx, cy, 8 + k) = s[10 + k];
    }
};

// A 3x3 convolution with zero padding (cross-correlation, as JAX's and oneDNN's), bias, optional
// ReLU: out(x, y, o) = b[o] + sum_{ky, kx, i} in(x + kx - 1, y + ky - 1, i) k[((ky 3 + kx) cin + i) cout + o].
// The GPU's convolution and the CPU's reference (the CPU runs oneDNN's).
struct LearnedConv3 {
    ImageView in, out;
    const float *k, *b;
    bool relu;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int cin = in.channels, cout = out.channels;
        float acc[kLearnedHidden];
        for (int o = 0; o < cout; ++o) acc[o] = b[o];
        for (int ky = 0; ky < 3; ++ky) {
            const int yy = y + ky - 1;
            if (yy < 0 || yy >= in.height) continue;
            for (int kx = 0; kx < 3; ++kx) {
                const int xx = x + kx - 1;
                if (xx < 0 || xx >= in.width) continue;
                const float* kk = k + size_t(ky * 3 + kx) * size_t(cin) * size_t(cout);
                for (int i = 0; i < cin; ++i) {
                    const float v = in(xx, yy, i);
                    for (int o = 0; o < cout; ++o) acc[o] = fmaf(v, kk[i * cout + o], acc[o]);
                }
            }
        }
        for (int o = 0; o < cout; ++o) out(x, y, o) = relu ? learnedMax(acc[o], 0.0f) : acc[o];
    }
};

// z = c4 . kz + kbz (a 1x1 layer, linear).
struct LearnedCtxZ {
    ImageView c4, z;
    const float *kz, *kbz;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float acc[kLearnedHidden];
        for (int j = 0; j < kLearnedHidden; ++j) acc[j] = kbz[j];
        for (int i = 0; i < kLearnedCtx; ++i) {
            const float v = c4(x, y, i);
            for (int j = 0; j < kLearnedHidden; ++j) acc[j] = fmaf(v, kz[i * kLearnedHidden + j], acc[j]);
        }
        for (int j = 0; j < kLearnedHidden; ++j) z(x, y, j) = acc[j];
    }
};

// pool = the mean over each 2x2 block's samples inside `in`.
struct LearnedPool2 {
    ImageView in, out;
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

// Bilinear x2 of `in` into `out` (out's size; rows first, then columns, as context.upsample).
struct LearnedUp2 {
    ImageView in, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const LearnedUpTap ty = learnedUpTap(y, 2, in.height), tx = learnedUpTap(x, 2, in.width);
        for (int c = 0; c < out.channels; ++c) {
            const float a = in(tx.i0, ty.i0, c) * (1.0f - ty.t) + in(tx.i0, ty.i1, c) * ty.t;
            const float b = in(tx.i1, ty.i0, c) * (1.0f - ty.t) + in(tx.i1, ty.i1, c) * ty.t;
            out(x, y, c) = a * (1.0f - tx.t) + b * tx.t;
        }
    }
};

// The shift up4(z) of the first hidden layer at full-resolution pixel (x, y), unit j.
ATROUS_FORCE_INLINE ATROUS_INLINE float learnedCtxShift(const ImageView& z, int x, int y, int j) {
    const LearnedUpTap ty = learnedUpTap(y, kLearnedCell, z.height), tx = learnedUpTap(x, kLearnedCell, z.width);
    const float a = z(tx.i0, ty.i0, j) * (1.0f - ty.t) + z(tx.i0, ty.i1, j) * ty.t;
    const float b = z(tx.i1, ty.i0, j) * (1.0f - ty.t) + z(tx.i1, ty.i1, j) * ty.t;
    return a * (1.0f - tx.t) + b * tx.t;
}

// The passes that are not convolutions, and the whole branch through the functors (the GPU; the
// CPU's reference). net: the context's parameters on exec's device.
template <class Exec>
void runLearnedCells(const Exec& exec, const ImageView& d, const ImageView& var, const ImageView& albedo,
                     const ImageView& normal, const ImageView& depth, const LearnedCtxPlanes& C) {
    exec.forEachPixel(C.cells.width, C.cells.height, LearnedCellPass{d, var, albedo, normal, depth, C.cells});
}
template <class Exec>
void runLearnedContextFunctors(const Exec& exec, const LearnedCtxNet* net, const ImageView& d, const ImageView& var,
                               const ImageView& albedo, const ImageView& normal, const ImageView& depth,
                               const LearnedCtxPlanes& C) {
    const ImageView c1 = learnedChannels(C.cat, 0, kLearnedCtx), up = learnedChannels(C.cat, kLearnedCtx, kLearnedCtx);
    const int w4 = C.cells.width, h4 = C.cells.height, w8 = C.pool.width, h8 = C.pool.height;
    runLearnedCells(exec, d, var, albedo, normal, depth, C);
    exec.forEachPixel(w4, h4, LearnedConv3{C.cells, c1, net->k1, net->kb1, true});
    exec.forEachPixel(w8, h8, LearnedPool2{c1, C.pool});
    exec.forEachPixel(w8, h8, LearnedConv3{C.pool, C.c2, net->k2, net->kb2, true});
    exec.forEachPixel(w8, h8, LearnedConv3{C.c2, C.c3, net->k3, net->kb3, true});
    exec.forEachPixel(w4, h4, LearnedUp2{C.c3, up});
    exec.forEachPixel(w4, h4, LearnedConv3{C.cat, C.c4, net->k4, net->kb4, true});
    exec.forEachPixel(w4, h4, LearnedCtxZ{C.c4, C.z, net->kz, net->kbz});
}

}  // namespace atrous::filters

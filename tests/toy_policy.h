// A toy edge-stop policy of the shared à-trous level: a cross-bilateral stop on a 1-channel guide,
// w = h(q) exp(-(g_p - g_q)² / σ²). This is all a new edge stop needs (filters/atrous_level.h
// lists the contract); tests/toy_policy_test.cpp runs it on the CPU, and
// tests/cuda/toy_policy_cuda_test.cu compiles it for the GPU.
#pragma once
#include "filters/atrous_level.h"

namespace atrous::toy {

struct ToyStop {
    int step_ = 1;
    float invSigma2 = 1.0f;  // 1/σ² of the guide difference (0: the plain B3 à-trous)
    ImageView in, guide, out;  // 3, 1 and 3 channels

    static constexpr int kSums = 4;  // Σw, Σw c (3)
    static constexpr bool kCentreTap = false, kRowPartialSums = false, kScalarTaps = false;
    struct Row {
        const float *r, *g, *b, *guide;
        float *oR, *oG, *oB;
    };
    struct Centre {
        float guide;
    };
    struct TapRow {};

    ATROUS_HOST_DEVICE int width() const { return in.width; }
    ATROUS_HOST_DEVICE int height() const { return in.height; }
    ATROUS_HOST_DEVICE int step() const { return step_; }
    ATROUS_HOST_DEVICE Row row(int y) const {
        const size_t o = size_t(y) * size_t(in.width);
        return Row{in.channel(0) + o,  in.channel(1) + o,  in.channel(2) + o, guide.channel(0) + o,
                   out.channel(0) + o, out.channel(1) + o, out.channel(2) + o};
    }
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE Centre centre(const Row& R, int x) const { return Centre{R.guide[x]}; }
    ATROUS_HOST_DEVICE TapRow tapRow(int) const { return TapRow{}; }
    template <int QX, bool kCentre>
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void tap(const Row& R, const Centre& c, filters::AtrousSums<kSums>& a,
                                                    ptrdiff_t q, float hxy, const TapRow&) const {
        const float w = hxy * filters::fastExp(-filters::sq(c.guide - R.guide[q]) * invSigma2);
        a.s[0] += w;
        a.s[1] += w * R.r[q];
        a.s[2] += w * R.g[q];
        a.s[3] += w * R.b[q];
    }
    ATROUS_FORCE_INLINE ATROUS_HOST_DEVICE void finish(const Row& R, int x, int, const filters::AtrousSums<kSums>& a) const {
        const float inv = 1.0f / a.s[0];  // > 0: the centre tap has weight h(0)²
        R.oR[x] = a.s[1] * inv;
        R.oG[x] = a.s[2] * inv;
        R.oB[x] = a.s[3] * inv;
    }
};

}  // namespace atrous::toy

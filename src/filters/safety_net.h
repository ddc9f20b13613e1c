// The safety net of EAW and SURE (docs/algorithms.md, "The safety net"): after the cascade, the
// residual r = y - F between the (demodulated, firefly-clamped) input y and the filter's output F
// is one more detail band, and SURE chooses per pixel how much of it to give back:
//     F' = F + s (y - F),   s = argmin_s (1 - s)² ΣD + (2s - 1) ΣV   over a window W(p),
// D = Σ_ch r², V = Σ_ch var(y). E[D] = bias² + var(y) - 2 cov(F, y) + var(F); for a filter that
// averages many pixels cov and var(F) are small, so E[ΣD] ≈ ΣV where the filter only removed
// noise (s = 0: F kept) and ΣD ≫ ΣV where it also removed signal (s → 1: back toward the input).
// The same window sums and choice as the SURE levels (sure.h), so it costs about one SURE level.
#pragma once
#include "atrous/image.h"
#include "filters/filter_math.h"
#include "filters/sure.h"

namespace atrous::filters {

// The input's summed variance, kept before the cascade (SURE's propagation overwrites the
// variance buffer): vSum = Σ_ch var(y).
struct SafetyVariance {
    ImageView var, vSum;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        vSum(x, y, 0) = maxSel(var(x, y, 0), 0.0f) + maxSel(var(x, y, 1), 0.0f) + maxSel(var(x, y, 2), 0.0f);
    }
};

// The two detail maps of the residual: D = Σ_ch (y - F)², V = vSum. F = cN + detailSum (SURE) or
// cN (EAW).
struct SafetyDetail {
    ImageView input, cN, detailSum, vSum, detail;  // detailSum may be invalid
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float d = 0;
        for (int c = 0; c < 3; ++c) {
            float f = cN(x, y, c);
            if (detailSum.valid()) f += detailSum(x, y, c);
            const float r = input(x, y, c) - f;
            d += r * r;
        }
        detail(x, y, 0) = d;
        detail(x, y, 1) = vSum(x, y, 0);
    }
};

// ΣD / ΣV of p's window (+Inf where ΣV = 0): its median over the image is the calibration κ of an
// estimated variance (the driver, step 6).
struct SafetyRatio {
    int radius;
    ImageView boxH, ratio;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float sumD, sumV;
        sureWindowSums(boxH, radius, x, y, sumD, sumV);
        ratio(x, y, 0) = sumV > 0.0f ? sumD / sumV : INFINITY;
    }
};

// Vertical window sums of the horizontal sums (SureBoxH), the choice of s, and
// cN ← F + s (y - F) in place (detailSum is folded in: Remodulate then runs without it).
struct SafetyBlend {
    SureChoiceParams p;
    float varScale;  // κ: ΣV is taken as κ ΣV
    float trigger;   // τ: the net acts only where ΣD > τ κ ΣV
    ImageView boxH, input, cN, detailSum;
    ImageView sOut;  // optional: the chosen s (1 channel)
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float sumD, sumV;
        sureWindowSums(boxH, p.radius, x, y, sumD, sumV);
        const float s = sumD > trigger * varScale * sumV ? sureChoose(p, sumD, varScale * sumV) : 0.0f;
        for (int c = 0; c < 3; ++c) {
            float f = cN(x, y, c);
            if (detailSum.valid()) f += detailSum(x, y, c);
            cN(x, y, c) = f + s * (input(x, y, c) - f);
        }
        if (sOut.valid()) sOut(x, y, 0) = s;
    }
};

// The albedo give-back (docs/algorithms.md): the part of the residual r = y - F (demodulated) that
// the albedo explains is signal the filter took for noise, and goes back into F. Where a renderer's
// albedo pass does not describe how the texture shades (Cycles' albedo of a diffuse floor differs
// from what the colour carries; a specular layer the albedo does not multiply), the demodulation
// c / a' keeps the texture's pattern, the noise estimate reads it as noise and the filter smooths
// it away. Per channel, over the (2R+1)² window W(p) (in-image taps, n of them):
//     A = cov_W(a, r) / var_W(a), shrunk by its significance: A · max(0, 1 - k / (n R²)),
// R² = cov² / (var(a) var(r)) (n R² is the fit's χ² statistic, about 1 on pure noise); then, as a
// guided filter, F' = F + mean_W(A) a(p) + mean_W(b), b = -A mean_W(a): the slope's part only, not
// the residual's mean (giving that back too returned the filter's low-frequency noise). R 4, k 4:
// a smaller k let noise back, a larger k or R kept less of the texture (docs/decisions.md).
constexpr int kGiveBackRadius = 4;
constexpr float kGiveBackSignificance = 4.0f;
// The albedo must vary over the window by this much (a standard deviation of 0.003, as the noise
// estimate's fit, kNoiseFitMinVar) for the fit to be taken.
constexpr float kGiveBackMinVar = 1e-5f;
constexpr int kGiveBackMoments = 15;  // a, r, a², a r, r² per colour channel

// Per pixel, the five moments of (a, r) per channel: m, 15 channels (5 per colour channel).
// F = cN + detailSum (SURE) or cN.
struct GiveBackMoments {
    ImageView input, cN, detailSum, albedo, m;  // detailSum may be invalid
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int c = 0; c < 3; ++c) {
            float f = cN(x, y, c);
            if (detailSum.valid()) f += detailSum(x, y, c);
            const float r = input(x, y, c) - f, a = albedo(x, y, c);
            m(x, y, 5 * c + 0) = a;
            m(x, y, 5 * c + 1) = r;
            m(x, y, 5 * c + 2) = a * a;
            m(x, y, 5 * c + 3) = a * r;
            m(x, y, 5 * c + 4) = r * r;
        }
    }
};

// The window's shrunk slope A and offset b = -A mean(a) from its sums of a, r, a², a r, r² over n taps.
ATROUS_INLINE void giveBackSlopeInv(float significance, float n, float inv, float sa, float sr, float saa, float sar,
                                    float srr, float& A, float& b);
ATROUS_INLINE void giveBackSlope(float significance, float n, float sa, float sr, float saa, float sar, float srr,
                                 float& A, float& b) {
    giveBackSlopeInv(significance, n, 1.0f / n, sa, sr, saa, sar, srr, A, b);
}
// The same with inv = 1 / n given (the CPU row loop divides once per distinct n, not per pixel and
// channel: the same value).
ATROUS_INLINE void giveBackSlopeInv(float significance, float n, float inv, float sa, float sr, float saa, float sar,
                                    float srr, float& A, float& b) {
    const float ma = sa * inv, mr = sr * inv;
    const float va = saa * inv - ma * ma, car = sar * inv - ma * mr, vr = srr * inv - mr * mr;
    float s = 0.0f;
    if (va > kGiveBackMinVar && vr > 0.0f) {
        const float r2 = car * car / (va * vr);  // in [0, 1] up to rounding
        const float keep = minSel(maxSel(1.0f - significance / (n * maxSel(r2, 1e-30f)), 0.0f), 1.0f);
        s = car / va * keep;
    }
    A = finite(s) ? s : 0.0f;
    b = -A * ma;
}

// What goes back at p: mean_W(A) a(p) + mean_W(b) from the window sums of A and b over n taps
// (0 where not finite).
ATROUS_INLINE float giveBackTermInv(float sumA, float sumB, float inv, float a);
ATROUS_INLINE float giveBackTerm(float sumA, float sumB, float n, float a) { return giveBackTermInv(sumA, sumB, 1.0f / n, a); }
ATROUS_INLINE float giveBackTermInv(float sumA, float sumB, float inv, float a) {
    const float g = sumA * inv * a + sumB * inv;
    return finite(g) ? g : 0.0f;
}

// The window's shrunk slope A_c and offset b_c = -A_c mean_W(a_c) per channel (coef: 6 channels,
// A rgb then b rgb), from the window sums of the moments.
struct GiveBackFit {
    int radius = kGiveBackRadius;
    float significance = kGiveBackSignificance;
    ImageView sums, coef;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float n = boxTaps(radius, x, y, sums.width, sums.height);
        for (int c = 0; c < 3; ++c) {
            float A, b;
            giveBackSlope(significance, n, sums(x, y, 5 * c), sums(x, y, 5 * c + 1), sums(x, y, 5 * c + 2),
                          sums(x, y, 5 * c + 3), sums(x, y, 5 * c + 4), A, b);
            coef(x, y, c) = A;
            coef(x, y, 3 + c) = b;
        }
    }
};

// cN ← F + mean_W(A) a(p) + mean_W(b) in place, from the window sums of the coefficients (detailSum
// folded in: Remodulate then runs without it).
struct GiveBackApply {
    int radius = kGiveBackRadius;
    ImageView sums, albedo, cN, detailSum;  // detailSum may be invalid
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float n = boxTaps(radius, x, y, sums.width, sums.height);
        for (int c = 0; c < 3; ++c) {
            float f = cN(x, y, c);
            if (detailSum.valid()) f += detailSum(x, y, c);
            cN(x, y, c) = f + giveBackTerm(sums(x, y, c), sums(x, y, 3 + c), n, albedo(x, y, c));
        }
    }
};

// Six image planes (w x h floats each) a caller has no more use for, which the CPU give-back may
// take for its coefficients instead of allocating them (the driver's spare cascade buffer and σ
// planes).
struct GiveBackScratch {
    float* plane[6] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
    int count = 0;
};

// The passes on `exec`: cN ← F + the albedo-explained residual of y (input) against F. The CpuExec
// overload (src/cpu/sure_cpu.cpp) fuses them into row loops with the same arithmetic.
template <class Exec>
void runAlbedoGiveBack(const Exec& exec, const ImageView& input, const ImageView& cN, const ImageView& detailSum,
                       const ImageView& albedo, int radius = kGiveBackRadius,
                       float significance = kGiveBackSignificance, const GiveBackScratch* scratch = nullptr) {
    (void)scratch;
    const int w = input.width, h = input.height;
    const Device dev = exec.device();
    Image m(w, h, kGiveBackMoments, dev), t(w, h, kGiveBackMoments, dev);
    exec.forEachPixel(w, h, GiveBackMoments{input, cN, detailSum, albedo, m.view()});
    runBoxSum(exec, BoxSum<false>{radius, m.view(), t.view()});
    runBoxSum(exec, BoxSum<true>{radius, t.view(), m.view()});
    // The coefficients and their sums in the first 6 planes of the same buffers.
    const ImageView coefM{m.data(), w, h, 6}, coefT{t.data(), w, h, 6};
    exec.forEachPixel(w, h, GiveBackFit{radius, significance, m.view(), coefT});
    runBoxSum(exec, BoxSum<false>{radius, coefT, coefM});
    runBoxSum(exec, BoxSum<true>{radius, coefM, coefT});
    exec.forEachPixel(w, h, GiveBackApply{radius, coefT, albedo, cN, detailSum});
    exec.synchronize();  // before the temporaries die
}
void runAlbedoGiveBack(const CpuExec& exec, const ImageView& input, const ImageView& cN, const ImageView& detailSum,
                       const ImageView& albedo, int radius = kGiveBackRadius,
                       float significance = kGiveBackSignificance, const GiveBackScratch* scratch = nullptr);

}  // namespace atrous::filters

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

}  // namespace atrous::filters

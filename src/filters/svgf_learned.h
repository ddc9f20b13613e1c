// SVGF with the learned à-trous cascade as its spatial filter (SvgfParams::learnedSpatial): the
// planes the cascade (filters/learned.h, the still filter's network and weights) reads, made from
// SVGF's temporal half. d is the accumulated demodulated illumination; var is the variance *of d*:
// SVGF's estimate (temporal moments, or the 7x7 spatial one on young pixels) is of one frame's
// sample, and the still network was trained on the variance of the value it filters, so it is
// scaled by what the accumulation averages away, 1/n for a running mean of n frames and alpha /
// (2 - alpha) for the exponential average it becomes (var(EMA) = var · alpha / (2 - alpha)).
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

// The variance factor of the accumulated colour: max(alpha / (2 - alpha), 1 / n) for history
// length n (1 on an empty pixel, n = 0). alpha in (0, 1].
ATROUS_INLINE float accumulatedVarianceFactor(float alpha, float n) {
    return n > 0.0f ? maxf(alpha / (2.0f - alpha), 1.0f / n) : 1.0f;
}

// var (3 channels, the same value in each: SVGF's variance is of the luminance) = the factor times
// SVGF's variance; non-finite or negative reads as 0.
struct LearnedInputVariance {
    float alpha = 0.2f;
    ImageView variance, length;  // SVGF's, 1 channel each
    ImageView out;               // 3 channels
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const float v = variance(x, y, 0);
        const float s = (v > 0.0f && isFiniteF(v))
                            ? v * accumulatedVarianceFactor(alpha, length(x, y, 0))
                            : 0.0f;
        out(x, y, 0) = s;
        out(x, y, 1) = s;
        out(x, y, 2) = s;
    }
};

}  // namespace atrous::svgf

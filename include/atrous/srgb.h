// The sRGB transfer function (IEC 61966-2-1), both ways, for host and device code.
#pragma once
#include <cmath>

#include "atrous/platform.h"

namespace atrous {

// Linear [0, 1] to sRGB-encoded [0, 1]; values outside [0, 1] are clamped first.
ATROUS_INLINE float srgbEncode(float v) {
    v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

// sRGB-encoded to linear; values outside [0, 1] are clamped first.
ATROUS_INLINE float srgbDecode(float v) {
    v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

// A display value in [0, 1] as 8 bits, rounded to nearest; values outside [0, 1] are clamped and
// NaN is 0. The quantisation of every 8-bit image atrous makes: the PNG writer's sRGB, the
// tonemapped previews of the evaluation (tonemap8, atrous/metrics.h; Python's atrous.tonemap).
ATROUS_INLINE unsigned char displayByte(float v) {
    v = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
    return (unsigned char)lroundf(v * 255.0f);
}

}  // namespace atrous

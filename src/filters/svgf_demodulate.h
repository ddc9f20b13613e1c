// SVGF stage 1: demodulation (docs/svgf.md, "Stages"). Filtering the illumination instead of the
// colour keeps texture detail out of the blur: illumination = (color - emission) / modulationAlbedo (svgf_common.h).
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

struct Demodulate {
    ImageView color;     // 3 channels, required
    ImageView albedo;    // 3 channels, optional (data == nullptr -> 1)
    ImageView emission;  // 3 channels, optional (-> 0)
    ImageView illum;     // out: 3 channels
    ImageView valid;     // out: 1 channel, 1 where the colour is a usable sample, 0 where not

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        Vec3 c = readVec3(color, x, y);
        // A non-finite colour is no sample at all: the accumulation keeps the history there and
        // the spatial filter ignores the pixel (NaN must never spread).
        if (!isFinite(c)) {
            writeVec3(illum, x, y, Vec3(0.0f));
            valid(x, y, 0) = 0.0f;
            return;
        }
        Vec3 l = (c - sanitizedEmission(emission, x, y)) / modulationAlbedo(albedo, x, y);
        l = Vec3(clampf(l.x, -kMaxIllum, kMaxIllum), clampf(l.y, -kMaxIllum, kMaxIllum),
                 clampf(l.z, -kMaxIllum, kMaxIllum));
        writeVec3(illum, x, y, l);
        valid(x, y, 0) = 1.0f;
    }
};

}  // namespace atrous::svgf

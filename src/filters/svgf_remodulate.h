// SVGF stage 6: remodulation (docs/svgf.md, "Stages"): colour = illumination × albedo + emission,
// with the same clamped albedo the demodulation divided by. The final guard maps anything
// non-finite to 0 so that no NaN leaves the filter whatever came in.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

struct Remodulate {
    ImageView illum;              // filtered illumination, 3 channels
    ImageView albedo, emission;   // the frame's raw inputs (optional, as in Demodulate)
    ImageView out;                // out: 3 channels

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        Vec3 c = readVec3(illum, x, y) * modulationAlbedo(albedo, x, y) + sanitizedEmission(emission, x, y);
        writeVec3(out, x, y, Vec3(finiteOr(c.x, 0.0f), finiteOr(c.y, 0.0f), finiteOr(c.z, 0.0f)));
    }
};

}  // namespace atrous::svgf

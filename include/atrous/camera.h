// The pinhole camera the renderer looks through (its frame as unit vectors), public for callers
// that move it: the viewer's session (atrous/view_pipeline.h), its orbit control.
#pragma once
#include "atrous/math.h"

namespace atrous::pt {

struct Camera {
    Vec3 position = Vec3(0.0f, 0.0f, 5.0f);
    Vec3 forward = Vec3(0.0f, 0.0f, -1.0f);  // unit
    Vec3 right = Vec3(1.0f, 0.0f, 0.0f);     // unit
    Vec3 up = Vec3(0.0f, 1.0f, 0.0f);        // unit
    float tanHalfFov = 0.4f;                 // tan(vertical fov / 2)
};

}  // namespace atrous::pt

// Consistency checks of an animated sequence from another renderer (docs/inputs.md,
// "Sequences"), run by the sequence session (include/atrous/sequence.h) before each frame is
// filtered: how much of the frame reprojects onto the previous one with the motion vectors as
// given and negated (a wrong sign convention reprojects far less), and whether the ids survive
// reprojection (Mitsuba renumbers its shapes whenever a scene is loaded: such ids must not cut
// the history).
#pragma once
#include "atrous/image.h"

namespace atrous::io {

struct ReprojectionCheck {
    int tested = 0;            // pixels of this frame on a surface (not background)
    double kept = 0;           // fraction of them that reproject onto the same surface (motion as given)
    double keptNegated = 0;    // ... with the motion negated
    double idsAgree = 1;       // of the reprojected pixels, the fraction whose ids match (1 without ids)
};

// Reprojects frame (depth, normal, ids, motion) onto the previous frame's depth, normal and ids.
// A pixel reprojects when its motion lands inside the image on a surface whose depth is within
// 5% and (with normals) whose normal is within ~25 degrees. Absent buffers are empty images.
ReprojectionCheck checkReprojection(const Image& depth, const Image& normal, const Image& ids, const Image& motion,
                                    const Image& prevDepth, const Image& prevNormal, const Image& prevIds);

}  // namespace atrous::io

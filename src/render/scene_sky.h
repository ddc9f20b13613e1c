// The procedural sky with a sun (scene "sphere-env" and the scene file's "sky" light).
#pragma once
#include <cmath>

#include "atrous/image.h"
#include "atrous/math.h"
#include "render/sampling.h"

namespace atrous::pt {

// Radiance of a clear sky: a blue zenith fading to a bright horizon, a warm glow around the sun,
// a dim ground below the horizon. Not a physical sky model; chosen to look plausible and give the
// strong, small sun that makes fireflies (what the denoisers must survive).
Vec3 skyRadiance(Vec3 dir, Vec3 sun);

// A lat-long environment map (w x h, RGB radiance) of the sky above with a sun disk of angular
// radius `sunAngularRadius` (radians) around `sunDir` (unit) and radiance `sunRadiance`. Inline on
// purpose: compiled into each caller, as it was when the built-in scenes and the parser shared one
// file, the compiler folds the callers' constant arguments in. An out-of-line copy gives the same
// map to within rounding but not bit for bit, and the renders of sky scenes would change.
inline Image makeSkyMap(int w, int h, Vec3 sunDir, float sunAngularRadius, Vec3 sunRadiance) {
    Image img(w, h, 3);
    const float cosSun = std::cos(sunAngularRadius);
    const int ss = 4;  // supersampling so the sun's disk has soft, correct coverage
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            Vec3 acc(0.0f);
            for (int j = 0; j < ss; ++j)
                for (int i = 0; i < ss; ++i) {
                    Vec3 dir = latLongToDirection((x + (i + 0.5f) / ss) / w, (y + (j + 0.5f) / ss) / h);
                    acc += dot(dir, sunDir) >= cosSun ? sunRadiance : skyRadiance(dir, sunDir);
                }
            acc = acc / float(ss * ss);
            for (int c = 0; c < 3; ++c) img(x, y, c) = acc[c];
        }
    return img;
}

}  // namespace atrous::pt

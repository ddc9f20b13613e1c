// The procedural sky (scene_sky.h).
#include "render/scene_sky.h"

#include <algorithm>
#include <cmath>

namespace atrous::pt {

Vec3 skyRadiance(Vec3 dir, Vec3 sun) {
    if (dir.y < 0.0f) return Vec3(0.16f, 0.15f, 0.13f) * 0.6f;
    float up = std::pow(std::max(0.0f, dir.y), 0.45f);
    Vec3 horizon(0.55f, 0.6f, 0.68f), zenith(0.12f, 0.24f, 0.55f);
    Vec3 c = horizon * (1.0f - up) + zenith * up;
    float cs = std::max(0.0f, dot(dir, sun));
    c += Vec3(0.9f, 0.7f, 0.45f) * (0.35f * std::pow(cs, 24.0f));
    return c;
}

}  // namespace atrous::pt

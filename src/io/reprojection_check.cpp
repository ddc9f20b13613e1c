#include "io/reprojection_check.h"

#include <cmath>

namespace atrous::io {

namespace {

bool surface(float z) { return z > 0.0f && z < 1e29f; }

struct Frames {
    const Image &depth, &normal, &ids, &motion, &prevDepth, &prevNormal, &prevIds;
    // 1 when (x, y) moved by sign * motion lands on the same surface in the previous frame.
    bool lands(int x, int y, float sign, int* qxOut, int* qyOut) const {
        const int w = depth.width(), h = depth.height();
        const float fx = x + sign * motion(x, y, 0), fy = y + sign * motion(x, y, 1);
        if (!std::isfinite(fx) || !std::isfinite(fy)) return false;
        const int qx = int(std::lround(fx)), qy = int(std::lround(fy));
        if (qx < 0 || qy < 0 || qx >= w || qy >= h) return false;
        const float z = depth(x, y, 0), zq = prevDepth(qx, qy, 0);
        if (!surface(zq) || std::fabs(z - zq) > 0.05f * std::fmax(z, zq)) return false;
        if (!normal.empty() && !prevNormal.empty()) {
            const float d = normal(x, y, 0) * prevNormal(qx, qy, 0) + normal(x, y, 1) * prevNormal(qx, qy, 1) +
                            normal(x, y, 2) * prevNormal(qx, qy, 2);
            if (d < 0.9f) return false;
        }
        *qxOut = qx;
        *qyOut = qy;
        return true;
    }
};

}  // namespace

ReprojectionCheck checkReprojection(const Image& depth, const Image& normal, const Image& ids, const Image& motion,
                                    const Image& prevDepth, const Image& prevNormal, const Image& prevIds) {
    ReprojectionCheck r;
    if (depth.empty() || prevDepth.empty() || motion.empty()) return r;
    const Frames f{depth, normal, ids, motion, prevDepth, prevNormal, prevIds};
    long kept = 0, keptNeg = 0, idTested = 0, idSame = 0;
    for (int y = 0; y < depth.height(); ++y)
        for (int x = 0; x < depth.width(); ++x) {
            if (!surface(depth(x, y, 0))) continue;
            ++r.tested;
            int qx = 0, qy = 0;
            if (f.lands(x, y, -1.0f, &qx, &qy)) ++keptNeg;
            if (!f.lands(x, y, 1.0f, &qx, &qy)) continue;
            ++kept;
            if (!ids.empty() && !prevIds.empty()) {
                ++idTested;
                idSame += ids(x, y, 0) == prevIds(qx, qy, 0) && ids(x, y, 1) == prevIds(qx, qy, 1);
            }
        }
    if (r.tested > 0) {
        r.kept = double(kept) / r.tested;
        r.keptNegated = double(keptNeg) / r.tested;
    }
    if (idTested > 0) r.idsAgree = double(idSame) / double(idTested);
    return r;
}

}  // namespace atrous::io

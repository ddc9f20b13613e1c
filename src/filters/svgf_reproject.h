// SVGF stage 2: reprojection (docs/svgf.md, "Stages"). Fetches last frame's accumulated illumination,
// luminance moments and history length at p + motion(p) with a bilinear 2x2 footprint whose taps
// are kept only where depth, normal and mesh id agree with the current pixel; if no tap survives,
// a 3x3 search around the reprojected position; if that fails too the history is reset
// (history length 0). Motion pointing outside the image (or non-finite, or absurdly large) is a
// disocclusion: reset, never an out-of-bounds read.
#pragma once
#include "filters/svgf_common.h"

namespace atrous::svgf {

struct Reproject {
    float depthTolerance = 2.0f;  // τ_z: |z_prev - z| <= τ_z (|dz/dx| + |dz/dy| + 0.01 z)
    float normalCos = 0.9f;       // minimum n_prev · n
    bool havePrevious = false;    // false on the first frame after a reset

    // current frame (sanitised)
    ImageView motion, depth, normal, ids, depthGrad;
    // previous frame
    ImageView prevIllum, prevMoments, prevLength, prevDepth, prevNormal, prevIds;
    // out: reprojected history (all zero where it was reset)
    ImageView outIllum, outMoments, outLength;

    ATROUS_HOST_DEVICE bool consistent(int qx, int qy, float z, Vec3 n, float id, float zTol) const {
        if (qx < 0 || qy < 0 || qx >= prevDepth.width || qy >= prevDepth.height) return false;
        if (prevIds(qx, qy, 0) != id) return false;
        float zq = prevDepth(qx, qy, 0);
        bool bp = isBackground(z), bq = isBackground(zq);
        if (bp || bq) return bp && bq;  // background matches background only
        if (!(fabsf(zq - z) <= zTol)) return false;
        Vec3 nq = readVec3(prevNormal, qx, qy);
        bool hp = hasNormal(n), hq = hasNormal(nq);
        if (hp != hq) return false;
        return !hp || dot(n, nq) >= normalCos;
    }

    ATROUS_HOST_DEVICE void writeReset(int x, int y) const {
        writeVec3(outIllum, x, y, Vec3(0.0f));
        outMoments(x, y, 0) = 0.0f;
        outMoments(x, y, 1) = 0.0f;
        outLength(x, y, 0) = 0.0f;
    }

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float mx = motion(x, y, 0), my = motion(x, y, 1);
        if (!havePrevious || !(fabsf(mx) < kMaxMotion) || !(fabsf(my) < kMaxMotion)) {
            writeReset(x, y);
            return;
        }
        float z = depth(x, y, 0);
        Vec3 n = readVec3(normal, x, y);
        float id = ids(x, y, 0);
        float zTol = depthTolerance * (fabsf(depthGrad(x, y, 0)) + fabsf(depthGrad(x, y, 1)) + 0.01f * fabsf(z));

        // Pixel centres are at integer coordinates here, so p + motion indexes the previous frame
        // directly and an integer motion hits one tap with weight 1 (exact copy).
        float px = float(x) + mx, py = float(y) + my;
        float fx0 = floorf(px), fy0 = floorf(py);
        int x0 = int(fx0), y0 = int(fy0);
        float fx = px - fx0, fy = py - fy0;

        Vec3 sumC(0.0f);
        float sumM0 = 0.0f, sumM1 = 0.0f, sumL = 0.0f, sumW = 0.0f;
        for (int j = 0; j < 2; ++j) {
            for (int i = 0; i < 2; ++i) {
                float w = (i ? fx : 1.0f - fx) * (j ? fy : 1.0f - fy);
                int qx = x0 + i, qy = y0 + j;
                if (w <= 0.0f || !consistent(qx, qy, z, n, id, zTol)) continue;
                sumC += w * readVec3(prevIllum, qx, qy);
                sumM0 += w * prevMoments(qx, qy, 0);
                sumM1 += w * prevMoments(qx, qy, 1);
                sumL += w * prevLength(qx, qy, 0);
                sumW += w;
            }
        }
        // Too little of the footprint survived (e.g. only a sliver of a tap): search 3x3 around
        // the nearest previous pixel with equal weights (Schied et al. 2017, Falcor's SVGF pass).
        if (sumW < 0.01f) {
            sumC = Vec3(0.0f);
            sumM0 = sumM1 = sumL = sumW = 0.0f;
            int cx = int(floorf(px + 0.5f)), cy = int(floorf(py + 0.5f));
            for (int j = -1; j <= 1; ++j) {
                for (int i = -1; i <= 1; ++i) {
                    int qx = cx + i, qy = cy + j;
                    if (!consistent(qx, qy, z, n, id, zTol)) continue;
                    sumC += readVec3(prevIllum, qx, qy);
                    sumM0 += prevMoments(qx, qy, 0);
                    sumM1 += prevMoments(qx, qy, 1);
                    sumL += prevLength(qx, qy, 0);
                    sumW += 1.0f;
                }
            }
        }
        if (sumW <= 0.0f) {
            writeReset(x, y);
            return;
        }
        float inv = 1.0f / sumW;
        writeVec3(outIllum, x, y, sumC * inv);
        outMoments(x, y, 0) = sumM0 * inv;
        outMoments(x, y, 1) = sumM1 * inv;
        outLength(x, y, 0) = sumL * inv;
    }
};

}  // namespace atrous::svgf

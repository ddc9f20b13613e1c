// Progressive accumulation of rendered frames (the viewer's running mean) and screen-space motion
// rebuilt from a depth buffer, as per-pixel functors: CpuExec runs them on TBB threads, CudaExec
// as kernels, so `atrous view` keeps the same math on either device and the CPU tests check the
// code the GPU runs.
//
// Storage: everything is float planes (atrous::Image, on the host or the GPU; Image is float and
// most GPUs have slow doubles). The old host code kept double sums because its variance came from
// E[x²] − E[x]², which cancels catastrophically in float once E[x]² ≫ var (a bright, nearly
// converged pixel). Here the colour uses Welford's update instead,
//   x̄_N = x̄_{N−1} + (x_N − x̄_{N−1}) / N,   M2_N = M2_{N−1} + (x_N − x̄_{N−1}) (x_N − x̄_N),
// which only adds products of deviations. Plain float Welford still loses digits when σ ≪ x̄: the
// rounding of x̄ (2^-24 x̄) enters every deviation, so var is off by ~0.1 · 2^-24 · 256 · x̄/σ
// (docs/decisions.md, "Renderer"). So the mean is kept compensated, as two
// float planes x̄ = hi + lo (hi is the output colour, lo its rounding residual, updated with
// Knuth's 2Sum): deviations are then exact to 2^-24 σ and both the mean and the pooled variance agree
// with a double reference to ~1e-6 relative after 256 frames whatever σ/x̄ (tests/accumulate_test.cpp
// checks it, and that the float E[x²] − E[x]² form fails the same check). Features are plain
// running means x̄ += (x − x̄)/N (their values are not squared), which lets the output planes
// (colour, albedo, position, emission, depth) be the state.
//
// 2Sum needs IEEE evaluation: no -ffast-math / reassociation (neither GCC nor nvcc is given
// it; contraction into FMA only makes the residual more exact).
#pragma once
#include <cmath>

#include "atrous/device.h"
#include "atrous/image.h"
#include "atrous/platform.h"
#include "atrous/math.h"
#include "render/camera.h"

namespace atrous {

// Planes of the accumulation state besides the outputs (AccumulateFrame).
// M2 of the frame means (rgb), mean within-frame variance (rgb), rounding residual lo of the mean (rgb)
constexpr int kAccumMomentChannels = 9;
constexpr int kAccumNormalChannels = 3;  // running mean of the unnormalised normals over feature hits
constexpr int kAccumCountChannels = 3;   // feature hits, depth hits, mean depth over depth hits

struct AccumulateParams {
    // 1: this frame starts the running mean: the outputs become the frame's buffers (the renderer
    // already averaged its samples) and, when `seed` is 1, the state is initialised for later frames.
    int restart = 1;
    int seed = 1;
    // s > 1 samples per frame: each frame brings its own variance of the mean (the renderer's
    // variance buffer), pooled with the spread of the frame means. At s = 1 it has none.
    int withinFrame = 0;
    float invN = 1.0f;  // 1 / N, N = frames in the mean including this one
    // var = varWithin · v̄ + varBetween · M2 with n = N s samples:
    // M2_total = N s (s − 1) v̄ + s M2 (the pooled variance of two sample sets), var = M2_total / (n (n − 1)),
    // so varWithin = (s − 1) / (n − 1) and varBetween = s / (n (n − 1)) (computed in double by
    // makeAccumulateParams).
    float varWithin = 0.0f, varBetween = 0.0f;
    float hitDepth = 0.1f * 1e30f;     // depth < hitDepth is a primary hit (0.1 · kBackgroundDepth)
    float backgroundDepth = 1e30f;     // depth written where no frame hit anything yet
};

// Frame N (1-based) of a running mean with s samples per frame; restart: N is 1.
inline AccumulateParams makeAccumulateParams(bool restart, bool seed, int frames, int spp, float backgroundDepth) {
    AccumulateParams p;
    p.restart = restart ? 1 : 0;
    p.seed = seed ? 1 : 0;
    p.withinFrame = spp > 1 ? 1 : 0;
    p.invN = float(1.0 / double(frames));
    const double s = double(spp), n = double(frames) * s;
    p.varWithin = n > 1.0 ? float((s - 1.0) / (n - 1.0)) : 0.0f;
    p.varBetween = n > 1.0 ? float(s / (n * (n - 1.0))) : 0.0f;
    p.hitDepth = 0.1f * backgroundDepth;
    p.backgroundDepth = backgroundDepth;
    return p;
}

// One frame into the running mean. Inputs: this frame's 3-channel buffers (emission may be
// invalid). Outputs: the means the filters see. State: see the k*Channels constants. All views
// are of one size and on the executor's device.
struct AccumulateFrame {
    AccumulateParams p;
    ImageView color, variance, albedo, normal, position, depth, ids, emission;
    ImageView outColor, outVariance, outAlbedo, outNormal, outPosition, outDepth, outIds, outEmission;
    ImageView moments, normalMean, counts;

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const size_t pl = color.plane();
        const size_t i0 = color.index(x, y);
        const bool featureHit =
            normal.data[i0] != 0.0f || normal.data[pl + i0] != 0.0f || normal.data[2 * pl + i0] != 0.0f;
        const float z = depth.data[i0];
        const bool depthHit = z < p.hitDepth;
        const bool haveEmission = emission.data != nullptr;
        if (p.restart) {
            for (int c = 0; c < 3; ++c) {
                const size_t i = size_t(c) * pl + i0;
                outColor.data[i] = color.data[i];
                outVariance.data[i] = variance.data[i];
                outAlbedo.data[i] = albedo.data[i];
                outNormal.data[i] = normal.data[i];
                outPosition.data[i] = position.data[i];
                outDepth.data[i] = depth.data[i];
                outIds.data[i] = ids.data[i];  // ids are never averaged (as the renderer: the first sample's)
                if (haveEmission) outEmission.data[i] = emission.data[i];
            }
            if (!p.seed) return;
            for (int c = 0; c < 3; ++c) {
                const size_t i = size_t(c) * pl + i0;
                moments.data[i] = 0.0f;  // M2 of one frame mean
                moments.data[3 * pl + i] = p.withinFrame ? variance.data[i] : 0.0f;
                moments.data[6 * pl + i] = 0.0f;  // the mean is the frame's colour exactly
                normalMean.data[i] = featureHit ? normal.data[i] : 0.0f;
            }
            counts.data[i0] = featureHit ? 1.0f : 0.0f;
            counts.data[pl + i0] = depthHit ? 1.0f : 0.0f;
            counts.data[2 * pl + i0] = depthHit ? z : 0.0f;
            return;
        }
        const float invN = p.invN;
        // Hit counts are small integers, exact in float up to 2^24 frames.
        const float fh = counts.data[i0] + (featureHit ? 1.0f : 0.0f);
        const float dh = counts.data[pl + i0] + (depthHit ? 1.0f : 0.0f);
        counts.data[i0] = fh;
        counts.data[pl + i0] = dh;
        float zMean = counts.data[2 * pl + i0];
        // The first hit sets the mean outright (x̄ + (x − x̄)·1 would round).
        if (depthHit) zMean = dh == 1.0f ? z : zMean + (z - zMean) / dh;
        counts.data[2 * pl + i0] = zMean;
        const float outZ = dh > 0.0f ? zMean : p.backgroundDepth;
        float nrm[3];
        for (int c = 0; c < 3; ++c) {
            const size_t i = size_t(c) * pl + i0;
            // Colour: compensated Welford (see the top of this file); x̄ = hi + lo.
            const float xv = color.data[i];
            const float hi = outColor.data[i], lo = moments.data[6 * pl + i];
            const float dOld = (xv - hi) - lo;  // x − x̄_{N−1}
            const float t = lo + dOld * invN;
            // 2Sum (Knuth): hiNew + loNew = hi + t exactly, whatever their magnitudes (a firefly
            // can make |t| > |hi|, where the cheaper Fast2Sum is not exact).
            const float hiNew = hi + t;
            const float tPart = hiNew - hi;
            const float loNew = (hi - (hiNew - tPart)) + (t - tPart);
            const float dNew = (xv - hiNew) - loNew;  // x − x̄_N
            const float m2 = moments.data[i] + dOld * dNew;
            moments.data[i] = m2;
            moments.data[6 * pl + i] = loNew;
            outColor.data[i] = hiNew;
            float vbar = 0.0f;
            if (p.withinFrame) {
                vbar = moments.data[3 * pl + i];
                vbar += (variance.data[i] - vbar) * invN;
                moments.data[3 * pl + i] = vbar;
            }
            // Variance of the mean pooled over all n = N·s samples.
            outVariance.data[i] = p.varWithin * vbar + p.varBetween * m2;
            outAlbedo.data[i] += (albedo.data[i] - outAlbedo.data[i]) * invN;
            if (haveEmission) outEmission.data[i] += (emission.data[i] - outEmission.data[i]) * invN;
            float pos = outPosition.data[i], nm = normalMean.data[i];
            if (featureHit) {
                if (fh == 1.0f) {
                    pos = position.data[i];
                    nm = normal.data[i];
                } else {
                    pos += (position.data[i] - pos) / fh;
                    nm += (normal.data[i] - nm) / fh;
                }
            } else if (fh == 0.0f) {
                pos = nm = 0.0f;  // no hit yet: zero features (as the renderer's background)
            }
            outPosition.data[i] = pos;
            normalMean.data[i] = nm;
            nrm[c] = nm;
            outDepth.data[i] = outZ;
        }
        const float len = sqrtf(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        const float inv = len > 0.0f ? 1.0f / len : 0.0f;
        for (int c = 0; c < 3; ++c) outNormal.data[size_t(c) * pl + i0] = nrm[c] * inv;
    }
};

struct MotionParams {
    pt::Camera current, previous;
    int moved = 0;                  // 0: the camera did not move, motion is zero
    float hitDepth = 0.1f * 1e30f;  // depth < hitDepth is a primary hit
    float offscreen = -1.0e4f;      // pt::kMotionOffscreen: "no previous position"
};

// Screen-space motion of the primary hit, previous − current, in pixels (docs/rendering.md, "The buffers"), for a
// renderer that wrote depth but no motion. The hit point is rebuilt from the depth (distance along
// the forward axis) on the pixel centre's ray; background pixels move like directions (points at
// infinity). Channel 2 is 0.
struct MotionFromDepth {
    MotionParams p;
    ImageView depth;   // channel 0
    ImageView motion;  // out: 3 channels

    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = motion.width, h = motion.height;
        const size_t pl = motion.plane(), i = motion.index(x, y);
        float mx = 0.0f, my = 0.0f;
        if (p.moved) {
            const pt::Camera& cur = p.current;
            const pt::Camera& prev = p.previous;
            const Vec3 dir = pt::cameraRayDirection(cur, float(x) + 0.5f, float(y) + 0.5f, w, h);
            const float z = depth.data[i];
            Vec3 v;  // from the previous eye towards the point
            if (z < p.hitDepth) {
                const float cosF = dot(dir, cur.forward);
                const float den = cosF < 1e-6f ? 1e-6f : cosF;  // std::max(cosF, 1e-6f)
                v = cur.position + dir * (z / den) - prev.position;
            } else {
                v = dir;
            }
            const float zf = dot(v, prev.forward);
            if (zf <= 1e-6f) {
                mx = my = p.offscreen;  // behind the previous camera: no history
            } else {
                const float aspect = float(w) / float(h);
                const float sx = dot(v, prev.right) / (zf * prev.tanHalfFov * aspect);
                const float sy = dot(v, prev.up) / (zf * prev.tanHalfFov);
                const float px = (sx + 1.0f) * 0.5f * float(w), py = (1.0f - sy) * 0.5f * float(h);
                mx = px - (float(x) + 0.5f);
                my = py - (float(y) + 0.5f);
            }
        }
        motion.data[i] = mx;
        motion.data[pl + i] = my;
        motion.data[2 * pl + i] = 0.0f;
    }
};

// Runs the functors on `device` over the output's size and waits for them (CUDA: the kernels are
// checked and synchronised, so the caller's stage times and any host read that follows are
// valid). The caller guarantees that every view lives on `device` (ViewPipeline checks the
// Images before building the views). Device::Cuda without a CUDA build throws RuntimeError.
void runAccumulateFrame(Device device, const AccumulateFrame& f);
void runMotionFromDepth(Device device, const MotionFromDepth& f);
void runAccumulateFrameCuda(const AccumulateFrame& f);  // src/cuda/cuda_accumulate.cu
void runMotionFromDepthCuda(const MotionFromDepth& f);

}  // namespace atrous

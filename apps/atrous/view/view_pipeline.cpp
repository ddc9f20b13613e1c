// The viewer's frame pipeline (see view_pipeline.h).
#include "view/view_pipeline.h"

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "atrous/error.h"
#include "core/timer.h"
#include "filters/denoise_internal.h"
#include "io/image_io.h"
#include "render/bvh_render.h"
#include "render/bvh_tracer.h"
#include "render/camera.h"

namespace atrous::view {

const char* methodName(Method m) {
    switch (m) {
        case Method::None: return "none";
        case Method::Eaw: return "eaw";
        case Method::Sure: return "sure";
        case Method::Svgf: return "svgf";
    }
    return "?";
}

Method parseMethod(const std::string& name) {
    if (name == "none") return Method::None;
    if (name == "eaw") return Method::Eaw;
    if (name == "sure") return Method::Sure;
    if (name == "svgf") return Method::Svgf;
    throw InputError("unknown method \"" + name + "\" (expected none, eaw, sure or svgf)");
}

namespace {

template <class F>
void forRows(int h, F f) {
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y) f(y);
    });
}

bool sameSvgfParams(const SvgfParams& a, const SvgfParams& b) {
    return a.sigmaL == b.sigmaL && a.sigmaN == b.sigmaN && a.sigmaZ == b.sigmaZ && a.alpha == b.alpha &&
           a.momentsAlpha == b.momentsAlpha && a.historyCap == b.historyCap && a.levels == b.levels &&
           a.feedbackTap == b.feedbackTap && a.spatialVarianceFrames == b.spatialVarianceFrames &&
           a.reprojectDepthTolerance == b.reprojectDepthTolerance && a.reprojectNormalCos == b.reprojectNormalCos &&
           a.taa == b.taa && a.taaAlpha == b.taaAlpha;
}

constexpr float kPi = 3.14159265358979f;

}  // namespace

// ---- orbit camera ----

OrbitCamera OrbitCamera::fromCamera(const pt::Camera& c, float pivotDistance) {
    OrbitCamera o;
    o.distance = std::max(pivotDistance, 1e-3f);
    o.target = c.position + c.forward * o.distance;
    const Vec3 off = c.position - o.target;
    o.yaw = std::atan2(off.x, off.z);
    o.pitch = std::asin(std::clamp(off.y / o.distance, -1.0f, 1.0f));
    o.tanHalfFov = c.tanHalfFov;
    return o;
}

pt::Camera OrbitCamera::camera() const {
    const Vec3 off(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
    pt::Camera c = pt::makeLookAtCamera(target + off * distance, target, Vec3(0, 1, 0), 45.0f);
    c.tanHalfFov = tanHalfFov;
    return c;
}

void OrbitCamera::orbit(float dYaw, float dPitch) {
    yaw += dYaw;
    // Short of the poles, where the look-at basis (world up) degenerates.
    const float limit = 89.0f * kPi / 180.0f;
    pitch = std::clamp(pitch + dPitch, -limit, limit);
}

void OrbitCamera::pan(const pt::Camera& c, float right, float up, float forward) {
    target += c.right * right + c.up * up + c.forward * forward;
}

void OrbitCamera::zoom(float factor) { distance = std::clamp(distance * factor, 1e-3f, 1e6f); }

// ---- pipeline ----

ViewPipeline::ViewPipeline(const Scene& scene, int width, int height, Device device, uint32_t seed)
    : mScene(scene), mWidth(width), mHeight(height), mDevice(device), mSeed(seed) {
    RenderSettings check;
    check.width = width;
    check.height = height;
    validateRenderSettings(check);  // --width / --height in the message
    const pt::SceneData& data = scene.data();
    mSceneCamera = mCamera = mPrevCamera = data.camera;
    mBvh = std::make_unique<BvhData>(pt::buildSceneBvh(data));
    if (mBvh->root != kBvhInvalidRef) {
        const Vec3 lo(mBvh->sceneLo[0], mBvh->sceneLo[1], mBvh->sceneLo[2]);
        const Vec3 hi(mBvh->sceneHi[0], mBvh->sceneHi[1], mBvh->sceneHi[2]);
        mSceneCenter = (lo + hi) * 0.5f;
        mSceneRadius = std::max(0.5f * length(hi - lo), 1e-3f);
    } else {
        mSceneCenter = data.camera.position + data.camera.forward;
        mSceneRadius = 1.0f;
    }
    mFrame = detail::allocateRenderBuffers(width, height, Device::Cpu);
    const size_t n = size_t(width) * height;
    for (auto* v : {&mSumX, &mSumX2, &mSumM2, &mSumAlbedo, &mSumNormal, &mSumPosition}) v->assign(3 * n, 0.0);
    mSumDepth.assign(n, 0.0);
    mFeatureHits.assign(n, 0);
    mDepthHits.assign(n, 0);
    for (Image* img : {&mColor, &mVariance, &mAlbedo, &mNormal, &mPosition, &mDepth, &mIds, &mMotion, &mEmission})
        *img = Image(width, height, 3);
}

ViewPipeline::~ViewPipeline() = default;

void ViewPipeline::setCamera(const pt::Camera& c) {
    mCamera = c;
    mCameraMoved = true;
    mAccumulating = false;  // the running mean belongs to the old view
}

void ViewPipeline::resetAccumulation() {
    mAccumulating = false;
    mSvgfResetPending = true;
}

void ViewPipeline::renderFrame(const PipelineSettings& s) {
    RenderSettings rs;
    rs.width = mWidth;
    rs.height = mHeight;
    rs.spp = s.sppPerFrame;
    rs.maxDepth = s.maxDepth;
    // A fresh seed per frame: Rng(pixel, sample, seed) streams of different seeds are independent,
    // so the frames are independent estimates and their running mean converges.
    rs.seed = mSeed + uint32_t(mFrameIndex * 0x9E3779B9ull);
    ++mFrameIndex;
    validateRenderSettings(rs);
    if (mDevice == Device::Cuda) {
        // renderBvhCuda takes the scene's own camera (no override hook): see cameraMovable().
        mFrame = renderBvhCuda(mScene, rs);
        return;
    }
    // The renderer's own per-pixel functor over the shared BVH, with our camera in the SceneView:
    // that is the camera override, with no change to the renderer, and the BVH is built once.
    const pt::SceneData& data = mScene.data();
    pt::SceneView sv = data.view();
    sv.camera = mCamera;
    auto k = detail::makePathTraceKernel(sv, pt::makeBvhTracer(mBvh->view(), data), mFrame, rs);
    tbb::parallel_for(tbb::blocked_range2d<int>(0, mHeight, 8, 0, mWidth, 8), [&](const tbb::blocked_range2d<int>& r) {
        for (int y = r.rows().begin(); y < r.rows().end(); ++y)
            for (int x = r.cols().begin(); x < r.cols().end(); ++x) k(x, y);
    });
}

void ViewPipeline::accumulateFrame(bool accumulate) {
    const int w = mWidth;
    const size_t plane = size_t(w) * mHeight;
    const bool restart = !accumulate || !mAccumulating;
    if (restart) {
        mFrames = 0;
        mIds.copyFrom(mFrame.ids);  // ids are not averaged (as the renderer: the first sample's)
    }
    mAccumulating = accumulate;
    ++mFrames;
    const int N = mFrames;
    const double spp = double(mSppAccumulated);
    forRows(mHeight, [&](int y) {
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            if (restart) {
                for (int c = 0; c < 3; ++c) {
                    mSumX[c * plane + p] = mSumX2[c * plane + p] = mSumM2[c * plane + p] = 0.0;
                    mSumAlbedo[c * plane + p] = mSumNormal[c * plane + p] = mSumPosition[c * plane + p] = 0.0;
                }
                mSumDepth[p] = 0.0;
                mFeatureHits[p] = mDepthHits[p] = 0;
            }
            const float* nrm = mFrame.normal.data();
            const bool featureHit = nrm[p] != 0.0f || nrm[plane + p] != 0.0f || nrm[2 * plane + p] != 0.0f;
            const float d = mFrame.depth.data()[p];
            const bool depthHit = d < 0.1f * kBackgroundDepth;
            mFeatureHits[p] += featureHit;
            mDepthHits[p] += depthHit;
            if (depthHit) mSumDepth[p] += d;
            for (int c = 0; c < 3; ++c) {
                const size_t i = c * plane + p;
                const double x_ = mFrame.color.data()[i];
                mSumX[i] += x_;
                mSumX2[i] += x_ * x_;
                // The frame's own sum of squared deviations: variance of its mean · s (s - 1).
                mSumM2[i] += double(mFrame.variance.data()[i]) * spp * (spp - 1.0);
                mSumAlbedo[i] += mFrame.albedo.data()[i];
                if (featureHit) {
                    mSumNormal[i] += mFrame.normal.data()[i];
                    mSumPosition[i] += mFrame.position.data()[i];
                }
            }
            // Finalise: mean colour, variance of the mean pooled over all N·s samples
            // (M2 = Σ M2_k + s Σ (x_k - x̄)², var = M2 / (n (n - 1))), averaged features.
            const double n = double(N) * spp;
            double nx = 0, ny = 0, nz = 0;
            for (int c = 0; c < 3; ++c) {
                const size_t i = c * plane + p;
                const double mean = mSumX[i] / N;
                mColor.data()[i] = float(mean);
                const double between = std::max(0.0, mSumX2[i] - mSumX[i] * mean);
                const double m2 = mSumM2[i] + spp * between;
                mVariance.data()[i] = n > 1 ? float(m2 / (n * (n - 1.0))) : 0.0f;
                mAlbedo.data()[i] = float(mSumAlbedo[i] / N);
                const int fh = mFeatureHits[p];
                mPosition.data()[i] = fh ? float(mSumPosition[i] / fh) : 0.0f;
                const double nv = fh ? mSumNormal[i] / fh : 0.0;
                (c == 0 ? nx : c == 1 ? ny : nz) = nv;
                mDepth.data()[i] = mDepthHits[p] ? float(mSumDepth[p] / mDepthHits[p]) : kBackgroundDepth;
            }
            const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
            const double inv = len > 0 ? 1.0 / len : 0.0;
            mNormal.data()[p] = float(nx * inv);
            mNormal.data()[plane + p] = float(ny * inv);
            mNormal.data()[2 * plane + p] = float(nz * inv);
        }
    });
    mVarianceValid = double(N) * spp > 1.0;
}

void ViewPipeline::computeMotion() {
    // Screen-space motion of the primary hit, previous - current, in pixels (ALGORITHMS.md 1). The
    // hit point is rebuilt from the frame's depth (distance along the forward axis) on the pixel
    // centre's ray; background pixels move like directions (points at infinity).
    const pt::Camera cur = mCamera, prev = mPrevCamera;
    const bool moved = mCameraMoved;
    const int w = mWidth, h = mHeight;
    const size_t plane = size_t(w) * h;
    const float aspect = float(w) / float(h);
    const float nan = std::nanf("");
    forRows(h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            float mx = 0.0f, my = 0.0f;
            if (moved) {
                const Vec3 dir = pt::cameraRayDirection(cur, float(x) + 0.5f, float(y) + 0.5f, w, h);
                const float z = mFrame.depth.data()[p];
                Vec3 v;  // from the previous eye towards the point
                if (z < 0.1f * kBackgroundDepth) {
                    const Vec3 hit = cur.position + dir * (z / std::max(dot(dir, cur.forward), 1e-6f));
                    v = hit - prev.position;
                } else {
                    v = dir;
                }
                const float zf = dot(v, prev.forward);
                if (zf <= 1e-6f) {
                    mx = my = nan;  // behind the previous camera: no history (SVGF reads NaN so)
                } else {
                    const float sx = dot(v, prev.right) / (zf * prev.tanHalfFov * aspect);
                    const float sy = dot(v, prev.up) / (zf * prev.tanHalfFov);
                    const float px = (sx + 1.0f) * 0.5f * float(w), py = (1.0f - sy) * 0.5f * float(h);
                    mx = px - (float(x) + 0.5f);
                    my = py - (float(y) + 0.5f);
                }
            }
            mMotion.data()[p] = mx;
            mMotion.data()[plane + p] = my;
            mMotion.data()[2 * plane + p] = 0.0f;
        }
    });
}

void ViewPipeline::computeEmission() {
    // SVGF demodulates (colour - emission) / albedo. The renderer writes no emission buffer, and
    // without one an emitter's radiance divided by its (small) albedo floods its neighbours. The
    // emission of the material named by the frame's material id (ids.G) stands in for it: exact
    // inside an emitter seen from its front, approximate on its silhouette (ids are the first
    // sample's).
    const pt::SceneData& data = mScene.data();
    const int nm = int(data.materials.size());
    const size_t plane = size_t(mWidth) * mHeight;
    const float* mat = mFrame.ids.data() + plane;
    float* e = mEmission.data();
    for (size_t p = 0; p < plane; ++p) {
        const int m = int(mat[p]);
        const Vec3 em = (mat[p] >= 0.0f && m < nm) ? data.materials[m].emission : Vec3(0.0f);
        e[p] = em.x;
        e[plane + p] = em.y;
        e[2 * plane + p] = em.z;
    }
}

DenoiseOptions ViewPipeline::denoiseOptions(Method m, const PipelineSettings& s) const {
    DenoiseOptions o;
    o.method = m == Method::Sure ? DenoiseMethod::Sure : DenoiseMethod::Eaw;
    o.device = mDevice;
    o.eaw = s.eaw;
    o.sure = s.sure;
    o.firefly = s.firefly;
    o.demodulate = s.demodulate;
    o.albedoEpsilon = s.albedoEpsilon;
    return o;
}

void ViewPipeline::runSlot(int i, Method m, const PipelineSettings& s) {
    SlotResult& r = mSlots[i];
    r.method = m;
    r.error.clear();
    r.filterMs = 0;
    if (m == Method::None) {
        r.image = mColor.clone();
        return;
    }
    if (m == Method::Svgf) {
        try {
            if (!mSvgf[i] || !sameSvgfParams(mSvgfParams[i], s.svgf)) {
                mSvgf[i] = std::make_unique<SvgfDenoiser>(s.svgf, mDevice);  // validates
                mSvgfParams[i] = s.svgf;
            }
            if (mSvgfResetPending || (mCameraMoved && !s.svgfMotionVectors)) mSvgf[i]->reset();
            // SVGF does its own temporal accumulation, so it takes this frame's samples, not the
            // running mean.
            SvgfFrame f;
            f.color = &mFrame.color;
            f.albedo = &mFrame.albedo;
            f.normal = &mFrame.normal;
            f.depth = &mFrame.depth;
            f.ids = &mFrame.ids;
            f.motion = &mMotion;
            f.emission = &mEmission;
            Timer t;
            r.image = mSvgf[i]->denoiseFrame(f);
            r.filterMs = t.ms();
        } catch (const InputError& e) {
            mSvgf[i].reset();
            r.error = e.what();
            r.image = mFrame.color.clone();
        }
        return;
    }
    DenoiseInputs in;
    in.color = &mColor;
    // At one sample per pixel there is no variance estimate: the filter then estimates the noise
    // from the image (Donoho's MAD) rather than seeing zero noise everywhere.
    in.variance = mVarianceValid ? &mVariance : nullptr;
    in.albedo = &mAlbedo;
    in.normal = &mNormal;
    in.position = &mPosition;
    in.depth = &mDepth;
    in.ids = &mIds;
    DenoiseOptions o = denoiseOptions(m, s);
    DenoiseReport rep;
    o.report = &rep;
    try {
        if (m == Method::Sure && s.sureFractions && mDevice == Device::Cpu) {
            // The public denoise() has no debug outputs; the internal CPU entry fills s_i(p).
            filters::PreparedInputs prep = filters::prepareInputs(in, o, rep);
            filters::DriverDebug dbg;
            dbg.sureS = Image(mWidth, mHeight, s.eaw.levels);
            r.image = filters::denoiseCpu(in, o, prep, rep, &dbg);
            mSureS = std::move(dbg.sureS);
        } else {
            r.image = denoise(in, o);
        }
        r.filterMs = rep.milliseconds;
    } catch (const InputError& e) {
        r.error = e.what();
        r.image = mColor.clone();
    }
}

void ViewPipeline::step(const PipelineSettings& s) {
    mTimes = StageTimes{};
    if (s.sppPerFrame != mSppAccumulated) {
        mAccumulating = false;  // a running mean mixes frames of one spp only
        mSppAccumulated = s.sppPerFrame;
    }
    Timer t;
    renderFrame(s);
    mTimes.render = t.ms();

    t.reset();
    accumulateFrame(s.accumulate);
    mTimes.accumulate = t.ms();

    const bool svgf = s.methodA == Method::Svgf || (s.split && s.methodB == Method::Svgf);
    t.reset();
    if (svgf) {
        computeMotion();
        computeEmission();
    }
    mTimes.motion = t.ms();

    if (!s.sureFractions) mSureS = Image();
    t.reset();
    runSlot(0, s.methodA, s);
    mTimes.denoiseA = t.ms();
    t.reset();
    if (s.split) runSlot(1, s.methodB, s);
    else mSlots[1] = SlotResult{};
    mTimes.denoiseB = t.ms();

    t.reset();
    mDetail = Image();
    mDetailLevelShown = -1;
    if (s.detailLevel >= 0 && s.detailLevel < s.eaw.levels) {
        // The driver does not expose d_i; EAW's cascade is prefix-consistent (level i's weights do
        // not depend on the total), so d_i = c_i - c_{i+1} = EAW(i levels) - EAW(i + 1 levels),
        // both remodulated by the albedo. c_0 is taken as the colour before firefly suppression.
        try {
            DenoiseInputs in;
            in.color = &mColor;
            in.variance = mVarianceValid ? &mVariance : nullptr;
            in.albedo = &mAlbedo;
            in.normal = &mNormal;
            in.position = &mPosition;
            in.depth = &mDepth;
            in.ids = &mIds;
            DenoiseOptions o = denoiseOptions(Method::Eaw, s);
            const int L = s.detailLevel;
            Image fine;
            if (L == 0) {
                fine = mColor.clone();
            } else {
                o.eaw.levels = L;
                fine = denoise(in, o);
            }
            o.eaw.levels = L + 1;
            Image coarse = denoise(in, o);
            for (size_t k = 0; k < fine.size(); ++k) fine.data()[k] -= coarse.data()[k];
            mDetail = std::move(fine);
            mDetailLevelShown = L;
        } catch (const InputError&) {
            mDetail = Image();
        }
    }
    mTimes.debug = t.ms();

    mPrevCamera = mCamera;
    mCameraMoved = false;
    mSvgfResetPending = false;
}

std::vector<std::string> ViewPipeline::saveBuffers(const std::string& dir) const {
    io::ensureWritableDirectory(dir);
    namespace fs = std::filesystem;
    std::vector<std::string> names;
    auto put = [&](const std::string& name, const Image& img) {
        if (img.empty()) return;
        io::writeImage((fs::path(dir) / name).string(), img);
        names.push_back(name);
    };
    put("color.exr", mColor);
    if (mVarianceValid) put("variance.exr", mVariance);
    put("albedo.exr", mAlbedo);
    put("normal.exr", mNormal);
    put("position.exr", mPosition);
    put("depth.exr", mDepth);
    put("ids.exr", mIds);
    const bool svgf = mSlots[0].method == Method::Svgf || mSlots[1].method == Method::Svgf;
    if (svgf) {
        put("motion.exr", mMotion);
        put("emission.exr", mEmission);
    }
    for (int i = 0; i < 2; ++i) {
        const SlotResult& r = mSlots[i];
        if (r.image.empty() || r.method == Method::None) continue;
        put(std::string(i == 0 ? "denoised_a_" : "denoised_b_") + methodName(r.method) + ".exr", r.image);
    }
    if (!mDetail.empty()) put("detail_level" + std::to_string(mDetailLevelShown) + ".exr", mDetail);
    for (int l = 0; l < mSureS.channels(); ++l) {
        Image one(mWidth, mHeight, 1);
        std::memcpy(one.data(), mSureS.data() + size_t(l) * mSureS.plane(), mSureS.plane() * sizeof(float));
        put("sure_s_level" + std::to_string(l) + ".exr", one);
    }
    return names;
}

}  // namespace atrous::view

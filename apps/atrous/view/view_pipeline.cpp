// The viewer's frame pipeline (see view_pipeline.h).
#include "view/view_pipeline.h"

#include <sys/resource.h>
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
        case Method::None:
            return "none";
        case Method::Eaw:
            return "eaw";
        case Method::Sure:
            return "sure";
        case Method::Svgf:
            return "svgf";
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
    return a.sigmaL == b.sigmaL && a.sigmaN == b.sigmaN && a.sigmaZ == b.sigmaZ &&
           a.alpha == b.alpha && a.momentsAlpha == b.momentsAlpha && a.historyCap == b.historyCap &&
           a.levels == b.levels && a.feedbackTap == b.feedbackTap &&
           a.spatialVarianceFrames == b.spatialVarianceFrames &&
           a.reprojectDepthTolerance == b.reprojectDepthTolerance &&
           a.reprojectNormalCos == b.reprojectNormalCos && a.taa == b.taa &&
           a.taaAlpha == b.taaAlpha;
}

constexpr float kPi = 3.14159265358979f;

}  // namespace

double processCpuMs() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return (double(u.ru_utime.tv_sec) + double(u.ru_stime.tv_sec)) * 1e3 +
           (double(u.ru_utime.tv_usec) + double(u.ru_stime.tv_usec)) * 1e-3;
}

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
    const Vec3 off(std::cos(pitch) * std::sin(yaw), std::sin(pitch),
                   std::cos(pitch) * std::cos(yaw));
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

void OrbitCamera::zoom(float factor) {
    distance = std::clamp(distance * factor, 1e-3f, 1e6f);
}

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
    for (auto* v : {&mSumX, &mSumX2, &mSumM2}) v->assign(3 * n, 0.0);
    for (auto* v : {&mSumAlbedo, &mSumNormal, &mSumPosition, &mSumEmission}) v->assign(3 * n, 0.0f);
    mSumDepth.assign(n, 0.0f);
    mFeatureHits.assign(n, 0);
    mDepthHits.assign(n, 0);
    for (Image* img : {&mColor, &mVariance, &mAlbedo, &mNormal, &mPosition, &mDepth, &mIds,
                       &mMotion, &mEmission, &mEmissionMean})
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

void ViewPipeline::renderFrame(const PipelineSettings& s, bool svgf) {
    RenderSettings rs;
    rs.width = mWidth;
    rs.height = mHeight;
    rs.spp = s.sppPerFrame;
    rs.maxDepth = s.maxDepth;
    // One seed, fresh sample indices per frame (frame * spp + s): every frame draws new samples
    // (own RNG streams) and the running mean continues each pixel's stratified sub-pixel sequence.
    rs.seed = mSeed;
    rs.firstSample = uint32_t(mFrameIndex * uint64_t(rs.spp));
    ++mFrameIndex;
    validateRenderSettings(rs);
    mRendererMotion = false;
    if (mDevice == Device::Cuda) {
        // The persistent renderer: scene and BVH uploaded once, device buffers kept, our camera
        // per call. It returns host buffers with emission but no motion: computeMotion() rebuilds
        // the motion from the depth.
        if (!mCudaRenderer) mCudaRenderer = std::make_unique<CudaBvhRenderer>(mScene);
        mFrame = mCudaRenderer->render(rs, &mCamera);
        return;
    }
    // The renderer's own per-pixel functor over the shared BVH, with our camera in the SceneView:
    // that is the camera override, with no change to the renderer, and the BVH is built once.
    const pt::SceneData& data = mScene.data();
    pt::SceneView sv = data.view();
    sv.camera = mCamera;
    auto k = detail::makePathTraceKernel(sv, pt::makeBvhTracer(mBvh->view(), data), mFrame, rs);
    if (svgf) {
        // SVGF's extra inputs straight from the renderer: the emission of the primary hit, and the
        // motion of each sample's primary hit reprojected into the previous camera (averaged over
        // the pixel's samples; the scene is static, so only the camera moves).
        k.out.motion = mMotion.view();
        k.motion.enabled = mCameraMoved;
        k.motion.previousCamera = mPrevCamera;
        mRendererMotion = true;
    }
    tbb::parallel_for(tbb::blocked_range2d<int>(0, mHeight, 8, 0, mWidth, 8),
                      [&](const tbb::blocked_range2d<int>& r) {
                          for (int y = r.rows().begin(); y < r.rows().end(); ++y)
                              for (int x = r.cols().begin(); x < r.cols().end(); ++x) k(x, y);
                      });
}

void ViewPipeline::accumulateFrame(bool accumulate) {
    const int w = mWidth;
    const size_t plane = size_t(w) * mHeight;
    const bool restart = !accumulate || !mAccumulating;
    mAccumulating = accumulate;
    if (restart) {
        // One frame: its buffers are the filters' input as they are (the renderer already averaged
        // the frame's samples). The sums are seeded only when later frames will add to them.
        mFrames = 1;
        mColor.copyFrom(mFrame.color);
        mVariance.copyFrom(mFrame.variance);
        mAlbedo.copyFrom(mFrame.albedo);
        mNormal.copyFrom(mFrame.normal);
        mPosition.copyFrom(mFrame.position);
        mDepth.copyFrom(mFrame.depth);
        mIds.copyFrom(mFrame.ids);  // ids are never averaged (as the renderer: the first sample's)
        mEmissionValid = !mFrame.emission.empty();
        if (mEmissionValid) mEmissionMean.copyFrom(mFrame.emission);
        mVarianceValid = mSppAccumulated > 1;
        if (!accumulate) return;
    } else {
        ++mFrames;
    }
    const int N = mFrames;
    const double spp = double(mSppAccumulated);
    const double invN = 1.0 / N;
    const double n = double(N) * spp;
    const double invVar = n > 1 ? 1.0 / (n * (n - 1.0)) : 0.0;
    const bool withinFrame = mSppAccumulated > 1;  // at 1 spp a frame has no own variance
    const float* fc = mFrame.color.data();
    const float* fv = mFrame.variance.data();
    const float* fa = mFrame.albedo.data();
    const float* fn = mFrame.normal.data();
    const float* fp = mFrame.position.data();
    const float* fd = mFrame.depth.data();
    const float* fe = mEmissionValid ? mFrame.emission.data() : nullptr;
    auto rows = [&](int y) {
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            const bool featureHit =
                fn[p] != 0.0f || fn[plane + p] != 0.0f || fn[2 * plane + p] != 0.0f;
            const bool depthHit = fd[p] < 0.1f * kBackgroundDepth;
            if (restart) {
                mFeatureHits[p] = featureHit;
                mDepthHits[p] = depthHit;
                mSumDepth[p] = depthHit ? fd[p] : 0.0f;
                for (int c = 0; c < 3; ++c) {
                    const size_t i = c * plane + p;
                    const double v = fc[i];
                    mSumX[i] = v;
                    mSumX2[i] = v * v;
                    if (withinFrame) mSumM2[i] = double(fv[i]) * spp * (spp - 1.0);
                    mSumAlbedo[i] = fa[i];
                    if (fe) mSumEmission[i] = fe[i];
                    mSumNormal[i] = featureHit ? fn[i] : 0.0f;
                    mSumPosition[i] = featureHit ? fp[i] : 0.0f;
                }
                continue;  // outputs already copied
            }
            const int fh = mFeatureHits[p] += featureHit;
            const int dh = mDepthHits[p] += depthHit;
            if (depthHit) mSumDepth[p] += fd[p];
            const float depth = dh ? mSumDepth[p] / float(dh) : kBackgroundDepth;
            const float invFh = fh ? 1.0f / float(fh) : 0.0f;
            float nrm[3];
            for (int c = 0; c < 3; ++c) {
                const size_t i = c * plane + p;
                const double v = fc[i];
                const double sx = mSumX[i] += v;
                const double sx2 = mSumX2[i] += v * v;
                // Each frame's own sum of squared deviations: the variance of its mean · s (s - 1).
                const double sm2 =
                    withinFrame ? (mSumM2[i] += double(fv[i]) * spp * (spp - 1.0)) : 0.0;
                // Variance of the mean pooled over all n = N·s samples:
                // M2 = Σ M2_k + s Σ (x_k - x̄)²,  var = M2 / (n (n - 1)).
                const double mean = sx * invN;
                const double m2 = sm2 + spp * std::max(0.0, sx2 - sx * mean);
                mColor.data()[i] = float(mean);
                mVariance.data()[i] = float(m2 * invVar);
                mAlbedo.data()[i] = (mSumAlbedo[i] += fa[i]) * float(invN);
                if (fe) mEmissionMean.data()[i] = (mSumEmission[i] += fe[i]) * float(invN);
                if (featureHit) {
                    mSumNormal[i] += fn[i];
                    mSumPosition[i] += fp[i];
                }
                mPosition.data()[i] = mSumPosition[i] * invFh;
                nrm[c] = mSumNormal[i] * invFh;
                mDepth.data()[i] = depth;
            }
            const float len = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
            const float inv = len > 0 ? 1.0f / len : 0.0f;
            for (int c = 0; c < 3; ++c) mNormal.data()[c * plane + p] = nrm[c] * inv;
        }
    };
    forRows(mHeight, rows);
    mVarianceValid = n > 1.0;
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
    const float kOffscreen = pt::kMotionOffscreen;  // the renderer's "no previous position"
    forRows(h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            float mx = 0.0f, my = 0.0f;
            if (moved) {
                const Vec3 dir =
                    pt::cameraRayDirection(cur, float(x) + 0.5f, float(y) + 0.5f, w, h);
                const float z = mFrame.depth.data()[p];
                Vec3 v;  // from the previous eye towards the point
                if (z < 0.1f * kBackgroundDepth) {
                    const Vec3 hit =
                        cur.position + dir * (z / std::max(dot(dir, cur.forward), 1e-6f));
                    v = hit - prev.position;
                } else {
                    v = dir;
                }
                const float zf = dot(v, prev.forward);
                if (zf <= 1e-6f) {
                    mx = my = kOffscreen;  // behind the previous camera: no history
                } else {
                    const float sx = dot(v, prev.right) / (zf * prev.tanHalfFov * aspect);
                    const float sy = dot(v, prev.up) / (zf * prev.tanHalfFov);
                    const float px = (sx + 1.0f) * 0.5f * float(w),
                                py = (1.0f - sy) * 0.5f * float(h);
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

DenoiseInputs ViewPipeline::accumulatedInputs() const {
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
    // Emission: the filters work on colour - emission and add back its edge-filtered mean, so a
    // visible light neither bleeds into the ceiling nor keeps its coverage noise (docs/denoising.md).
    in.emission = mEmissionValid ? &mEmissionMean : nullptr;
    return in;
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

const Image& ViewPipeline::resultHost(int i) const {
    SlotResult& r = mSlots[i];
    if (r.image.empty() && !r.deviceImage.empty()) r.image = r.deviceImage.to(Device::Cpu);
    return r.image;
}

void ViewPipeline::runSlot(int i, Method m, const PipelineSettings& s) {
    SlotResult& r = mSlots[i];
    r.method = m;
    r.error.clear();
    r.filterMs = 0;
    r.stages.clear();
    r.image = Image();
    r.deviceImage = Image();
    const bool onDevice = s.deviceResults && mDevice == Device::Cuda;
    if (m == Method::None) {
        if (onDevice)
            r.deviceImage = mColor.to(Device::Cuda);
        else
            r.image = mColor.clone();
        return;
    }
    if (m == Method::Svgf) {
        try {
            if (!mSvgf[i] || !sameSvgfParams(mSvgfParams[i], s.svgf)) {
                mSvgf[i] = std::make_unique<SvgfDenoiser>(s.svgf, mDevice);  // validates
                mSvgfParams[i] = s.svgf;
                mSvgf[i]->setReport(&mSvgfReport[i]);
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
            if (onDevice)
                r.deviceImage = mSvgf[i]->denoiseFrameOnDevice(f).clone();  // valid until next frame
            else
                r.image = mSvgf[i]->denoiseFrame(f);
            r.filterMs = t.ms();
            r.stages = mSvgfReport[i].stages;
        } catch (const InputError& e) {
            mSvgf[i].reset();
            r.error = e.what();
            r.image = mFrame.color.clone();
        }
        return;
    }
    DenoiseInputs in = accumulatedInputs();
    DenoiseOptions o = denoiseOptions(m, s);
    DenoiseReport rep;
    o.report = &rep;
    Timer t;
    try {
        if (m == Method::Sure && s.sureFractions && mDevice == Device::Cpu) {
            // The public denoise() has no debug outputs; the internal CPU entry fills s_i(p).
            filters::PreparedInputs prep = filters::prepareInputs(in, o, rep);
            filters::DriverDebug dbg;
            dbg.sureS = Image(mWidth, mHeight, s.eaw.levels);
            r.image = filters::denoiseCpu(in, o, prep, rep, &dbg);
            mSureS = std::move(dbg.sureS);
        } else if (onDevice) {
            // A colour on the GPU keeps denoise()'s result there (the other buffers are uploaded).
            const Image deviceColor = mColor.to(Device::Cuda);
            in.color = &deviceColor;
            r.deviceImage = denoise(in, o);
        } else {
            r.image = denoise(in, o);
        }
        r.filterMs = t.ms();
        r.stages = rep.stages;
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
    double c = processCpuMs();
    auto lap = [&](double& wall, double& cpu) {
        wall = t.ms();
        const double now = processCpuMs();
        cpu = now - c;
        c = now;
        t.reset();
    };
    const bool svgf = s.methodA == Method::Svgf || (s.split && s.methodB == Method::Svgf);
    renderFrame(s, svgf);
    lap(mTimes.render, mTimes.renderCpu);

    if (s.needAccumulated) {
        accumulateFrame(s.accumulate);
    } else {
        mAccumulating = false;
        mFrames = 1;
    }
    lap(mTimes.accumulate, mTimes.accumulateCpu);

    if (svgf) {
        if (!mRendererMotion) computeMotion();  // the CUDA renderer: motion from the depth buffer
        if (!mFrame.emission.empty())
            mEmission.copyFrom(mFrame.emission);
        else
            computeEmission();
    }
    lap(mTimes.motion, mTimes.motionCpu);

    if (!s.sureFractions) mSureS = Image();
    runSlot(0, s.methodA, s);
    lap(mTimes.denoiseA, mTimes.denoiseACpu);
    if (s.split)
        runSlot(1, s.methodB, s);
    else
        mSlots[1] = SlotResult{};
    lap(mTimes.denoiseB, mTimes.denoiseBCpu);

    mDetail = Image();
    mDetailLevelShown = -1;
    if (s.detailLevel >= 0 && s.detailLevel < s.eaw.levels) {
        // The driver does not expose d_i; EAW's cascade is prefix-consistent (level i's weights do
        // not depend on the total), so d_i = c_i - c_{i+1} = EAW(i levels) - EAW(i + 1 levels),
        // both remodulated by the albedo. c_0 is taken as the colour before firefly suppression.
        try {
            const DenoiseInputs in = accumulatedInputs();
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
    lap(mTimes.debug, mTimes.debugCpu);

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
        if (r.method == Method::None) continue;
        const Image& img = resultHost(i);
        if (img.empty()) continue;
        put(std::string(i == 0 ? "denoised_a_" : "denoised_b_") + methodName(r.method) + ".exr",
            img);
    }
    if (!mDetail.empty()) put("detail_level" + std::to_string(mDetailLevelShown) + ".exr", mDetail);
    for (int l = 0; l < mSureS.channels(); ++l) {
        Image one(mWidth, mHeight, 1);
        std::memcpy(one.data(), mSureS.data() + size_t(l) * mSureS.plane(),
                    mSureS.plane() * sizeof(float));
        put("sure_s_level" + std::to_string(l) + ".exr", one);
    }
    return names;
}

}  // namespace atrous::view

// The viewer's frame pipeline (see view_pipeline.h).
#include "atrous/view_pipeline.h"

#include <sys/resource.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <initializer_list>

#include "atrous/error.h"
#include "atrous/params.h"
#include "atrous/timer.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/image_io.h"
#include "render/accumulate.h"
#include "render/bvh_render.h"
#include "render/bvh_tracer.h"
#include "render/camera.h"

namespace atrous::view {

std::vector<std::string> methodNames() {
    std::vector<std::string> n{"none"};
    for (const DenoiseMethodInfo& m : denoiseMethods()) n.push_back(m.name);
    for (const SequenceMethodInfo& m : sequenceMethods())
        if (m.causal || m.causalMode) n.push_back(m.name);
    return n;
}

const char* methodName(const Method& m) {
    switch (m.kind) {
        case Method::Kind::None:
            return "none";
        case Method::Kind::Sequence:
            return m.sequence->name;
        case Method::Kind::Still:
            return denoiseMethodName(m.still);
    }
    return "?";
}

Method parseMethod(const std::string& name) {
    if (name == "none") return Method::none();
    if (const DenoiseMethodInfo* m = findDenoiseMethod(name)) return Method::of(m->method);
    if (const SequenceMethodInfo* m = findSequenceMethod(name))
        if (m->causal || m->causalMode) return Method::of(*m);
    std::string list;
    for (const std::string& n : methodNames()) list += (list.empty() ? "" : ", ") + n;
    throw InputError("unknown method \"" + name + "\" (expected " + list + ")");
}

namespace {

size_t sequenceIndex(const SequenceMethodInfo& m) {
    const auto& rows = sequenceMethods();
    for (size_t i = 0; i < rows.size(); ++i)
        if (&rows[i] == &m) return i;
    throw InputError(std::string("sequence method '") + m.name + "' is not a row of sequenceMethods()");
}

}  // namespace

ParamSet& sequenceParams(PipelineSettings& s, const SequenceMethodInfo& m) {
    const size_t i = sequenceIndex(m);
    if (s.sequence.size() <= i) s.sequence.resize(sequenceMethods().size());
    if (s.sequence[i].empty()) s.sequence[i] = m.params;
    return s.sequence[i];
}

const ParamSet& sequenceParams(const PipelineSettings& s, const SequenceMethodInfo& m) {
    const size_t i = sequenceIndex(m);
    return i < s.sequence.size() && !s.sequence[i].empty() ? s.sequence[i] : m.params;
}

double processCpuMs() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return (double(u.ru_utime.tv_sec) + double(u.ru_stime.tv_sec)) * 1e3 +
           (double(u.ru_utime.tv_usec) + double(u.ru_stime.tv_usec)) * 1e-3;
}

StageLap::StageLap() : mCpu(processCpuMs()) {}

void StageLap::operator()(double& wall, double& cpu) {
    wall = mTimer.ms();
    const double now = processCpuMs();
    cpu = now - mCpu;
    mCpu = now;
    mTimer.reset();
}

// ---- pipeline ----

ViewPipeline::ViewPipeline(const Scene& scene, int width, int height, Device device, uint32_t seed)
    : mScene(scene), mWidth(width), mHeight(height), mDevice(device), mSeed(seed) {
    RenderSettings check;
    check.width = width;
    check.height = height;
    validateRenderSettings(check);  // ParamError naming width / height
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
    if (device == Device::Cuda) {
        // The persistent renderer first: without a GPU its InputError names --device cuda before
        // anything is allocated on the device.
        mCudaRenderer = std::make_unique<CudaBvhRenderer>(mScene);
    } else {
        mFrame = detail::allocateRenderBuffers(width, height, Device::Cpu);
    }
    mMoments = Image(width, height, kAccumMomentChannels, device);
    mNormalMean = Image(width, height, kAccumNormalChannels, device);
    mCounts = Image(width, height, kAccumCountChannels, device);
    for (Image* img : {&mColor, &mVariance, &mAlbedo, &mNormal, &mPosition, &mDepth, &mIds,
                       &mMotion, &mEmission, &mEmissionMean})
        *img = Image(width, height, 3, device);
}

ViewPipeline::~ViewPipeline() = default;

void ViewPipeline::setCamera(const pt::Camera& c) {
    mCamera = c;
    mCameraMoved = true;
    mAccumulating = false;  // the running mean belongs to the old view
}

void ViewPipeline::resetAccumulation() {
    mAccumulating = false;
    mHistoryResetPending = true;
    mKey[0] = mKey[1] = mDetailKey = SlotKey{};  // a loaded frame: filter it again
}

void ViewPipeline::renderFrame(const PipelineSettings& s, bool ownSamples) {
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
    mCur = &mFrame;
    if (mDevice == Device::Cuda) {
        // The persistent renderer: scene and BVH uploaded once, device buffers kept, our camera
        // per call. Its buffers stay on the GPU (emission, no motion: computeMotion() rebuilds the
        // motion from the depth there).
        mCur = &mCudaRenderer->renderOnDevice(rs, &mCamera);
        return;
    }
    // The renderer's own per-pixel functor over the shared BVH, with our camera in the SceneView:
    // that is the camera override, with no change to the renderer, and the BVH is built once.
    const pt::SceneData& data = mScene.data();
    pt::SceneView sv = data.view();
    sv.camera = mCamera;
    auto k = detail::makePathTraceKernel(sv, pt::makeBvhTracer(mBvh->view(), data), mFrame, rs);
    if (ownSamples) {
        // SVGF's and the temporal method's extra inputs straight from the renderer: the emission of the primary hit, and the
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

namespace {

// Every image a functor is about to read or write must live on the device it runs on (a host
// pointer in a CUDA kernel, or the reverse, is the classic failure) and have the pipeline's size
// (the functors index every view with one plane size): checked before each launch.
void requireOn(Device d, int w, int h, std::initializer_list<const Image*> images, const char* what) {
    for (const Image* img : images) {
        if (img->empty() || img->device() != d)
            throw RuntimeError(std::string("view pipeline: ") + what + ": a buffer is " +
                               (img->empty() ? "missing" : "on the wrong device") + " (expected " +
                               deviceName(d) + ")");
        if (img->width() != w || img->height() != h || img->channels() < 3)
            throw RuntimeError(std::string("view pipeline: ") + what + ": a buffer is not " +
                               std::to_string(w) + "x" + std::to_string(h) + " with 3 channels");
    }
}

}  // namespace

void ViewPipeline::accumulateFrame(bool accumulate) {
    const RenderBuffers& f = frame();
    const bool restart = !accumulate || !mAccumulating;
    mAccumulating = accumulate;
    if (restart) {
        // One frame: its buffers are the filters' input as they are (the renderer already averaged
        // the frame's samples). The state is seeded only when later frames will add to it.
        mFrames = 1;
        mEmissionValid = !f.emission.empty();
    } else {
        ++mFrames;
    }
    AccumulateFrame a;
    a.p = makeAccumulateParams(restart, accumulate, mFrames, mSppAccumulated, kBackgroundDepth);
    requireOn(mDevice, mWidth, mHeight,
              {&f.color, &f.variance, &f.albedo, &f.normal, &f.position, &f.depth, &f.ids, &mColor,
               &mVariance, &mAlbedo, &mNormal, &mPosition, &mDepth, &mIds, &mEmissionMean, &mMoments,
               &mNormalMean, &mCounts},
              "accumulation");
    if (mEmissionValid) requireOn(mDevice, mWidth, mHeight, {&f.emission}, "accumulation");
    a.color = f.color.view(), a.variance = f.variance.view(), a.albedo = f.albedo.view();
    a.normal = f.normal.view(), a.position = f.position.view(), a.depth = f.depth.view();
    a.ids = f.ids.view();
    a.emission = mEmissionValid ? f.emission.view() : ImageView{};
    a.outColor = mColor.view(), a.outVariance = mVariance.view(), a.outAlbedo = mAlbedo.view();
    a.outNormal = mNormal.view(), a.outPosition = mPosition.view(), a.outDepth = mDepth.view();
    a.outIds = mIds.view(), a.outEmission = mEmissionMean.view();
    a.moments = mMoments.view(), a.normalMean = mNormalMean.view(), a.counts = mCounts.view();
    runAccumulateFrame(mDevice, a);
    mVarianceValid = double(mFrames) * double(mSppAccumulated) > 1.0;
}

void ViewPipeline::computeMotion() {
    // Screen-space motion from the frame's depth (render/accumulate.h, MotionFromDepth), for the
    // CUDA renderer, which writes no motion buffer.
    MotionFromDepth m;
    m.p.current = mCamera;
    m.p.previous = mPrevCamera;
    m.p.moved = mCameraMoved ? 1 : 0;
    m.p.hitDepth = 0.1f * kBackgroundDepth;
    m.p.offscreen = pt::kMotionOffscreen;  // the renderer's "no previous position"
    requireOn(mDevice, mWidth, mHeight, {&frame().depth, &mMotion}, "motion");
    m.depth = frame().depth.view();
    m.motion = mMotion.view();
    runMotionFromDepth(mDevice, m);
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
    const float* mat = frame().ids.data() + plane;  // host: computeEmission runs on the CPU only
    float* e = mEmission.data();
    for (size_t p = 0; p < plane; ++p) {
        const int m = int(mat[p]);
        const Vec3 em = (mat[p] >= 0.0f && m < nm) ? data.materials[m].emission : Vec3(0.0f);
        e[p] = em.x;
        e[plane + p] = em.y;
        e[2 * plane + p] = em.z;
    }
}

Frame ViewPipeline::accumulatedInputs() const {
    if (mLoaded) return io::refsOf(*mLoaded);  // as `atrous denoise --in` hands them over
    Frame r;
    r.set(io::Buffer::Color, &mColor).set(io::Buffer::Albedo, &mAlbedo).set(io::Buffer::Normal, &mNormal);
    r.set(io::Buffer::Position, &mPosition).set(io::Buffer::Depth, &mDepth).set(io::Buffer::ObjectId, &mIds);
    // At one sample per pixel there is no variance estimate: the filter then estimates the noise
    // from the image (Donoho's MAD) rather than seeing zero noise everywhere.
    if (mVarianceValid) r.set(io::Buffer::Variance, &mVariance);
    // Emission: the filters work on colour - emission and add back its edge-filtered mean, so a
    // visible light neither bleeds into the ceiling nor keeps its coverage noise (docs/denoising.md).
    if (mEmissionValid) r.set(io::Buffer::Emission, &mEmissionMean);
    return r;
}

DenoiseOptions ViewPipeline::denoiseOptions(Method m, const PipelineSettings& s) const {
    DenoiseOptions o = s.denoise;
    o.method = m.kind == Method::Kind::Still ? m.still : DenoiseMethod::Eaw;
    o.device = mDevice;
    return o;
}

const Image& ViewPipeline::resultHost(int i) const {
    SlotResult& r = mSlots[i];
    if (r.image.empty() && !r.deviceImage.empty()) r.image = r.deviceImage.to(Device::Cpu);
    return r.image;
}

const Image* ViewPipeline::buffer(Buffer b) const {
    switch (b) {
        case kColor: return &mColor;
        case kVariance: return &mVariance;
        case kAlbedo: return &mAlbedo;
        case kNormal: return &mNormal;
        case kPosition: return &mPosition;
        case kDepth: return &mDepth;
        case kIds: return &mIds;
        case kMotion: return &mMotion;
        case kEmission: return &mEmission;
        case kEmissionMean: return &mEmissionMean;
        case kBufferCount: break;
    }
    return &mColor;
}

const Image& ViewPipeline::hostBuffer(Buffer b) const {
    const Image& img = *buffer(b);
    if (img.device() == Device::Cpu) return img;
    // Downloaded once per step, into the same host allocation each time. Every kernel of the step
    // ran on the default stream and cudaMemcpy waits for them, so the copy sees the finished buffer.
    if (!mHostValid[b]) {
        if (mHost[b].empty()) mHost[b] = Image(img.width(), img.height(), img.channels(), Device::Cpu);
        mHost[b].copyFrom(img);
        mHostValid[b] = true;
    }
    return mHost[b];
}

void ViewPipeline::runSlot(int i, Method m, const PipelineSettings& s) {
    SlotResult& r = mSlots[i];
    r.method = m;
    r.error.clear();
    r.filterMs = 0;
    r.stages.clear();
    r.image = Image();
    r.deviceImage = Image();
    // On CUDA every input is on the GPU: the result stays there when the display can take it
    // (deviceResults) and is downloaded once here otherwise.
    const bool onDevice = s.deviceResults && mDevice == Device::Cuda;
    auto hostCopy = [](const Image& img) { return img.device() == Device::Cpu ? img.clone() : img.to(Device::Cpu); };
    if (m == Method::none()) {
        if (onDevice)
            r.deviceImage = mColor.clone();  // GPU to GPU
        else
            r.image = hostCopy(mColor);
        return;
    }
    if (m.kind == Method::Kind::Sequence) {
        runSequence(i, *m.sequence, s, r);
        return;
    }
    Frame in = accumulatedInputs();
    DenoiseOptions o = denoiseOptions(m, s);
    Timer t;
    try {
        if (m == Method::of(DenoiseMethod::Sure) && s.sureFractions && mDevice == Device::Cpu) {
            SureFractionsResult result = denoiseWithSureFractions(in, o);
            r.image = std::move(result.image);
            mSureS = std::move(result.fractions);
            r.stages = std::move(result.report.stages);
        } else {
            // On CUDA the inputs are the running means on the GPU: denoise() reads them in place
            // and leaves its result there.
            DenoiseResult result = denoiseWithReport(in, o);
            r.stages = std::move(result.report.stages);
            if (mDevice == Device::Cpu)
                r.image = std::move(result.image);
            else if (onDevice)
                r.deviceImage = std::move(result.image);
            else
                r.image = hostCopy(result.image);
        }
        r.filterMs = t.ms();
    } catch (const InputError& e) {
        r.error = e.what();
        r.image = hostCopy(mColor);
    }
}

// The slot's denoiser of sequence method m, made anew when the method, its parameters, the still
// method's options or where the results go changed (a new history), and reset when the
// accumulation restarts or the camera moved without motion vectors.
SequenceDenoiser& ViewPipeline::sequenceDenoiser(int i, const SequenceMethodInfo& m, const PipelineSettings& s,
                                                bool onDevice) {
    SequenceSlot& slot = mSequence[i];
    const ParamSet& params = sequenceParams(s, m);
    const DenoiseOptions still = denoiseOptions(Method::of(DenoiseMethod::Auto), s);
    if (!slot.denoiser || slot.method != &m || !slot.params.same(params) || slot.onDevice != onDevice ||
        (m.stillMethod && !sameParams(slot.still, still, denoiseParams()))) {
        slot = SequenceSlot{};
        SequenceSetup setup;
        setup.device = mDevice;
        setup.params = params;
        setup.still = still;
        setup.causal = true;  // the viewer has no later frames
        setup.timing = true;
        setup.keepOnDevice = onDevice;
        slot.denoiser = makeSequenceDenoiser(m.name, setup);  // validates
        slot.method = &m, slot.params = params, slot.still = still, slot.onDevice = onDevice;
    }
    if (mHistoryResetPending || (mCameraMoved && !s.sequenceMotionVectors)) slot.denoiser->reset();
    return *slot.denoiser;
}

SequenceInput ViewPipeline::renderedSequenceInput(bool own) const {
    SequenceInput in;
    if (own) {
        auto copy = std::make_shared<RenderBuffers>();
        for (const RenderBufferField& field : kRenderBufferFields) {
            const bool pipelines = field.image == &RenderBuffers::motion || field.image == &RenderBuffers::emission;
            if (!pipelines && !(frame().*field.image).empty()) copy.get()->*field.image = (frame().*field.image).clone();
        }
        copy->motion = mMotion.clone();
        copy->emission = mEmission.clone();
        in.buffers = copy->frame();
        in.owner = copy;
    } else {
        Frame refs = frame().frame();
        refs.set(io::Buffer::Motion, &mMotion).set(io::Buffer::Emission, &mEmission);
        in.buffers = refs;
    }
    return in;
}

Image ViewPipeline::noisyHost() const {
    const Image& c = mLoaded ? mLoaded->image[int(io::Buffer::Color)] : frame().color;
    return c.device() == Device::Cpu ? c.clone() : c.to(Device::Cpu);
}

// A sequence method takes this frame's own samples, not the running mean, with the pipeline's
// motion and emission. On CUDA all of them are device images, which a method that reads them there
// (SVGF) reads in place. A method that holds frames beyond this step (a window: temporal) gets its
// own copy of the frame.
void ViewPipeline::runSequence(int i, const SequenceMethodInfo& m, const PipelineSettings& s, SlotResult& r) {
    try {
        SequenceDenoiser& den = sequenceDenoiser(i, m, s, s.deviceResults && mDevice == Device::Cuda);
        if (mLoaded) {
            // A loaded frame: the history goes on only from the frame this one follows (a step
            // that filters the same frame again, or one after a jump, starts a new stream).
            if (mPushed[i] == 0 || mPushed[i] != mFollows) den.reset();
            mPushed[i] = mGeneration;
        }
        const bool own = den.lookbehind() + den.lookahead() > 0;
        SequenceInput in = mLoaded ? loadedSequenceInput(own) : renderedSequenceInput(own);
        Timer t;
        den.push(std::move(in));
        SequenceOutput out = den.next();
        r.filterMs = t.ms();
        r.stages = std::move(out.stages);
        if (out.image.device() == Device::Cpu)
            r.image = std::move(out.image);
        else
            r.deviceImage = std::move(out.image);  // valid until the slot changes
    } catch (const InputError& e) {
        mSequence[i] = SequenceSlot{};
        mPushed[i] = 0;
        r.error = e.what();
        r.image = noisyHost();
    }
}

void ViewPipeline::step(const PipelineSettings& s) {
    if (mLoaded) {
        stepLoaded(s);
        return;
    }
    mTimes = StageTimes{};
    mStepFiltered = true;
    for (bool& v : mHostValid) v = false;  // this step rewrites the buffers
    if (s.sppPerFrame != mSppAccumulated) {
        mAccumulating = false;  // a running mean mixes frames of one spp only
        mSppAccumulated = s.sppPerFrame;
    }
    StageLap lap;
    const bool ownSamples = s.methodA.ownSamples() || (s.split && s.methodB.ownSamples());
    renderFrame(s, ownSamples);
    lap(mTimes.render, mTimes.renderCpu);

    if (s.needAccumulated) {
        accumulateFrame(s.accumulate);
    } else {
        mAccumulating = false;
        mFrames = 1;
    }
    lap(mTimes.accumulate, mTimes.accumulateCpu);

    if (ownSamples) {
        if (!mRendererMotion) computeMotion();  // the CUDA renderer: motion from the depth buffer
        if (!frame().emission.empty())
            mEmission.copyFrom(frame().emission);  // same device: a host or a GPU-to-GPU copy
        else if (mDevice == Device::Cpu)
            computeEmission();
        else
            throw RuntimeError("view pipeline: the CUDA renderer wrote no emission buffer");
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

    computeDetail(s);
    lap(mTimes.debug, mTimes.debugCpu);

    mPrevCamera = mCamera;
    mCameraMoved = false;
    mHistoryResetPending = false;
}

void ViewPipeline::computeDetail(const PipelineSettings& s) {
    mDetail = Image();
    mDetailLevelShown = -1;
    if (s.detailLevel >= 0 && s.detailLevel < s.denoise.eaw.levels) {
        // The driver does not expose d_i; EAW's cascade is prefix-consistent (level i's weights do
        // not depend on the total), so d_i = c_i - c_{i+1} = EAW(i levels) - EAW(i + 1 levels),
        // both remodulated by the albedo. c_0 is taken as the colour before firefly suppression.
        try {
            const Frame in = accumulatedInputs();
            DenoiseOptions o = denoiseOptions(Method::of(DenoiseMethod::Eaw), s);
            const int L = s.detailLevel;
            // A debug view: on CUDA both results are brought to the host (the view shows them
            // from there anyway).
            auto toHost = [](Image img) { return img.device() == Device::Cpu ? std::move(img) : img.to(Device::Cpu); };
            Image fine;
            if (L == 0) {
                fine = color().clone();
            } else {
                o.eaw.levels = L;
                fine = toHost(denoise(in, o));
            }
            o.eaw.levels = L + 1;
            Image coarse = toHost(denoise(in, o));
            for (size_t k = 0; k < fine.size(); ++k) fine.data()[k] -= coarse.data()[k];
            mDetail = std::move(fine);
            mDetailLevelShown = L;
        } catch (const InputError&) {
            mDetail = Image();
        }
    }
}

std::vector<std::string> ViewPipeline::saveBuffers(const std::string& dir) const {
    io::ensureWritableDirectory(dir);
    namespace fs = std::filesystem;
    std::vector<std::string> names;
    auto put = [&](const std::string& name, const Image& img) {
        if (img.empty()) return;
        atrous::writeImage((fs::path(dir) / name).string(), img);
        names.push_back(name);
    };
    // The host accessors: on CUDA each buffer is downloaded here (once per step).
    put("color.exr", color());
    if (mVarianceValid) put("variance.exr", variance());
    put("albedo.exr", albedo());
    put("normal.exr", normal());
    put("position.exr", position());
    put("depth.exr", depth());
    put("ids.exr", ids());
    if (mSlots[0].method.ownSamples() || mSlots[1].method.ownSamples()) {
        put("motion.exr", motion());
        put("emission.exr", emission());
    }
    for (int i = 0; i < 2; ++i) {
        const SlotResult& r = mSlots[i];
        if (r.method == Method::none()) continue;
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

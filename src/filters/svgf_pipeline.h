// The SVGF per-frame driver, written once as a template on the executor (CpuExec from
// core/parallel.h, CudaExec from cuda/cuda_exec.cuh) so both backends run the same stage functors
// in the same order. SvgfState owns every buffer on the executor's device: the history carried
// from frame to frame and this frame's temporaries (allocated once per image size).
#pragma once
#include <memory>
#include <string>
#include <utility>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/learned.h"
#include "atrous/svgf.h"
#include "filters/learned.h"
#include "filters/stage_clock.h"
#include "filters/svgf_accumulate.h"
#include "filters/svgf_atrous.h"
#include "filters/svgf_emission.h"
#include "filters/svgf_gbuffer.h"
#include "filters/svgf_learned.h"
#include "filters/svgf_reproject.h"
#include "filters/svgf_safety.h"
#include "filters/svgf_taa.h"
#include "filters/svgf_variance.h"

namespace atrous::detail {

// Type-erased backend behind SvgfDenoiser (virtuals here, never inside a functor).
class SvgfBackend {
public:
    virtual ~SvgfBackend() = default;
    virtual Image denoiseFrame(const Frame& frame) = 0;
    virtual const Image& denoiseFrameOnDevice(const Frame& frame) = 0;
    virtual void reset() = 0;
    virtual void setTiming(bool on) = 0;
    virtual SvgfReport lastReport() const = 0;
    virtual void setLearnedWeights(const LearnedWeights& weights) = 0;
};

std::unique_ptr<SvgfBackend> makeSvgfCpuBackend(const SvgfParams& params);
// Defined in src/cuda/cuda_svgf.cu on CUDA builds; throws InputError otherwise.
std::unique_ptr<SvgfBackend> makeSvgfCudaBackend(const SvgfParams& params);

}  // namespace atrous::detail

namespace atrous::svgf {

// Checks the frame's buffers (colour present; every given buffer of the colour's size with enough
// channels) and returns nothing; throws InputError naming the buffer and the problem.
void checkFrame(const Frame& frame);

struct SvgfState {
    int width = 0, height = 0;
    bool havePrevious = false;  // history buffers hold a previous frame
    bool haveTaa = false;       // taaHistory holds a previous output
    bool haveEmission = false;  // histEmission holds a previous frame's accumulated emission
    int frames = 0;             // frames since the last reset

    // Carried across frames: accumulated illumination after the feedback tap, luminance moments,
    // history length, the previous frame's sanitised features, the TAA output, and the
    // accumulated emission with its own history length.
    Image histIllum, histMoments, histLength, prevDepth, prevNormal, prevIds, taaHistory;
    Image histEmission, histEmissionLength;
    // This frame.
    Image illum, valid, depth, normal, ids, motion, depthGrad;
    Image reprojIllum, reprojMoments, reprojLength;
    Image accIllum, accMoments, accLength, variance;
    Image levelIllum[2], levelVariance[2], nextHistIllum;
    Image output, taaOutput, accEmission, accEmissionLength;
    Image safeRel, safeOut;  // the safety net's difference plane and output (allocated on first use)
    Image lumStop;  // the à-trous level's luminance stop (Atrous::lumStop)
    Image learnedVar, learnedOut;  // learnedSpatial: the cascade's var and d_out (3 channels each)
    filters::LearnedCache learnedCache;  // learnedSpatial: the cascade's temporaries and device network
    const Image* result = nullptr;  // output or taaHistory after the last run

    void allocate(int w, int h, Device d) {
        width = w;
        height = h;
        havePrevious = haveTaa = haveEmission = false;
        frames = 0;
        auto make = [&](int c) { return Image(w, h, c, d); };
        histIllum = make(3), histMoments = make(2), histLength = make(1);
        prevDepth = make(1), prevNormal = make(3), prevIds = make(1), taaHistory = make(3);
        illum = make(3), valid = make(1), depth = make(1), normal = make(3), ids = make(1), motion = make(2);
        depthGrad = make(2);
        reprojIllum = make(3), reprojMoments = make(2), reprojLength = make(1);
        accIllum = make(3), accMoments = make(2), accLength = make(1), variance = make(1);
        for (int i = 0; i < 2; ++i) levelIllum[i] = make(3), levelVariance[i] = make(1);
        nextHistIllum = make(3), lumStop = make(1);
        learnedVar = Image(), learnedOut = Image();  // made by the first learned frame
        safeRel = Image(), safeOut = Image();        // made by the first frame with the safety net
        output = make(3), taaOutput = make(3);
        histEmission = make(3), histEmissionLength = make(1), accEmission = make(3), accEmissionLength = make(1);
        result = nullptr;
    }
};

template <class Exec>
class SvgfPipeline {
public:
    explicit SvgfPipeline(const SvgfParams& params, Exec exec = Exec{}) : mParams(params), mExec(exec) {
        validateSvgfParams(params);
        if (params.learnedSpatial) mLearned = LearnedWeights::builtin();
    }

    // The learned spatial filter's weights (learnedSpatial; the built-in ones until this is called).
    void setLearnedWeights(const LearnedWeights& weights) {
        if (!weights.impl) throw InputError("SVGF: empty learned weights");
        mLearned = weights;
    }

    void reset() {
        mState.havePrevious = mState.haveTaa = mState.haveEmission = false;
        mState.frames = 0;
    }

    // Runs every stage on `frame`; the result is left in *state().result on the executor's device.
    void run(const Frame& frame) {
        checkFrame(frame);
        const Device dev = mExec.device();
        const int w = frame.color->width(), h = frame.color->height();
        if (w != mState.width || h != mState.height || mState.illum.device() != dev || mState.illum.empty())
            mState.allocate(w, h, dev);  // a new size starts a new history
        SvgfState& s = mState;

        // Inputs not yet on the executor's device are copied there for this frame.
        Image holders[7];
        const Image* inputs[7] = {frame.color, frame.albedo, frame.normal, frame.depth, frame.ids, frame.motion, frame.emission};
        ImageView views[7];
        for (int i = 0; i < 7; ++i) {
            if (!inputs[i]) continue;
            if (inputs[i]->device() == dev) {
                views[i] = inputs[i]->view();
            } else {
                holders[i] = inputs[i]->to(dev);
                views[i] = holders[i].view();
            }
        }
        filters::StageClock* clock = mTiming ? mClock.get() : nullptr;
        if (clock) clock->start();
        const ImageView color = views[0], albedo = views[1], normalIn = views[2], depthIn = views[3], idsIn = views[4],
                        motionIn = views[5], emission = views[6];

        // illumination = (colour - emission) / a', clamped to ±kMaxIllum so that l² stays finite;
        // a non-finite colour is no sample (valid 0: the history is kept there).
        filters::DemodulateSample demod;
        demod.rule = albedoRule();
        demod.albedo = albedo, demod.in = color, demod.out = s.illum.view();
        demod.emission = emission, demod.valid = s.valid.view(), demod.maxAbs = kMaxIllum;
        mExec.forEachPixel(w, h, demod);
        mExec.forEachPixel(w, h, SanitizeGbuffer{depthIn, normalIn, idsIn, motionIn, s.depth.view(), s.normal.view(),
                                                 s.ids.view(), s.motion.view()});
        mExec.forEachPixel(w, h, DepthGradient{s.depth.view(), s.depthGrad.view()});
        filters::markStage(clock, "demodulate");

        Reproject rp;
        rp.depthTolerance = mParams.depthTolerance;
        rp.normalCos = mParams.normalCos;
        rp.havePrevious = s.havePrevious;
        rp.motion = s.motion.view(), rp.depth = s.depth.view(), rp.normal = s.normal.view(), rp.ids = s.ids.view();
        rp.depthGrad = s.depthGrad.view();
        rp.prevIllum = s.histIllum.view(), rp.prevMoments = s.histMoments.view(), rp.prevLength = s.histLength.view();
        rp.prevDepth = s.prevDepth.view(), rp.prevNormal = s.prevNormal.view(), rp.prevIds = s.prevIds.view();
        rp.outIllum = s.reprojIllum.view(), rp.outMoments = s.reprojMoments.view(), rp.outLength = s.reprojLength.view();
        mExec.forEachPixel(w, h, rp);
        filters::markStage(clock, "reproject");

        Accumulate acc;
        acc.alpha = mParams.alpha;
        acc.momentsAlpha = mParams.momentsAlpha;
        acc.historyCap = float(mParams.historyCap);
        acc.historyClip = mParams.historyClip;
        acc.illum = s.illum.view(), acc.valid = s.valid.view();
        acc.histIllum = s.reprojIllum.view(), acc.histMoments = s.reprojMoments.view(), acc.histLength = s.reprojLength.view();
        acc.outIllum = s.accIllum.view(), acc.outMoments = s.accMoments.view(), acc.outLength = s.accLength.view();
        mExec.forEachPixel(w, h, acc);
        filters::markStage(clock, "accumulate");

        Variance var;
        var.spatialFrames = float(mParams.spatialVarianceFrames);
        var.sigmaN = mParams.sigmaN;
        var.sigmaZ = mParams.sigmaZ;
        var.moments = s.accMoments.view(), var.length = s.accLength.view();
        var.depth = s.depth.view(), var.normal = s.normal.view(), var.depthGrad = s.depthGrad.view();
        var.variance = s.variance.view();
        mExec.forEachPixel(w, h, var);
        filters::markStage(clock, "variance");

        // À-trous levels, ping-ponging between two buffers; the level at the feedback tap writes
        // straight into next frame's colour history instead (no copy). With the learned spatial
        // filter only the levels up to the feedback tap run, for the history alone.
        const int svgfLevels =
            mParams.learnedSpatial ? (mParams.levels > 0 ? mParams.feedbackTap + 1 : 0) : mParams.levels;
        ImageView inIllum = s.accIllum.view(), inVar = s.variance.view();
        for (int level = 0; level < svgfLevels; ++level) {
            Atrous at;
            at.sigmaL = mParams.sigmaL, at.sigmaN = mParams.sigmaN, at.sigmaZ = mParams.sigmaZ;
            at.step = 1 << level;
            at.illum = inIllum, at.variance = inVar, at.length = s.accLength.view();
            at.depth = s.depth.view(), at.normal = s.normal.view(), at.depthGrad = s.depthGrad.view();
            at.outIllum = level == mParams.feedbackTap ? s.nextHistIllum.view() : s.levelIllum[level & 1].view();
            at.outVariance = s.levelVariance[level & 1].view();
            at.lumStop = s.lumStop.view();
            runSvgfAtrous(mExec, at);
            filters::markStage(clock, "level", level);
            inIllum = at.outIllum;
            inVar = at.outVariance;
        }
        if (mParams.learnedSpatial) {
            // The learned cascade on the accumulation (svgf_learned.h): its output is what is
            // remodulated; the frame's own albedo, normal and depth where they were given.
            if (s.learnedOut.empty()) s.learnedVar = Image(w, h, 3, dev), s.learnedOut = Image(w, h, 3, dev);
            mExec.forEachPixel(w, h, LearnedInputVariance{mParams.alpha, s.variance.view(), s.accLength.view(),
                                                          s.learnedVar.view()});
            const PreparedView planes = filters::preparedView(s.accIllum.view(), s.learnedVar.view(), albedo,
                                                normalIn.valid() ? s.normal.view() : ImageView{},
                                                depthIn.valid() ? s.depth.view() : ImageView{});
            filters::runLearned(mExec, mLearned, planes, s.learnedOut.view(), nullptr, &s.learnedCache);
            filters::markStage(clock, "learned");
            inIllum = s.learnedOut.view();
        }

        // Emission: with a buffer and emissionAlpha < 1 the accumulated emission is added back
        // instead of this frame's (see svgf_emission.h); its history follows the same frames.
        ImageView remodEmission = emission;
        const bool accumulateEmission = emission.valid() && mParams.emissionAlpha < 1.0f;
        if (accumulateEmission) {
            AccumulateEmission ae;
            ae.alpha = mParams.emissionAlpha;
            ae.motionAlpha = mParams.emissionMotionAlpha;
            ae.historyCap = float(mParams.historyCap);
            ae.havePrevious = s.haveEmission;
            ae.emission = emission, ae.motion = s.motion.view();
            ae.prevEmission = s.histEmission.view(), ae.prevLength = s.histEmissionLength.view();
            ae.outEmission = s.accEmission.view(), ae.outLength = s.accEmissionLength.view();
            mExec.forEachPixel(w, h, ae);
            remodEmission = s.accEmission.view();
        }
        filters::RemodulateGuarded remod;  // colour = illumination × a' + emission, non-finite -> 0
        remod.rule = albedoRule();
        remod.base = inIllum, remod.albedo = albedo, remod.emission = remodEmission, remod.out = s.output.view();
        mExec.forEachPixel(w, h, remod);
        filters::markStage(clock, "remodulate");
        s.result = &s.output;
        if (mParams.taa) {
            Taa taa;
            taa.alpha = mParams.taaAlpha;
            taa.havePrevious = s.haveTaa;
            taa.current = s.output.view(), taa.motion = s.motion.view(), taa.history = s.taaHistory.view();
            taa.out = s.taaOutput.view();
            mExec.forEachPixel(w, h, taa);
            filters::markStage(clock, "taa");
            std::swap(s.taaHistory, s.taaOutput);
            s.haveTaa = true;
            s.result = &s.taaHistory;
        }
        if (mParams.safetyNet > 0.0f) {
            // The still default on the frame alone (on this device; host inputs come back on the
            // host and go up again), then the per-pixel give-way (svgf_safety.h).
            DenoiseOptions o;
            o.device = dev;
            o.weights = mLearned;
            Image still = denoise(frame, o);
            if (still.device() != dev) still = still.to(dev);
            if (s.safeRel.empty()) s.safeRel = Image::uninitialized(w, h, 1, dev), s.safeOut = Image::uninitialized(w, h, 3, dev);
            mExec.forEachPixel(w, h, SafetyDifference{s.result->view(), still.view(), s.safeRel.view()});
            mExec.forEachPixel(w, h, SafetyBlend{mParams.safetyNet, s.result->view(), still.view(), s.safeRel.view(),
                                                 s.safeOut.view()});
            filters::markStage(clock, "safety net");
            s.result = &s.safeOut;
            mExec.synchronize();  // `still` dies at the end of this scope
        }

        // This frame becomes the history. Swaps move ownership only; nothing is copied.
        // With no à-trous level (levels 0) nothing was filtered: the history is the accumulation
        // whatever the tap says.
        if (mParams.feedbackTap < 0 || mParams.levels == 0)
            std::swap(s.histIllum, s.accIllum);
        else
            std::swap(s.histIllum, s.nextHistIllum);
        std::swap(s.histMoments, s.accMoments);
        std::swap(s.histLength, s.accLength);
        std::swap(s.prevDepth, s.depth);
        std::swap(s.prevNormal, s.normal);
        std::swap(s.prevIds, s.ids);
        if (accumulateEmission) {
            std::swap(s.histEmission, s.accEmission);
            std::swap(s.histEmissionLength, s.accEmissionLength);
        }
        s.haveEmission = accumulateEmission;  // a frame without emission breaks the emission history
        s.havePrevious = true;
        ++s.frames;
        mExec.synchronize();  // the holders die at the end of this scope
        if (clock) mReport.milliseconds = clock->collect(mReport.stages);
    }

    // run() and a copy of the result on the host.
    Image denoiseFrame(const Frame& frame) {
        run(frame);
        return mState.result->to(Device::Cpu);
    }

    SvgfState& state() { return mState; }
    // Per-stage timings of each later run() (lastReport); off: no timing.
    void setTiming(bool on) {
        mTiming = on;
        if (on && !mClock) mClock = filters::makeStageClock(mExec.device());
        if (!on) mReport = SvgfReport{};
    }
    const SvgfReport& lastReport() const { return mReport; }
    const SvgfParams& params() const { return mParams; }

private:
    SvgfParams mParams;
    LearnedWeights mLearned;  // learnedSpatial: the built-in weights or setLearnedWeights
    Exec mExec;
    SvgfState mState;
    bool mTiming = false;
    SvgfReport mReport;  // the last timed frame's
    std::unique_ptr<filters::StageClock> mClock;
};

template <class Exec>
class SvgfBackendImpl final : public detail::SvgfBackend {
public:
    explicit SvgfBackendImpl(const SvgfParams& p) : mPipeline(p) {}
    Image denoiseFrame(const Frame& frame) override { return mPipeline.denoiseFrame(frame); }
    const Image& denoiseFrameOnDevice(const Frame& frame) override {
        mPipeline.run(frame);
        return *mPipeline.state().result;
    }
    void reset() override { mPipeline.reset(); }
    void setTiming(bool on) override { mPipeline.setTiming(on); }
    SvgfReport lastReport() const override { return mPipeline.lastReport(); }
    void setLearnedWeights(const LearnedWeights& weights) override { mPipeline.setLearnedWeights(weights); }

private:
    SvgfPipeline<Exec> mPipeline;
};

}  // namespace atrous::svgf

// The interactive session behind `atrous view`, without any windowing: progressive path tracing
// with a movable camera, accumulation of the buffers over frames, screen-space motion vectors for
// SVGF, the denoisers of the two comparison slots, and the debug buffers (per-level detail, SURE's
// s_i). A session of the library (src/api/view_pipeline.cpp), so that the viewer's GLFW/ImGui code
// (apps/atrous/view) only shows it and another front-end can drive it; tests/view_pipeline_test.cpp
// tests it on its own.
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/image.h"
#include "atrous/io/buffer_set.h"
#include "atrous/render.h"
#include "atrous/stage_time.h"
#include "atrous/timer.h"
#include "atrous/param_set.h"
#include "atrous/sequence_methods.h"
#include "atrous/camera.h"
#include "atrous/math.h"

namespace atrous {
class CudaBvhRenderer;  // src/render/bvh_render.h
struct BvhData;         // src/render/bvh_build.h
}

namespace atrous::view {

// A method of the viewer's list, which is the library's lists: "none" (the noisy input), each still
// method (denoiseMethods(), include/atrous/denoise.h; auto included), each causal sequence method
// (sequenceMethods(), include/atrous/sequence_methods.h: svgf) and each one with a causal mode, run
// in it (temporal: frames t-3..t, since the viewer has no later frames).
struct Method {
    enum class Kind : unsigned char { None, Still, Sequence };
    Kind kind = Kind::None;
    DenoiseMethod still = DenoiseMethod::Auto;      // Kind::Still: the still method
    const SequenceMethodInfo* sequence = nullptr;  // Kind::Sequence: its row
    static Method none() { return {}; }
    static Method of(DenoiseMethod m) { return {Kind::Still, m, nullptr}; }
    static Method of(const SequenceMethodInfo& m) { return {Kind::Sequence, DenoiseMethod::Auto, &m}; }
    // A sequence method takes each frame's own samples (with motion and emission), not the running
    // mean the still methods filter.
    bool ownSamples() const { return kind == Kind::Sequence; }
    bool operator==(const Method& o) const {
        return kind == o.kind && (kind != Kind::Still || still == o.still) && (kind != Kind::Sequence || sequence == o.sequence);
    }
    bool operator!=(const Method& o) const { return !(*this == o); }
};
// The names of the list in order (the panel's combo boxes, `atrous view --method`'s help).
// Read from the registries on each call: a method registered later is in it.
std::vector<std::string> methodNames();
const char* methodName(const Method& m);
Method parseMethod(const std::string& name);  // a name of methodNames(); InputError otherwise


// Everything the user can change between frames.
struct PipelineSettings {
    int sppPerFrame = 1;
    bool accumulate = true;  // EAW/SURE/none filter the running mean over frames
    // False when nothing will read the accumulated buffers this frame (only sequence-method slots,
    // which take each frame's own samples, and the result or motion view): the accumulation is
    // skipped (its cost: docs/decisions.md, "Speed") and the running mean restarts when needed again.
    bool needAccumulated = true;
    int maxDepth = 8;
    Method methodA = Method::of(DenoiseMethod::Blend);  // what auto picks with the renderer's albedo and normal
    Method methodB = Method::none();
    bool split = false;  // compute slot B too (split-screen comparison)
    // EAW's and SURE's parameters (SURE runs on the EAW cascade); the slot sets method, device
    // and report. The panel's controls are their tables' rows (params.h).
    DenoiseOptions denoise;
    // Each sequence method's parameters, by its place in sequenceMethods() (sequenceParams() below:
    // the row's defaults until set). A method with a causal mode runs in it; one that ends with a
    // still method ends with auto, with `denoise`'s parameters.
    std::vector<ParamSet> sequence;
    // The sequence methods on camera motion: true = feed reprojection motion vectors computed from
    // the depth buffer and the previous camera (history survives the move); false = reset the
    // history instead.
    bool sequenceMotionVectors = true;
    // Debug buffers, computed only when asked for (they cost extra filter runs).
    int detailLevel = -1;        // >= 0: compute d_i for this level
    bool sureFractions = false;  // capture SURE's s_i(p) (CPU only)
    // CUDA only: leave the slots' results on the GPU (SlotResult::deviceImage) for the CUDA-OpenGL
    // interop display; host copies are made only when something asks for them (resultHost()).
    bool deviceResults = false;
};

// The parameters of sequence method m in s: the row's defaults until set (the panel's controls and
// the viewer's flags write there).
ParamSet& sequenceParams(PipelineSettings& s, const SequenceMethodInfo& m);
const ParamSet& sequenceParams(const PipelineSettings& s, const SequenceMethodInfo& m);

// Milliseconds spent in each stage of the last step(): wall clock, and CPU time of the whole
// process (user + system over all threads, getrusage), which other tenants of a shared machine
// distort much less.
struct StageTimes {
    double render = 0, accumulate = 0, motion = 0, denoiseA = 0, denoiseB = 0, debug = 0;
    double renderCpu = 0, accumulateCpu = 0, motionCpu = 0, denoiseACpu = 0, denoiseBCpu = 0,
           debugCpu = 0;
};

// Process CPU time (user + system, all threads) in milliseconds.
double processCpuMs();

// Times consecutive stages: lap(wall, cpu) sets the wall clock and the process CPU time (ms) since
// the previous lap, or since construction.
class StageLap {
  public:
    StageLap();
    void operator()(double& wall, double& cpu);

  private:
    Timer mTimer;
    double mCpu;
};

// One slot's result.
struct SlotResult {
    Method method = Method::none();
    Image image;          // 3-channel linear HDR (the noisy input for Method::none())
    // On the GPU when PipelineSettings::deviceResults asked for it (image is then empty until
    // ViewPipeline::resultHost() downloads it).
    Image deviceImage;
    std::string error;    // non-empty when the filter refused its parameters (image = input then)
    double filterMs = 0;  // wall clock of the slot's filter call (uploads and checks included)
    // The filter's own per-stage times (DenoiseReport::stages / SequenceOutput::stages); their sum is
    // at most filterMs, the rest being validation, noise estimation and transfers.
    std::vector<StageTime> stages;
};

class ViewPipeline {
  public:
    // `device` Cpu renders with the shared BVH traversal on TBB threads (camera freely movable);
    // Cuda renders with a persistent CudaBvhRenderer (scene and BVH uploaded once, the viewer's
    // camera passed per frame) and runs the filters on the GPU.
    ViewPipeline(const Scene& scene, int width, int height, Device device, uint32_t seed);
    // A frame read from files (`atrous view --in`, `--sequence`; src/api/view_files.cpp): no
    // renderer, no camera and no accumulation. The loaded buffers are the frame: the still methods
    // take them as `atrous denoise --in` hands them over (io::refsOf), the sequence methods as one
    // frame of a stream. A slot is filtered again only when its method, its parameters or the frame
    // changed (step() is cheap otherwise). The buffer views show host copies (3 planes each; zero
    // where the files had no such buffer); the filters run on `device`.
    ViewPipeline(io::BufferSet frame, Device device);
    // Replaces the loaded frame (a sequence's other frame: the same size, else InputError).
    // follows: it comes right after the current one, and the sequence methods continue their
    // history; otherwise they start a new one at this frame.
    void setFrame(io::BufferSet frame, bool follows);
    bool fromFiles() const { return mLoaded != nullptr; }
    const io::BufferSet* loadedFrame() const { return mLoaded.get(); }
    ~ViewPipeline();

    int width() const { return mWidth; }
    int height() const { return mHeight; }
    Device device() const { return mDevice; }
    const pt::Camera& camera() const { return mCamera; }
    const pt::Camera& sceneCamera() const { return mSceneCamera; }
    // World-space bounds of the scene (for the orbit pivot and movement speed).
    Vec3 sceneCenter() const { return mSceneCenter; }
    float sceneRadius() const { return mSceneRadius; }

    // Moves the camera: accumulation restarts; the sequence methods get motion vectors (or a reset).
    void setCamera(const pt::Camera& c);
    // Drops the accumulated frames (and the sequence methods' histories).
    void resetAccumulation();

    // Renders one frame, accumulates it and runs the slots' filters. Throws InputError only for
    // settings the renderer rejects; filter parameter errors land in SlotResult::error.
    void step(const PipelineSettings& s);

    // Whether the last step() filtered anything (always when rendering; a loaded frame's step only
    // when a slot's method, parameters or frame changed): its times() are then this step's.
    bool stepFiltered() const { return mStepFiltered; }
    int framesAccumulated() const { return mFrames; }
    int samplesPerPixel() const { return mFrames * mSppAccumulated; }
    const StageTimes& times() const { return mTimes; }

    enum Buffer { kColor, kVariance, kAlbedo, kNormal, kPosition, kDepth, kIds, kMotion, kEmission, kEmissionMean,
                  kBufferCount };
    // The buffers the filters saw in the last step (accumulated ones when accumulating), on the
    // host. On Device::Cuda they live on the GPU (deviceBuffer()) and these accessors download a
    // buffer the first time it is asked for after a step (buffer views, save, screenshot); nothing
    // is copied to the host otherwise. The references stay valid until the next step().
    const Image& color() const { return hostBuffer(kColor); }
    const Image& variance() const { return hostBuffer(kVariance); }
    bool varianceValid() const { return mVarianceValid; }  // false at 1 sample per pixel
    const Image& albedo() const { return hostBuffer(kAlbedo); }
    const Image& normal() const { return hostBuffer(kNormal); }
    const Image& position() const { return hostBuffer(kPosition); }
    const Image& depth() const { return hostBuffer(kDepth); }
    const Image& ids() const { return hostBuffer(kIds); }
    const Image& motion() const { return hostBuffer(kMotion); }  // x = dx, y = dy (previous - current), pixels
    const Image& emission() const { return hostBuffer(kEmission); }  // this frame's (the sequence methods' input)
    const Image& emissionMean() const { return hostBuffer(kEmissionMean); }  // running mean (EAW/SURE)
    // The same buffers where they live, on device() (no copy; for GPU consumers).
    const Image& deviceBuffer(Buffer b) const { return *buffer(b); }
    const SlotResult& slot(int i) const { return mSlots[i]; }
    // The slot's result on the host (downloaded once when it lives on the GPU); may be empty.
    const Image& resultHost(int i) const;
    // d_i = (EAW with i levels) - (EAW with i + 1 levels), remodulated by the albedo; empty
    // unless PipelineSettings::detailLevel asked for it.
    const Image& detail() const { return mDetail; }
    int detailLevel() const { return mDetailLevelShown; }
    // SURE's s_i(p), one channel per level; empty unless asked for and a slot runs SURE on the CPU.
    const Image& sureFractions() const { return mSureS; }

    // Writes every buffer (EXR, linear) into `dir` (created when missing); returns the file names.
    std::vector<std::string> saveBuffers(const std::string& dir) const;

  private:
    const Image* buffer(Buffer b) const;
    const Image& hostBuffer(Buffer b) const;
    // This frame's render: mFrame on the CPU, the CUDA renderer's device buffers on the GPU.
    const RenderBuffers& frame() const { return *mCur; }
    void renderFrame(const PipelineSettings& s, bool ownSamples);
    void accumulateFrame(bool accumulate);
    void computeMotion();
    void computeEmission();
    void runSlot(int i, Method m, const PipelineSettings& s);
    void computeDetail(const PipelineSettings& s);
    // The frame a sequence method takes: this frame's render with the pipeline's motion and
    // emission, or the loaded frame; a copy of its own when the method holds frames (own).
    SequenceInput renderedSequenceInput(bool own) const;
    SequenceInput loadedSequenceInput(bool own) const;
    Image noisyHost() const;  // the noisy colour on the host (a refused filter's stand-in)
    // From files: loadDisplayBuffers() fills the display copies from mLoaded; stepLoaded() is
    // step() for a loaded frame (each slot filtered again only when its key changed).
    void loadDisplayBuffers();
    void stepLoaded(const PipelineSettings& s);
    // The running means (colour, variance, features, emission) as the EAW/SURE slots filter them.
    Frame accumulatedInputs() const;
    DenoiseOptions denoiseOptions(Method m, const PipelineSettings& s) const;

    Scene mScene;
    int mWidth, mHeight;
    Device mDevice;
    uint32_t mSeed;
    pt::Camera mSceneCamera, mCamera, mPrevCamera;
    bool mCameraMoved = false;
    Vec3 mSceneCenter;
    float mSceneRadius = 1.0f;
    std::unique_ptr<BvhData> mBvh;      // CPU rendering
    std::unique_ptr<CudaBvhRenderer> mCudaRenderer;  // CUDA rendering: scene uploaded once
    bool mRendererMotion = false;  // this frame's motion and emission came from the renderer
    uint64_t mFrameIndex = 0;      // seeds: every frame draws fresh samples

    RenderBuffers mFrame;  // this frame's render on the CPU (unused on CUDA)
    const RenderBuffers* mCur = &mFrame;
    // Running-mean state on device() (render/accumulate.h): colour moments (Welford M2 and the
    // mean within-frame variance), the mean of the unnormalised normals, and hit counts with the
    // mean depth. The outputs below double as the running means.
    Image mMoments, mNormalMean, mCounts;
    int mFrames = 0, mSppAccumulated = 0;
    bool mAccumulating = false;

    // All on device(). mEmission: this frame's emission (SVGF's input); mEmissionMean: its running
    // mean (EAW/SURE).
    Image mColor, mVariance, mAlbedo, mNormal, mPosition, mDepth, mIds, mMotion, mEmission, mEmissionMean;
    // Host copies of the buffers above on Device::Cuda, made on demand (hostBuffer()).
    mutable Image mHost[kBufferCount];
    mutable bool mHostValid[kBufferCount] = {};
    bool mEmissionValid = false;
    bool mVarianceValid = false;
    mutable SlotResult mSlots[2];  // mutable: resultHost() fills the host copy on demand
    // A slot's sequence method: its denoiser and what it was made with (a change makes a new one).
    struct SequenceSlot {
        std::unique_ptr<SequenceDenoiser> denoiser;
        const SequenceMethodInfo* method = nullptr;
        ParamSet params;
        DenoiseOptions still;
        bool onDevice = false;
    };
    SequenceSlot mSequence[2];
    SequenceDenoiser& sequenceDenoiser(int i, const SequenceMethodInfo& m, const PipelineSettings& s, bool onDevice);
    void runSequence(int i, const SequenceMethodInfo& m, const PipelineSettings& s, SlotResult& r);
    bool mHistoryResetPending = false;
    // From files: the loaded frame, its generation (one per setFrame) and the one it follows (0:
    // none); per slot, what its result was made from and the frame last pushed to its sequence
    // method.
    std::unique_ptr<io::BufferSet> mLoaded;
    uint64_t mGeneration = 0, mFollows = 0;
    struct SlotKey {
        bool valid = false;
        Method method;
        DenoiseOptions still;
        ParamSet sequence;
        uint64_t generation = 0;
        bool sureFractions = false, onDevice = false;
        int detailLevel = -1;
    };
    SlotKey mKey[2], mDetailKey;
    uint64_t mPushed[2] = {0, 0};
    static bool sameKey(const SlotKey& a, const SlotKey& b);
    Image mDetail, mSureS;
    int mDetailLevelShown = -1;
    StageTimes mTimes;
    bool mStepFiltered = false;
};

// A pinhole camera that orbits a pivot: yaw about world +y, pitch about the camera's right axis.
struct OrbitCamera {
    Vec3 target;
    float distance = 1.0f;
    float yaw = 0.0f, pitch = 0.0f;  // radians
    float tanHalfFov = 0.4f;

    // Starts from `c`, orbiting the point `pivotDistance` in front of it.
    static OrbitCamera fromCamera(const pt::Camera& c, float pivotDistance);
    pt::Camera camera() const;
    void orbit(float dYaw, float dPitch);
    // Moves target and eye together along the camera's right/up/forward axes (world units).
    void pan(const pt::Camera& c, float right, float up, float forward);
    void zoom(float factor);  // distance *= factor
};

}  // namespace atrous::view

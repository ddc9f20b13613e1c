// The viewer's pipeline on a frame read from files (view_pipeline.h: `atrous view --in`,
// `--sequence`): no renderer, no accumulation; each slot is filtered again only when what makes
// its result changed.
#include <algorithm>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <utility>

#include "atrous/error.h"
#include "atrous/params.h"
#include "atrous/timer.h"
#include "atrous/view_pipeline.h"
#include "render/bvh_render.h"  // the members ~ViewPipeline destroys
#include "render/bvh_tracer.h"

namespace atrous::view {

ViewPipeline::ViewPipeline(io::BufferSet frame, Device device) : mWidth(0), mHeight(0), mDevice(device), mSeed(0) {
    const Image& c = frame.image[int(io::Buffer::Color)];
    if (c.empty()) throw InputError("view: the frame has no colour buffer");
    mWidth = c.width();
    mHeight = c.height();
    mLoaded = std::make_unique<io::BufferSet>(std::move(frame));
    mGeneration = 1;
    // The display copies live on the host: the buffer views read them there, the filters read the
    // loaded buffers (and upload them themselves on CUDA).
    for (Image* img : {&mColor, &mVariance, &mAlbedo, &mNormal, &mPosition, &mDepth, &mIds, &mMotion, &mEmission,
                       &mEmissionMean})
        *img = Image(mWidth, mHeight, 3, Device::Cpu);
    loadDisplayBuffers();
}

void ViewPipeline::setFrame(io::BufferSet frame, bool follows) {
    if (!mLoaded) throw InputError("view: setFrame on a pipeline that renders");
    const Image& c = frame.image[int(io::Buffer::Color)];
    if (c.empty() || c.width() != mWidth || c.height() != mHeight)
        throw InputError(frame.from[int(io::Buffer::Color)] + ": the colour is " +
                         (c.empty() ? std::string("missing") : std::to_string(c.width()) + "x" + std::to_string(c.height())) +
                         ", the other frames " + std::to_string(mWidth) + "x" + std::to_string(mHeight));
    *mLoaded = std::move(frame);
    mFollows = follows ? mGeneration : 0;
    ++mGeneration;
    loadDisplayBuffers();
}

void ViewPipeline::loadDisplayBuffers() {
    const std::pair<io::Buffer, Image*> views[] = {
        {io::Buffer::Color, &mColor},   {io::Buffer::Variance, &mVariance}, {io::Buffer::Albedo, &mAlbedo},
        {io::Buffer::Normal, &mNormal}, {io::Buffer::Position, &mPosition}, {io::Buffer::Depth, &mDepth},
        {io::Buffer::ObjectId, &mIds},  {io::Buffer::Motion, &mMotion},      {io::Buffer::Emission, &mEmission}};
    for (const auto& [b, to] : views) {
        to->fill(0.0f);
        const Image& from = mLoaded->image[int(b)];
        for (int c = 0; c < std::min(3, from.empty() ? 0 : from.channels()); ++c)
            std::memcpy(to->data() + size_t(c) * to->plane(), from.data() + size_t(c) * from.plane(), from.plane() * sizeof(float));
    }
    mEmissionMean.copyFrom(mEmission);
    mVarianceValid = mLoaded->get(io::Buffer::Variance) != nullptr;
    mEmissionValid = mLoaded->get(io::Buffer::Emission) != nullptr;
    mFrames = 1;
    mSppAccumulated = 0;
    for (bool& v : mHostValid) v = false;
}

SequenceInput ViewPipeline::loadedSequenceInput(bool own) const {
    SequenceInput in;
    if (!own) {
        in.buffers = io::refsOf(*mLoaded);
        return in;
    }
    auto copy = std::make_shared<io::BufferSet>();
    for (int b = 0; b < io::kBufferCount; ++b)
        if (!mLoaded->image[b].empty()) copy->image[b] = mLoaded->image[b].clone();
    in.buffers = io::refsOf(*copy);
    in.owner = copy;
    return in;
}

bool ViewPipeline::sameKey(const SlotKey& a, const SlotKey& b) {
    return a.valid && b.valid && a.method == b.method && a.generation == b.generation &&
           a.sureFractions == b.sureFractions && a.onDevice == b.onDevice && a.detailLevel == b.detailLevel &&
           a.still.method == b.still.method && a.still.device == b.still.device &&
           sameParams(a.still, b.still, denoiseParams()) && a.sequence.same(b.sequence);
}

void ViewPipeline::stepLoaded(const PipelineSettings& settings) {
    PipelineSettings s = settings;
    s.deviceResults = false;  // the display of a loaded frame is the host path
    StageTimes times;
    bool changed = false;
    StageLap lap;
    // What makes slot m's result: the method, the parameters it reads, the frame.
    auto keyOf = [&](Method m) {
        SlotKey k;
        k.valid = true;
        k.method = m;
        k.generation = mGeneration;
        if (m.kind == Method::Kind::Still) k.still = denoiseOptions(m, s);
        if (m.kind == Method::Kind::Sequence) {
            k.sequence = sequenceParams(s, *m.sequence);
            if (m.sequence->stillMethod) k.still = denoiseOptions(Method::of(DenoiseMethod::Auto), s);
        }
        k.sureFractions = m == Method::of(DenoiseMethod::Sure) && s.sureFractions;
        return k;
    };
    if (!s.sureFractions) mSureS = Image();
    for (int i = 0; i < 2; ++i) {
        double& wall = i ? times.denoiseB : times.denoiseA;
        double& cpu = i ? times.denoiseBCpu : times.denoiseACpu;
        if (i == 1 && !s.split) {
            mSlots[1] = SlotResult{};
            mKey[1] = SlotKey{};
        } else {
            const Method m = i ? s.methodB : s.methodA;
            SlotKey k = keyOf(m);
            if (!sameKey(k, mKey[i])) {
                runSlot(i, m, s);
                mKey[i] = std::move(k);
                changed = true;
            }
        }
        lap(wall, cpu);
    }
    SlotKey d;
    d.valid = true;
    d.generation = mGeneration;
    d.detailLevel = s.detailLevel;
    d.still = denoiseOptions(Method::of(DenoiseMethod::Eaw), s);
    if (!sameKey(d, mDetailKey)) {
        computeDetail(s);
        mDetailKey = std::move(d);
        changed = true;
    }
    lap(times.debug, times.debugCpu);
    if (changed) mTimes = times;  // the panel keeps the times of the last filtering
    mStepFiltered = changed;
    mCameraMoved = false;
    mHistoryResetPending = false;
}

}  // namespace atrous::view

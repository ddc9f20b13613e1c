// SVGF's row in the registry of sequence methods (include/atrous/sequence_methods.h): one
// SvgfDenoiser per stream, each frame denoised as it comes with the history of the ones before.
#include <string>
#include <utility>

#include "atrous/params.h"
#include "atrous/svgf.h"
#include "filters/sequence_rows.h"

namespace atrous::filters {

namespace {

// Variance and position: for the safety net's still filter (SVGF itself does not read them).
constexpr BufferMask kReads{Buffer::Color,  Buffer::Variance, Buffer::Albedo,   Buffer::Normal, Buffer::Position,
                            Buffer::Depth,  Buffer::ObjectId, Buffer::Emission, Buffer::Motion};

class SvgfStream final : public SequenceDenoiser {
public:
    SvgfStream(const SequenceSetup& s, const SvgfParams& p)
        : SequenceDenoiser(0, 0, kReads), mSvgf(p, s.device, s.still.weights),
          mOnDevice(s.keepOnDevice && s.device == Device::Cuda), mTiming(s.timing) {
        mSvgf.setTiming(s.timing);
    }

private:
    SequenceOutput denoise(const std::vector<Frame>& window, size_t center, const std::vector<long long>&) override {
        SequenceOutput out;
        // On the device the result is the denoiser's own buffer, valid until the next frame: a copy.
        out.image = mOnDevice ? mSvgf.denoiseFrameOnDevice(window[center]).clone() : mSvgf.denoiseFrame(window[center]);
        out.methodUsed = kSvgfMethod;
        if (mSvgf.params().learnedSpatial) out.detail = " (learned spatial)";
        if (mTiming) out.stages = mSvgf.lastReport().stages;
        return out;
    }
    void restart() override { mSvgf.reset(); }

    SvgfDenoiser mSvgf;
    bool mOnDevice, mTiming;
};

}  // namespace

SequenceMethodInfo svgfMethodRow() {
    SequenceMethodInfo m;
    m.name = kSvgfMethod;
    m.label = "SVGF";
    m.summary = "spatiotemporal variance-guided filtering, causal: each frame from the ones before it (docs/svgf.md)";
    m.causal = true;
    m.causalMode = false;
    m.history = true;
    m.stillMethod = false;
    m.params = ParamSet(svgfParams());
    m.weightsParam = "learned_spatial";
    m.reads = kReads;
    m.acrossFrames = "SVGF carries its history from one frame to the next";
    m.withoutMotion = "SVGF assumes nothing moves on screen";
    m.make = [](const SequenceSetup& s) { return std::make_unique<SvgfStream>(s, *s.params.get<SvgfParams>()); };
    return m;
}

}  // namespace atrous::filters

// The temporal method's row in the registry of sequence methods (include/atrous/sequence_methods.h):
// a window of frames t - r .. t + r (t - r .. t in its causal mode) through denoiseTemporal
// (include/atrous/temporal.h), each frame prepared once (TemporalCache), then the still method of
// the caller's choice on the average.
#include <cstdio>
#include <string>
#include <utility>

#include "atrous/error.h"
#include "atrous/params.h"
#include "atrous/temporal.h"
#include "filters/sequence_rows.h"

namespace atrous::filters {

namespace {

// What it reads: every buffer (positions, variance, depth and ids for its still method).
constexpr BufferMask kReads{Buffer::Color,  Buffer::Variance, Buffer::Albedo,   Buffer::Normal, Buffer::Position,
                            Buffer::Depth,  Buffer::ObjectId, Buffer::Emission, Buffer::Motion};

// The parameters as they run: causal when asked for, and no static window without the renderer's
// own motion vectors (motion fitted or estimated sees a moving object as still).
TemporalParams runParams(const SequenceSetup& s) {
    TemporalParams p = *s.params.get<TemporalParams>();
    p.causal = p.causal || s.causal;
    if (!s.motionGiven) p.staticRadius = 0;
    validateTemporalParams(p);
    return p;
}

class TemporalStream final : public SequenceDenoiser {
public:
    TemporalStream(const TemporalParams& p, const DenoiseOptions& still)
        : SequenceDenoiser(temporalWindowRadius(p), p.causal ? 0 : temporalWindowRadius(p),
                           temporalWindowRadius(p) > 0 ? kReads : kReads.without(Buffer::Motion)),
          mParams(p), mStill(still) {
        validateDenoiseOptions(mStill);
    }

private:
    // Each frame as it arrives, so that a bad value is named by its own frame (the window's checks
    // would name the frame being denoised).
    void check(const Frame& frame) override {
        if (frame.color && frame.color->device() != Device::Cpu)
            throw InputError("temporal: the frames must be host images (its gather has no CUDA path)");
        checkTemporalFrame(frame);
    }
    SequenceOutput denoise(const std::vector<Frame>& window, size_t center, const std::vector<long long>& ids) override {
        TemporalResult r = denoiseTemporalWithReport(window, center, mParams, mStill, &mCache, &ids);
        SequenceOutput out;
        out.image = std::move(r.image);
        out.methodUsed = denoiseMethodName(r.report.spatial.methodUsed);
        out.stages = std::move(r.report.spatial.stages);
        out.detail = detail(r.report, out.methodUsed);
        return out;
    }
    void restart() override { mCache = TemporalCache(); }
    // The report line's words: " (+-3 frames (+-6 where nothing moves), 3.8 averaged per pixel in 6
    // ms; then auto -> blend)".
    std::string detail(const TemporalReport& r, const std::string& used) const {
        const int radius = lookbehind();
        const bool resolved = mStill.method == DenoiseMethod::Auto;
        char wider[64] = "", text[512];
        if (radius > mParams.radius) std::snprintf(wider, sizeof wider, " (+-%d where nothing moves)", radius);
        std::snprintf(text, sizeof text, " (%s%d frames%s, %.1f averaged per pixel in %.0f ms; then %s%s%s)",
                      mParams.causal ? "causal, -" : "+-", mParams.radius, wider, r.meanFrames, r.gatherMs,
                      denoiseMethodName(mStill.method), resolved ? " -> " : "", resolved ? used.c_str() : "");
        return text;
    }

    TemporalParams mParams;
    DenoiseOptions mStill;
    TemporalCache mCache;  // each frame prepared once for all the windows it is in
};

}  // namespace

SequenceMethodInfo temporalMethodRow() {
    SequenceMethodInfo m;
    m.name = kTemporalMethod;
    m.label = "Temporal";
    m.summary = "the default with --sequence: frames t-3..t+3 (t-6..t+6 where nothing moves) reprojected onto t and "
                "averaged, then the still method --spatial (docs/temporal.md)";
    m.causal = false;
    m.causalMode = true;
    m.history = false;
    m.stillMethod = true;
    m.params = ParamSet(temporalParams());
    m.reads = kReads;
    m.acrossFrames = "the temporal method averages neighbouring frames";
    m.withoutMotion =
        "the temporal method takes them as still and leaves out what the depth, normal and colour tests find moved";
    m.make = [](const SequenceSetup& s) { return std::make_unique<TemporalStream>(runParams(s), s.still); };
    return m;
}

}  // namespace atrous::filters

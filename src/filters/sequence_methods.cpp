// The registry of sequence methods (include/atrous/sequence_methods.h): its built-in rows
// (temporal, svgf: src/filters/sequence_rows.h), the rows registerSequenceMethod adds, the stream
// that every method's denoiser shares (SequenceDenoiser: the window, the order, skipping, the
// buffers left out), and a still method run frame by frame through the same interface.
#include "atrous/sequence_methods.h"

#include <cctype>
#include <utility>

#include "atrous/error.h"
#include "filters/sequence_rows.h"

namespace atrous {

// ---- the stream --------------------------------------------------------------------------------

SequenceDenoiser::SequenceDenoiser(int lookbehind, int lookahead, BufferMask reads)
    : mLookbehind(lookbehind < 0 ? 0 : lookbehind), mLookahead(lookahead < 0 ? 0 : lookahead), mReads(reads) {}

SequenceDenoiser::~SequenceDenoiser() = default;

void SequenceDenoiser::check(const Frame&) {}

void SequenceDenoiser::restart() {}

Frame SequenceDenoiser::visible(const Frame& f) const {
    Frame v = f;
    for (int b = 0; b < kBufferCount; ++b)
        if (mIgnored.has(Buffer(b))) v.set(Buffer(b), nullptr);
    return v;
}

void SequenceDenoiser::push(SequenceInput frame) {
    if (mFinished) throw InputError("sequence denoiser: a frame pushed after finish() (reset() starts a new stream)");
    check(visible(frame.buffers));
    mHeld.push_back({(long long)mPushed, std::move(frame)});
    ++mPushed;
}

bool SequenceDenoiser::ready() const {
    return mNext < mPushed && (mFinished || mNext + size_t(mLookahead) < mPushed);
}

void SequenceDenoiser::release() {
    while (!mHeld.empty() && mHeld.front().index + mLookbehind < (long long)mNext) mHeld.pop_front();
}

SequenceOutput SequenceDenoiser::next() {
    if (!ready()) throw InputError("sequence denoiser: no frame is ready (push more, or finish())");
    const long long t = (long long)mNext;
    std::vector<Frame> window;
    std::vector<long long> ids;
    size_t center = 0;
    for (const Held& h : mHeld) {
        if (h.index < t - mLookbehind || h.index > t + mLookahead) continue;
        if (h.index == t) center = window.size();
        window.push_back(visible(h.input.buffers));
        ids.push_back(h.index);
    }
    SequenceOutput out = denoise(window, center, ids);
    out.index = mNext++;
    release();
    return out;
}

void SequenceDenoiser::skip() {
    if (!ready()) throw InputError("sequence denoiser: no frame is ready to skip");
    ++mNext;
    release();
}

void SequenceDenoiser::finish() { mFinished = true; }

void SequenceDenoiser::reset() {
    mHeld.clear();
    mPushed = mNext = 0;
    mFinished = false;
    mIgnored = {};
    restart();
}

void SequenceDenoiser::ignore(Buffer b) { mIgnored = mIgnored.with(b); }

// ---- a still method, frame by frame ------------------------------------------------------------

namespace {

class StillStream final : public SequenceDenoiser {
public:
    explicit StillStream(const DenoiseOptions& o) : SequenceDenoiser(0, 0, readsOf(o)), mOptions(o) {
        validateDenoiseOptions(mOptions);
    }

private:
    static BufferMask readsOf(const DenoiseOptions&) {
        return BufferMask::all().without(Buffer::Motion).without(Buffer::MaterialId);
    }
    SequenceOutput denoise(const std::vector<Frame>& window, size_t center, const std::vector<long long>&) override {
        DenoiseResult r = denoiseWithReport(window[center], mOptions);
        SequenceOutput out;
        out.image = std::move(r.image);
        out.methodUsed = denoiseMethodName(r.report.methodUsed);
        if (mOptions.method == DenoiseMethod::Auto) out.detail = " -> " + out.methodUsed;
        out.stages = std::move(r.report.stages);
        return out;
    }
    DenoiseOptions mOptions;
};

// ---- the registry ------------------------------------------------------------------------------

struct SequenceRegistry {
    std::deque<SequenceMethodInfo> rows = {filters::temporalMethodRow(), filters::svgfMethodRow()};
    std::deque<std::string> strings;  // the registered rows' text
    const char* keep(const char* s) {
        if (!s) return nullptr;
        strings.emplace_back(s);
        return strings.back().c_str();
    }
};

SequenceRegistry& registry() {
    static SequenceRegistry r;
    return r;
}

}  // namespace

const std::deque<SequenceMethodInfo>& sequenceMethods() { return registry().rows; }

const SequenceMethodInfo* findSequenceMethod(const std::string& name) {
    for (const SequenceMethodInfo& m : sequenceMethods())
        if (name == m.name) return &m;
    return nullptr;
}

std::string sequenceMethodNames() {
    std::string s;
    for (const SequenceMethodInfo& m : sequenceMethods()) s += (s.empty() ? "" : ", ") + std::string(m.name);
    return s;
}

const SequenceMethodInfo& registerSequenceMethod(SequenceMethodInfo info) {
    const std::string name = info.name ? info.name : "";
    bool ok = !name.empty() && name.size() <= 64;
    for (char ch : name) ok = ok && (std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-');
    if (!ok) throw InputError("registerSequenceMethod: '" + name + "' is not a method name (letters, digits, '_', '-')");
    if (findSequenceMethod(name)) throw InputError("registerSequenceMethod: there is already a sequence method '" + name + "'");
    // The still methods' names (registerDenoiseMethod refuses ours in turn), and the front-ends'
    // own words for no filter and for OIDN.
    if (findDenoiseMethod(name) || name == "none" || name == "noisy" || name == "oidn")
        throw InputError("registerSequenceMethod: '" + name +
                         "' is a name the front-ends use (a still method, none, noisy or oidn)");
    if (!info.make) throw InputError("registerSequenceMethod: method '" + name + "' has no factory (make)");
    if (info.weightsParam) {
        const int row = info.params.find(info.weightsParam);
        if (row < 0 || info.params.rows()[size_t(row)].kind != ParamKind::Bool)
            throw InputError("registerSequenceMethod: method '" + name + "': weightsParam '" + info.weightsParam +
                             "' is not a switch of its parameters");
    }
    SequenceRegistry& r = registry();
    info.name = r.keep(name.c_str());
    info.label = r.keep(info.label ? info.label : info.name);
    info.summary = r.keep(info.summary ? info.summary : "");
    info.weightsParam = r.keep(info.weightsParam);
    info.acrossFrames = r.keep(info.acrossFrames ? info.acrossFrames : "it denoises each frame with others");
    info.withoutMotion = r.keep(info.withoutMotion ? info.withoutMotion : "it takes them as still");
    info.reads = info.reads.with(Buffer::Color);
    info.registered = true;
    r.rows.push_back(std::move(info));
    return r.rows.back();
}

std::unique_ptr<SequenceDenoiser> makeSequenceDenoiser(const std::string& name, const SequenceSetup& setup) {
    if (const SequenceMethodInfo* m = findSequenceMethod(name)) {
        SequenceSetup s = setup;
        if (s.params.empty()) s.params = m->params;
        if (std::string(s.params.set()) != m->params.set())
            throw InputError("sequence method '" + name + "': its parameters are the table '" + m->params.set() +
                             "', not '" + s.params.set() + "'");
        s.params.validate();
        s.still.device = s.device;
        return m->make(s);
    }
    if (const DenoiseMethodInfo* still = findDenoiseMethod(name)) {
        DenoiseOptions o = setup.still;
        o.method = still->method;
        o.device = setup.device;
        return std::make_unique<StillStream>(o);
    }
    throw InputError("unknown denoise method '" + name + "' (expected " + sequenceMethodNames() + ", " +
                     denoiseMethodNames() + ")");
}

bool sequenceMethodReadsWeights(const SequenceMethodInfo& method, const ParamSet& params) {
    if (!method.weightsParam) return false;
    const int row = params.find(method.weightsParam);
    if (row < 0) return false;
    const ParamRef r = params.at(size_t(row));
    bool* const* on = std::get_if<bool*>(&r);
    return on && **on;
}

}  // namespace atrous

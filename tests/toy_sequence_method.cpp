// The toy sequence method, "toyseq": the whole of what a new sequence method is, one registry row
// (registerSequenceMethod) with a parameter table and a stateful denoiser, from the installed
// headers alone. Each frame is an exponential moving average of the colours where the motion
// vectors say the pixel has not moved (less than 0.05 px both ways), the frame's own colour
// elsewhere and on the first frame. Linked into a program it is registered when the program
// starts; in the plugin (ATROUS_TOY_PLUGIN) by atrous_plugin_register (tests/toy_plugin.cpp).
#include <cmath>
#include <iterator>
#include <memory>

#include "atrous/error.h"
#include "atrous/param_set.h"
#include "atrous/params.h"
#include "atrous/sequence_methods.h"

namespace atrous::toy {

namespace {

struct ToySequenceParams {
    float alpha = 0.3f;  // the new frame's weight in the average
};

const ParamField<ToySequenceParams> kToySequenceFields[] = {
    {"alpha", &params_detail::at<&ToySequenceParams::alpha>, paramAbove(0, 1),
     "weight of the new frame in the running average (1 = each frame alone)"},
};

const ParamTable<ToySequenceParams>& toySequenceParams() {
    static const ParamTable<ToySequenceParams> t{"toyseq", "toyseq-", kToySequenceFields, std::size(kToySequenceFields)};
    return t;
}

class ToySequence final : public SequenceDenoiser {
public:
    explicit ToySequence(float alpha) : SequenceDenoiser(0, 0, {Buffer::Color, Buffer::Motion}), mAlpha(alpha) {}

private:
    void check(const Frame& f) override {
        if (!f.color || f.color->empty()) throw InputError("toyseq frame: the color buffer is missing");
        if (f.color->device() != Device::Cpu) throw InputError("toyseq frame: the buffers must be host images");
        if (f.motion && (!f.motion->view().sameSize(f.color->view()) || f.motion->channels() < 2))
            throw InputError("toyseq frame: the motion buffer differs in size from the colour or has fewer than 2 channels");
    }
    SequenceOutput denoise(const std::vector<Frame>& window, size_t center, const std::vector<long long>&) override {
        const Frame& f = window[center];
        const Image& c = *f.color;
        const bool history = mHistory.width() == c.width() && mHistory.height() == c.height();
        Image out(c.width(), c.height(), 3);
        for (int y = 0; y < c.height(); ++y)
            for (int x = 0; x < c.width(); ++x) {
                const float mx = f.motion ? (*f.motion)(x, y, 0) : 0.0f, my = f.motion ? (*f.motion)(x, y, 1) : 0.0f;
                const bool still = history && std::fabs(mx) < 0.05f && std::fabs(my) < 0.05f;  // NaN: moved
                for (int ch = 0; ch < 3; ++ch) {
                    float v = c(x, y, ch < c.channels() ? ch : 0);
                    v = std::isfinite(v) ? v : 0.0f;
                    out(x, y, ch) = still ? mAlpha * v + (1.0f - mAlpha) * mHistory(x, y, ch) : v;
                }
            }
        mHistory = out.clone();
        SequenceOutput o;
        o.image = std::move(out);
        o.methodUsed = "toyseq";
        return o;
    }
    void restart() override { mHistory = Image(); }

    float mAlpha;
    Image mHistory;  // the last output
};

}  // namespace

void registerToySequence() {
    SequenceMethodInfo m;
    m.name = "toyseq";
    m.label = "Toy sequence";
    m.summary = "a toy: a running average of the colour where the motion says nothing moved (tests/toy_sequence_method.cpp)";
    m.causal = true;
    m.history = true;
    m.params = ParamSet(toySequenceParams());
    m.reads = {Buffer::Color, Buffer::Motion};
    m.acrossFrames = "the toy carries its average from one frame to the next";
    m.withoutMotion = "the toy takes every pixel as still";
    m.make = [](const SequenceSetup& s) { return std::make_unique<ToySequence>(s.params.get<ToySequenceParams>()->alpha); };
    registerSequenceMethod(m);
}

// Linked into a program (atrous_toy, toy_method_test) it is registered when the program starts.
#if !defined(ATROUS_TOY_PLUGIN)
static const bool kToySequenceRegistered = (registerToySequence(), true);
#endif

}  // namespace atrous::toy

// The sequence methods for Python (include/atrous/sequence_methods.h): their registry's rows and
// tables, a stream of frames through any of them (atrous.SequenceDenoiser, which atrous.Svgf is),
// one frame of a window (atrous.denoise_temporal's), and the session from files to files
// (atrous.denoise_sequence). No method is named here: every one is a row.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "arrays.h"
#include "atrous/error.h"
#include "atrous/sequence.h"
#include "atrous/sequence_methods.h"
#include "atrous/temporal.h"
#include "frame.h"
#include "params.h"
#include "words.h"

namespace nb = nanobind;

namespace atrous::python {

LearnedWeights weightsFrom(nb::handle h);  // vocabulary.cpp: None, "", a path or a Weights

std::shared_ptr<FrameArrays> frameArrays(const nb::handle& frame, const std::string& at) {
    using B = io::Buffer;
    static const std::pair<const char*, B> kKeys[] = {
        {"albedo", B::Albedo}, {"normal", B::Normal}, {"position", B::Position}, {"depth", B::Depth},
        {"variance", B::Variance}, {"ids", B::ObjectId}, {"emission", B::Emission}, {"motion", B::Motion}};
    if (!nb::isinstance<nb::dict>(frame)) throw InputError(at + "must be a dict of arrays");
    nb::dict d = nb::cast<nb::dict>(frame);
    for (auto [k, v] : d) {
        const std::string key = nb::cast<std::string>(k);
        bool known = key == "color" || key == "time";  // atrous.render_sequence's items carry their time
        for (const auto& [name, b] : kKeys) known = known || key == name;
        if (!known) throw InputError(at + "unknown buffer '" + key + "'");
    }
    if (!d.contains("color")) throw InputError(at + "has no color");
    auto f = std::make_shared<FrameArrays>(toImage(d["color"], "color"));
    for (const auto& [name, b] : kKeys)
        if (d.contains(name)) f->buffers.add({d[name], b, name});
    return f;
}

namespace {

const SequenceMethodInfo& rowNamed(const std::string& name) {
    if (const SequenceMethodInfo* m = findSequenceMethod(name)) return *m;
    throw InputError("unknown sequence method '" + name + "' (expected " + sequenceMethodNames() + ")");
}

// The registry for Python (atrous.sequence_methods(), atrous.SEQUENCE_METHODS): one dict per row.
nb::list sequenceMethodRows() {
    nb::list rows;
    for (const SequenceMethodInfo& m : sequenceMethods()) {
        nb::list reads;
        for (int b = 0; b < kBufferCount; ++b)
            if (m.reads.has(Buffer(b))) reads.append(bufferName(Buffer(b)));
        nb::dict d;
        d["name"] = m.name, d["label"] = m.label, d["summary"] = m.summary, d["params"] = m.params.set();
        d["causal"] = m.causal, d["causal_mode"] = m.causalMode, d["history"] = m.history;
        d["still_method"] = m.stillMethod, d["registered"] = m.registered, d["reads"] = reads;
        d["weights_param"] = m.weightsParam ? nb::cast(std::string(m.weightsParam)) : nb::none();
        rows.append(d);
    }
    return rows;
}

// A sequence method's parameters from its table's keywords (its defaults changed); none for a
// still method, which takes no such keywords.
ParamSet paramsOf(const std::string& method, nb::dict params) {
    const SequenceMethodInfo* row = findSequenceMethod(method);
    if (!row && !findDenoiseMethod(method))
        throw InputError("unknown method '" + method + "' (expected " + sequenceMethodNames() + ", " +
                         denoiseMethodNames() + ")");
    if (!row) {
        if (params.size() > 0) throw InputError("method '" + method + "' is a still method: it has no sequence parameters");
        return ParamSet();
    }
    ParamSet set = row->params;
    applyParams(set, params, row->label);
    return set;
}

// How a method is made from Python's keywords: `method` a sequence method (`params`: its table's
// values, paramsOf) or a still method; `spatial` the still method a sequence method ends with;
// `still` that still method's keywords; the weights loaded when a method of the run reads them.
SequenceSetup setupOf(const std::string& method, const std::string& device, const std::string& spatial,
                      nb::handle learnedWeights, const ParamSet& params, nb::dict still) {
    SequenceSetup s;
    s.device = parseDevice(device);
    s.params = params;
    const SequenceMethodInfo* row = findSequenceMethod(method);
    const std::string& stillName = row ? spatial : method;
    if (!stillName.empty()) s.still.method = parseDenoiseMethod(stillName);  // "": the library's default
    ParamSet stillSet = ParamSet::bind(denoiseParams(), s.still);
    applyParams(stillSet, still, "denoise");
    const bool stillWeights = readsWeights(denoiseMethodInfo(s.still.method));
    const bool weights = row ? (row->stillMethod && stillWeights) || sequenceMethodReadsWeights(*row, s.params) : stillWeights;
    if (weights) s.still.weights = weightsFrom(learnedWeights);
    return s;
}

// A stream of frames through a method (atrous.SequenceDenoiser): dicts of arrays pushed in order,
// denoised frames handed back in order, each on its colour's device.
class PySequenceDenoiser {
public:
    PySequenceDenoiser(const std::string& method, const std::string& device, const std::string& spatial,
                       nb::handle learnedWeights, nb::dict params, nb::dict still, bool causal, bool motionGiven) {
        SequenceSetup s = setupOf(method, device, spatial, learnedWeights, paramsOf(method, params), still);
        s.causal = causal;
        s.motionGiven = motionGiven;
        s.keepOnDevice = s.device == Device::Cuda;  // handed back where the frame's colour was
        mDevice = s.device;
        mMethod = method;
        mDenoiser = makeSequenceDenoiser(method, s);
    }
    void push(nb::handle frame) {
        std::shared_ptr<FrameArrays> f = frameArrays(frame, "frame: ");
        mDevices.push_back(f->color.device());
        try {
            mDenoiser->push({f->buffers.refs, f});
        } catch (...) {
            mDevices.pop_back();
            throw;
        }
    }
    nb::object next() {
        SequenceOutput out;
        {
            nb::gil_scoped_release release;
            out = mDenoiser->next();
        }
        mLastUsed = out.methodUsed, mLastDetail = out.detail;
        const Device want = mDevices.front();
        mDevices.pop_front();
        if (out.image.device() != want) out.image = out.image.to(want);
        return fromImage(std::move(out.image));
    }
    void skip() {
        mDenoiser->skip();
        mDevices.pop_front();
    }
    void reset() {
        mDenoiser->reset();
        mDevices.clear();
    }
    SequenceDenoiser& denoiser() { return *mDenoiser; }
    std::string device() const { return deviceToString(mDevice); }
    const std::string& method() const { return mMethod; }
    const std::string& lastUsed() const { return mLastUsed; }
    const std::string& lastDetail() const { return mLastDetail; }

private:
    std::unique_ptr<SequenceDenoiser> mDenoiser;
    std::deque<Device> mDevices;  // of the frames pushed and not handed back
    Device mDevice = Device::Cpu;
    std::string mMethod, mLastUsed, mLastDetail;
};

// frames[center] of a window of frames (dicts of host arrays) through a method without history
// (atrous.denoise_temporal): the frames its window reads pushed into a new stream, those before the
// centre skipped. Without motion in any frame, the motion comes from each frame's Position pass
// (a fitted camera) or its colours, for the frames the window reads (the first has no history), as
// `atrous denoise --sequence` does (StreamMotion).
nb::object pyDenoiseWindow(const std::string& method, nb::list frames, size_t center, const std::string& device,
                           const std::string& spatial, nb::handle learnedWeights, nb::dict params, nb::dict still) {
    const SequenceMethodInfo& row = rowNamed(method);
    if (row.history)
        throw InputError("method '" + method + "': " + row.acrossFrames + ": denoise its frames in order (SequenceDenoiser)");
    if (frames.size() == 0) throw InputError("frames must be a non-empty list of dicts");
    if (center >= frames.size()) throw InputError("center " + std::to_string(center) + " is outside the frames");
    std::vector<std::shared_ptr<FrameArrays>> fs;
    bool anyMotion = false;
    for (size_t i = 0; i < frames.size(); ++i) {
        fs.push_back(frameArrays(frames[i], "frame " + std::to_string(i) + ": "));
        if (fs.back()->color.device() != Device::Cpu)
            throw InputError("frame " + std::to_string(i) + ": the frames must be host (numpy) arrays");
        anyMotion = anyMotion || fs.back()->buffers.refs.motion != nullptr;
    }
    SequenceSetup s = setupOf(method, device, spatial, learnedWeights, paramsOf(method, params), still);
    s.motionGiven = anyMotion;
    std::unique_ptr<SequenceDenoiser> den = makeSequenceDenoiser(method, s);
    const size_t lo = center > size_t(den->lookbehind()) ? center - size_t(den->lookbehind()) : 0;
    const size_t hi = std::min(frames.size() - 1, center + size_t(den->lookahead()));
    Image out;
    {
        nb::gil_scoped_release release;
        StreamMotion motion;
        std::vector<Image> fitted(hi - lo + 1);
        for (size_t i = lo; i <= hi; ++i) {
            Frame f = fs[i]->buffers.refs;
            if (!anyMotion && frames.size() > 1 && den->reads().has(Buffer::Motion)) {
                const Frame prev = i > lo ? fs[i - 1]->buffers.refs : Frame();
                fitted[i - lo] = motion.next(f, i > lo ? &prev : nullptr);
                f.motion = &fitted[i - lo];
            }
            den->push({f, nullptr});  // fs and fitted outlive the stream
        }
        den->finish();
        for (size_t i = lo; i < center; ++i) den->skip();
        out = den->next().image;
    }
    return fromImage(std::move(out));
}

// A sequence from its files to files (include/atrous/sequence.h): the session `atrous denoise
// --sequence` runs. `tables`: {table name: keywords} of the sequence methods' tables (the chosen
// method's applies; every one is checked); on_frame (or None) is called with each frame's dict as
// it is done.
nb::dict pyDenoiseSequence(const std::string& input, const std::string& out, const std::string& method,
                           const std::string& spatial, const std::string& device, nb::handle learnedWeights,
                           const std::vector<std::string>& passes, const std::string& layer, const std::string& addPass,
                           int start, int end, int step, float exposure, bool pngs, bool preview, nb::dict tables,
                           nb::dict params, nb::object onFrame) {
    SequenceDenoiseOptions o;
    o.method = method.empty() ? sequenceMethods().front().name : method;
    const SequenceMethodInfo* row = findSequenceMethod(o.method);
    for (auto [k, v] : tables) {
        const std::string table = nb::cast<std::string>(k);
        bool known = false;
        for (const SequenceMethodInfo& m : sequenceMethods()) {
            if (m.params.empty() || table != m.params.set()) continue;
            ParamSet set = m.params;
            applyParams(set, nb::cast<nb::dict>(v), m.label);
            if (&m == row) o.params = set;
            known = true;
        }
        if (!known) throw InputError("'" + table + "' is not the parameter table of a sequence method");
    }
    // An unknown method is the session's InputError (it names the methods).
    if (findDenoiseMethod(o.method) || row)
        o.frame = setupOf(o.method, device, spatial, learnedWeights, o.params.empty() && row ? row->params : o.params, params).still;
    o.device = parseDevice(device);
    o.passes = passes, o.viewLayer = layer, o.addPass = addPass;
    o.start = start, o.end = end, o.step = step;
    o.exposure = exposure, o.pngs = pngs, o.preview = preview;
    auto frameDict = [](const SequenceFrameReport& f) {
        nb::dict d;
        d["index"] = f.index, d["input"] = f.input, d["output"] = f.output, d["method"] = f.method;
        d["method_used"] = f.methodUsed, d["ms"] = f.milliseconds;
        d["reprojected"] = f.reprojected < 0 ? nb::none() : nb::cast(f.reprojected);
        d["mse"] = f.hasReference ? nb::cast(f.mse) : nb::none();
        d["mse_input"] = f.hasReference ? nb::cast(f.mseInput) : nb::none();
        d["line"] = f.line;
        d["position"] = f.position, d["count"] = f.count;  // the k-th of the run's N frames (k/N counters)
        return d;
    };
    SequenceEvents events;
    if (!onFrame.is_none())
        events.frame = [&](const SequenceFrameReport& f) {
            nb::gil_scoped_acquire gil;
            onFrame(frameDict(f));
        };
    SequenceReport r;
    try {
        nb::gil_scoped_release release;
        r = denoiseSequence(input, out, o, events);
    } catch (const InputError& e) {
        // The session's messages name the CLI's flags: Python's keywords here (words.h).
        throw InputError(pythonWords(e.what(), {{"--sequence", "input"}, {"--out", "out"}, {"--method", "method"},
                                                {"--spatial", "spatial"}, {"--pass", "passes"}, {"--layer", "layer"},
                                                {"--add-pass", "add_pass"}, {"--start", "start"}, {"--end", "end"},
                                                {"--step", "step"}, {"--exposure", "exposure"}, {"--device", "device"},
                                                {"--learned-weights", "learned_weights"}}));
    }
    nb::dict d;
    nb::list frames;
    for (const SequenceFrameReport& f : r.frames) frames.append(frameDict(f));
    d["width"] = r.width, d["height"] = r.height, d["buffers"] = r.buffers, d["frames"] = frames;
    d["filter_ms_per_frame"] = r.filterMsPerFrame, d["wall_ms_per_frame"] = r.wallMsPerFrame;
    d["preview"] = r.preview.empty() ? nb::none() : nb::cast(r.preview);
    d["notes"] = r.notes;
    return d;
}

}  // namespace

void bindSequence(nb::module_& m) {
    m.def("sequence_methods", &sequenceMethodRows);
    m.def("sequence_params", [](const std::string& name) { return paramRows(rowNamed(name).params); });
    m.def("resolve_sequence_params", [](const std::string& name, nb::dict p) {
        const SequenceMethodInfo& row = rowNamed(name);
        ParamSet set = row.params;
        applyParams(set, p, row.params.set());
        return paramValues(set);
    });
    m.attr("SVGF_METHOD") = kSvgfMethod;
    m.attr("TEMPORAL_METHOD") = kTemporalMethod;
    nb::class_<PySequenceDenoiser>(m, "SequenceDenoiser")
        .def(nb::init<const std::string&, const std::string&, const std::string&, nb::handle, nb::dict, nb::dict, bool,
                      bool>(),
             nb::arg("method"), nb::arg("device"), nb::arg("spatial"), nb::arg("learned_weights").none(),
             nb::arg("params"), nb::arg("still"), nb::arg("causal"), nb::arg("motion_given"))
        .def("push", &PySequenceDenoiser::push, nb::arg("frame"))
        .def("next", &PySequenceDenoiser::next)
        .def("skip", &PySequenceDenoiser::skip)
        .def("finish", [](PySequenceDenoiser& d) { d.denoiser().finish(); })
        .def("reset", &PySequenceDenoiser::reset)
        .def_prop_ro("ready", [](PySequenceDenoiser& d) { return d.denoiser().ready(); })
        .def_prop_ro("lookahead", [](PySequenceDenoiser& d) { return d.denoiser().lookahead(); })
        .def_prop_ro("lookbehind", [](PySequenceDenoiser& d) { return d.denoiser().lookbehind(); })
        .def_prop_ro("pushed", [](PySequenceDenoiser& d) { return d.denoiser().pushed(); })
        .def_prop_ro("device", &PySequenceDenoiser::device)
        .def_prop_ro("method", &PySequenceDenoiser::method)
        .def_prop_ro("method_used", &PySequenceDenoiser::lastUsed)
        .def_prop_ro("detail", &PySequenceDenoiser::lastDetail);
    m.def("denoise_window", &pyDenoiseWindow, nb::arg("method"), nb::arg("frames"), nb::arg("center"), nb::arg("device"),
          nb::arg("spatial"), nb::arg("learned_weights").none(), nb::arg("params"), nb::arg("still"));
    m.def("denoise_sequence", &pyDenoiseSequence, nb::arg("input"), nb::arg("out"), nb::arg("method"), nb::arg("spatial"),
          nb::arg("device"), nb::arg("learned_weights").none(), nb::arg("passes"), nb::arg("layer"), nb::arg("add_pass"),
          nb::arg("start"), nb::arg("end"), nb::arg("step"), nb::arg("exposure"), nb::arg("pngs"), nb::arg("preview"),
          nb::arg("tables"), nb::arg("params"), nb::arg("on_frame").none());
}

}  // namespace atrous::python

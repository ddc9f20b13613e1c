// atrous._core: the nanobind layer under the Python package (python/atrous/__init__.py holds the
// documented API and the argument rules). Arrays cross as H x W x C float32 with any strides, on
// the host or (CUDA builds) on the GPU; results are returned as new C-contiguous arrays on the
// same device. Library errors arrive in Python as ValueError (InputError) or RuntimeError.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>
#include <nanobind/stl/unordered_map.h>

#include <cmath>
#include <initializer_list>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/device.h"
#include "atrous/error.h"
#include "atrous/interop.h"
#include "atrous/io.h"
#include "atrous/metrics.h"
#include "atrous/params.h"
#include "atrous/render.h"
#include "atrous/sequence.h"
#include "atrous/svgf.h"
#include "atrous/temporal.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/image_io.h"
#include "arrays.h"

namespace nb = nanobind;
using namespace atrous;

namespace atrous::python {
void bindMethods(nb::module_& m);  // methods.cpp: register_method
void bindMetrics(nb::module_& m);  // metrics.cpp: metrics, temporal_metrics
void bindFiles(nb::module_& m);    // files.cpp: read_image, read_buffers, write_image
void bindVocabulary(nb::module_& m);  // vocabulary.cpp: buffers, Weights, load_weights
LearnedWeights weightsFrom(nb::handle h);  // vocabulary.cpp: None, "", a path or a Weights
}

namespace {

using python::Array;
using python::fromImage;
using python::toImage;
using python::weightsFrom;

// The arrays of one denoise call as images, put into the library's one input assembly
// (io::BufferRefs, the Frame every denoiser takes), as the CLI and the viewer do.
struct Buffers {
    std::vector<std::unique_ptr<Image>> owned;
    const Image& color;
    io::BufferRefs refs;
    explicit Buffers(const Image& c) : color(c) { refs.set(io::Buffer::Color, &c); }
    // The binding's own copy of buffer b (toImage's), which denoise(DenoiseBuffers&) may filter in
    // its storage; null when b was not given.
    Image* ownedCopy(io::Buffer b) {
        for (auto& o : owned)
            if (o.get() == refs.get(b)) return o.get();
        return nullptr;
    }
    struct Arg {
        nb::handle obj;
        io::Buffer buffer;
        const char* what;  // the keyword
    };
    Buffers& add(std::initializer_list<Arg> args) {
        for (const Arg& a : args) add(a);
        return *this;
    }
    void add(const Arg& arg) {
        if (arg.obj.is_none()) return;
        Array a = nb::cast<Array>(arg.obj);
        // Motion vectors and ids of 2 or more channels keep them (dx, dy; object, material id); one
        // channel is repeated into 3, as for every other buffer.
        const bool ownCount = arg.buffer == io::Buffer::Motion || arg.buffer == io::Buffer::ObjectId;
        const int channels = ownCount && a.ndim() == 3 && a.shape(2) >= 2 ? int(a.shape(2)) : 3;
        owned.push_back(std::make_unique<Image>(toImage(a, arg.what, channels)));
        const Image& img = *owned.back();
        if (!img.view().sameSize(color.view()))
            throw InputError(std::string(arg.what) + ": size " + std::to_string(img.width()) + "x" +
                             std::to_string(img.height()) + " differs from the color's " + std::to_string(color.width()) +
                             "x" + std::to_string(color.height()));
        if (img.device() != color.device())
            throw InputError(std::string(arg.what) + ": lives on a different device than color");
        refs.set(arg.buffer, &img);
    }
};

template <class T>
T as(const nb::handle& v, const std::string& key) {
    try {
        return nb::cast<T>(v);
    } catch (const std::exception&) {
        throw InputError("parameter '" + key + "' has the wrong type");
    }
}

// A negated switch's CLI name as a keyword: --no-firefly -> no_firefly.
template <class S>
std::string pyAlias(const ParamTable<S>& t, const ParamField<S>& f) {
    std::string k = t.flag(f).substr(2);
    for (char& c : k)
        if (c == '-') c = '_';
    return k;
}

// A keyword of the table (params.h): its row's name, or for a negated switch the CLI's negative
// name too (no_firefly=True is firefly=False). The value is converted to the field's kind.
template <class S>
void applyParam(S& s, const ParamTable<S>& t, const std::string& k, const nb::handle& v, const char* what) {
    const ParamField<S>* f = t.find(k);
    bool negate = false;
    if (!f)
        for (const ParamField<S>& g : t)
            if (g.negated && k == pyAlias(t, g)) f = &g, negate = true;
    if (!f) throw InputError("unknown " + std::string(what) + " parameter '" + k + "'" + didYouMean(k, paramKeywords(t)));
    const ParamRef r = f->at(s);
    if (int* const* i = std::get_if<int*>(&r)) **i = as<int>(v, k);
    else if (uint32_t* const* u = std::get_if<uint32_t*>(&r)) {
        const long long x = as<long long>(v, k);  // range-checked here: a cast would wrap
        if (x < 0 || x > 4294967295LL) throw ParamError(t.set, f->name, f->range.rule(false), std::to_string(x));
        **u = uint32_t(x);
    } else if (float* const* x = std::get_if<float*>(&r)) **x = as<float>(v, k);
    else if (bool* const* b = std::get_if<bool*>(&r)) **b = as<bool>(v, k) != negate;
    else if (std::get_if<SureMode*>(&r)) setParamFromText(s, t, *f, as<std::string>(v, k));
    else *std::get<std::vector<float>*>(r) = as<std::vector<float>>(v, k);
}

// A field's value as a Python object (a choice as its name).
template <class S>
nb::object paramValue(const ParamField<S>& f, S& s) {
    const ParamRef r = f.at(s);
    if (int* const* i = std::get_if<int*>(&r)) return nb::cast(**i);
    if (uint32_t* const* u = std::get_if<uint32_t*>(&r)) return nb::cast(**u);
    if (float* const* x = std::get_if<float*>(&r)) return nb::cast(double(**x));
    if (bool* const* b = std::get_if<bool*>(&r)) return nb::cast(**b);
    if (std::get_if<SureMode*>(&r)) return nb::cast(paramText(r, f.choices));
    return nb::cast(*std::get<std::vector<float>*>(r));
}

// What a set of keywords makes of the struct: {name: value} for every row (atrous' tests).
template <class S>
nb::dict resolveParams(const ParamTable<S>& t, nb::dict params, const char* what) {
    S s{};
    for (auto [k, v] : params) applyParam(s, t, nb::cast<std::string>(k), v, what);
    nb::dict d;
    for (const ParamField<S>& f : t) d[f.name] = paramValue(f, s);
    return d;
}

// A method registry for Python (atrous.denoise_methods(), atrous.sequence_methods()): one dict per
// row, its name, summary and the registry's one flag under `flagName`.
template <class Rows, class Info>
nb::list methodRows(const Rows& infos, const char* flagName, bool Info::*flag) {
    nb::list rows;
    for (const Info& i : infos) {
        nb::dict d;
        d["name"] = i.name;
        d["summary"] = i.summary;
        d[flagName] = i.*flag;
        if constexpr (std::is_same_v<Info, DenoiseMethodInfo>) d["registered"] = i.registered(), d["params"] = "denoise";
        if constexpr (std::is_same_v<Info, SequenceMethodInfo>) {
            d["params"] = i.params;
            nb::list reads;
            for (Buffer b : i.reads) reads.append(bufferName(b));
            d["reads"] = reads;
        }
        rows.append(d);
    }
    return rows;
}

// The table for Python (atrous.denoise_params(), atrous.svgf_params()): one dict per row.
template <class S>
nb::list paramRows(const ParamTable<S>& t) {
    static const char* const kKinds[] = {"int", "float", "bool", "choice", "float_list", "uint"};
    S defaults{};
    nb::list rows;
    for (const ParamField<S>& f : t) {
        nb::dict d;
        d["name"] = f.name;
        d["kind"] = kKinds[int(f.kind())];
        d["default"] = paramValue(f, defaults);
        const bool numeric = f.kind() != ParamKind::Bool && f.kind() != ParamKind::Choice;
        d["min"] = numeric ? nb::cast(f.range.lo) : nb::none();
        d["max"] = numeric ? nb::cast(f.range.hi) : nb::none();
        d["min_open"] = numeric && f.range.loOpen;  // (min, max]
        d["zero"] = f.range.zero && numeric ? nb::cast(std::string(f.range.zero)) : nb::none();
        const bool isFloat = f.kind() == ParamKind::Float || f.kind() == ParamKind::FloatList;
        d["rule"] = numeric ? nb::cast(f.range.rule(isFloat)) : nb::none();
        nb::list choices;
        for (int i = 0; f.choices && f.choices[i]; ++i) choices.append(f.choices[i]);
        d["choices"] = choices;
        d["doc"] = f.doc;
        d["group"] = f.group;
        d["flag"] = t.flag(f);
        d["aliases"] = f.negated ? nb::cast(std::vector<std::string>{pyAlias(t, f)}) : nb::cast(std::vector<std::string>{});
        rows.append(d);
    }
    return rows;
}

nb::object pyDenoise(const Array& color, nb::handle albedo, nb::handle normal, nb::handle position, nb::handle depth,
                     nb::handle variance, nb::handle ids, nb::handle emission, const std::string& method,
                     nb::handle learnedWeights, nb::dict params) {
    using B = io::Buffer;
    Image c = toImage(color, "color");
    io::requireFinitePixel(c, "");  // host arrays; CUDA ones are not looked at here
    Buffers b(c);
    b.add({{albedo, B::Albedo, "albedo"}, {normal, B::Normal, "normal"}, {position, B::Position, "position"},
           {depth, B::Depth, "depth"}, {variance, B::Variance, "variance"}, {ids, B::ObjectId, "ids"},
           {emission, B::Emission, "emission"}});
    DenoiseOptions o;
    o.method = parseDenoiseMethod(method);
    if (denoiseMethodInfo(o.method).usesWeights) o.weights = weightsFrom(learnedWeights);  // auto's too
    o.device = c.device();
    for (auto [k, v] : params) applyParam(o, denoiseParams(), nb::cast<std::string>(k), v, "denoise");
    // The colour, variance and emission are the binding's own copies (toImage): handed over, the
    // filter works in their storage instead of copying them again (as the CLI does).
    DenoiseBuffers db = io::handOver(b.refs, c, b.ownedCopy(B::Variance), b.ownedCopy(B::Emission));
    Image out;
    {
        nb::gil_scoped_release release;
        out = denoise(db, o);
    }
    // denoise() ran on the colour's device and left its result there (o.device = c.device()).
    return fromImage(std::move(out));
}

// The learned filter's prepared planes (learnedPlanes): d, var, albedo, normal, depth
// (the last three only when given), mod and emission, on the host, for training.
nb::dict pyLearnedPlanes(const Array& color, nb::handle variance, nb::handle albedo, nb::handle normal,
                         nb::handle depth, nb::handle emission, nb::dict params) {
    using B = io::Buffer;
    Image c = toImage(color, "color");
    if (c.device() != Device::Cpu) throw InputError("learned_planes: color must be a host (numpy) array");
    Buffers b(c);
    b.add({{albedo, B::Albedo, "albedo"}, {normal, B::Normal, "normal"}, {depth, B::Depth, "depth"},
           {variance, B::Variance, "variance"}, {emission, B::Emission, "emission"}});
    const DenoiseInputs in = b.refs;
    DenoiseOptions o;
    for (auto [k, v] : params) applyParam(o, denoiseParams(), nb::cast<std::string>(k), v, "denoise");
    PreparedPlanes p;
    {
        nb::gil_scoped_release release;
        p = learnedPlanes(in, o);
    }
    nb::dict d;
    const std::pair<const char*, Image*> planes[] = {{"d", &p.d},           {"var", &p.var},   {"albedo", &p.albedo},
                                                     {"normal", &p.normal}, {"depth", &p.depth}, {"mod", &p.mod},
                                                     {"emission", &p.emission}};
    for (const auto& [name, img] : planes)
        if (!img->empty()) d[name] = fromImage(std::move(*img));
    return d;
}

class PySvgf {
public:
    PySvgf(const std::string& device, nb::handle learnedWeights, nb::dict params) {
        SvgfParams p;
        for (auto [k, v] : params) applyParam(p, svgfParams(), nb::cast<std::string>(k), v, "SVGF");
        const LearnedWeights w = p.learnedSpatial ? weightsFrom(learnedWeights) : LearnedWeights{};
        mDenoiser = std::make_unique<SvgfDenoiser>(p, parseDevice(device), w);
    }
    nb::object denoiseFrame(const Array& color, nb::handle albedo, nb::handle normal, nb::handle depth, nb::handle ids,
                            nb::handle motion, nb::handle emission, nb::handle position, nb::handle variance) {
        using B = io::Buffer;
        Image c = toImage(color, "color");
        Buffers b(c);
        b.add({{albedo, B::Albedo, "albedo"}, {normal, B::Normal, "normal"}, {depth, B::Depth, "depth"},
               {ids, B::ObjectId, "ids"}, {motion, B::Motion, "motion"}, {emission, B::Emission, "emission"},
               {position, B::Position, "position"}, {variance, B::Variance, "variance"}});
        const SvgfFrame f = b.refs;
        Image out;
        {
            nb::gil_scoped_release release;
            if (c.device() == mDenoiser->device() && c.device() == Device::Cuda)
                out = mDenoiser->denoiseFrameOnDevice(f).clone();
            else
                out = mDenoiser->denoiseFrame(f);
        }
        if (out.device() != c.device()) out = out.to(c.device());
        return fromImage(std::move(out));
    }
    void reset() { mDenoiser->reset(); }
    std::string device() const { return deviceToString(mDenoiser->device()); }

private:
    std::unique_ptr<SvgfDenoiser> mDenoiser;
};

// The offline sequence denoiser (include/atrous/temporal.h) on a window of frames, each a dict of
// host arrays (color required; albedo, normal, position, depth, variance, ids, emission, motion).
nb::object pyDenoiseTemporal(nb::list frames, size_t center, const std::string& method,
                             nb::handle learnedWeights, const std::string& device, nb::dict temporal,
                             nb::dict params) {
    using B = io::Buffer;
    static const std::pair<const char*, B> kKeys[] = {
        {"albedo", B::Albedo}, {"normal", B::Normal}, {"position", B::Position}, {"depth", B::Depth},
        {"variance", B::Variance}, {"ids", B::ObjectId}, {"emission", B::Emission}, {"motion", B::Motion}};
    std::vector<std::unique_ptr<Image>> colors;
    std::vector<std::unique_ptr<Buffers>> buffers;
    for (size_t i = 0; i < frames.size(); ++i) {
        const std::string at = "frame " + std::to_string(i) + ": ";
        if (!nb::isinstance<nb::dict>(frames[i])) throw InputError(at + "must be a dict of arrays");
        nb::dict d = nb::cast<nb::dict>(frames[i]);
        for (auto [k, v] : d) {
            const std::string key = nb::cast<std::string>(k);
            bool known = key == "color";
            for (const auto& [name, b] : kKeys) known = known || key == name;
            if (!known) throw InputError(at + "unknown buffer '" + key + "'");
        }
        if (!d.contains("color")) throw InputError(at + "has no color");
        colors.push_back(std::make_unique<Image>(toImage(nb::cast<Array>(d["color"]), "color")));
        if (colors.back()->device() != Device::Cpu) throw InputError(at + "denoise_temporal takes host (numpy) arrays");
        buffers.push_back(std::make_unique<Buffers>(*colors.back()));
        for (const auto& [name, b] : kKeys)
            if (d.contains(name)) buffers.back()->add({d[name], b, name});
    }
    TemporalParams tp;
    for (auto [k, v] : temporal) applyParam(tp, temporalParams(), nb::cast<std::string>(k), v, "temporal");
    // No motion in any frame but positions in all: motion from each frame's fitted camera, as
    // `atrous denoise --sequence` does (include/atrous/temporal.h, fitCamera).
    std::vector<Image> fitted;
    bool anyMotion = false, allPositions = true;
    for (const auto& b : buffers) {
        anyMotion = anyMotion || b->refs.get(B::Motion) != nullptr;
        allPositions = allPositions && b->refs.get(B::Position) != nullptr;
    }
    // The static window needs the renderer's own vectors: motion fitted to positions or estimated
    // from colours (below) sees a moving object as still (as the CLI).
    if (!anyMotion) tp.staticRadius = 0;
    if (!anyMotion && allPositions && buffers.size() > 1) {
        CameraFit previous;
        for (const auto& b : buffers) {
            const Image& pos = *b->refs.get(B::Position);
            const CameraFit fit = fitCamera(pos);
            fitted.push_back(motionFromPositions(pos, fit, previous));
            previous = fit;
        }
        for (size_t i = 0; i < buffers.size(); ++i) buffers[i]->refs.set(B::Motion, &fitted[i]);
    } else if (!anyMotion && buffers.size() > 1) {
        // Neither: motion from the colours themselves (estimateMotion), as the CLI does, for the
        // frames the window reads (centre ± radius) whose previous frame has their size; the
        // others, and the window's first frame (no previous one), get NaN: no history.
        const size_t n = buffers.size(), r = size_t(std::max(tp.radius, 0)), c = std::min(center, n - 1);
        const size_t lo = c > r ? c - r : 0, hi = tp.causal ? c : std::min(n - 1, c + r);
        for (size_t i = 0; i < n; ++i) {
            const bool read = i > lo && i <= hi && colors[i]->view().sameSize(colors[i - 1]->view());
            fitted.push_back(estimateMotion(*colors[i], read ? colors[i - 1].get() : nullptr));
        }
        for (size_t i = 0; i < n; ++i) buffers[i]->refs.set(B::Motion, &fitted[i]);
    }
    std::vector<SvgfFrame> window;
    for (const auto& b : buffers) window.push_back(b->refs);
    DenoiseOptions o;
    o.method = parseDenoiseMethod(method);
    if (denoiseMethodInfo(o.method).usesWeights) o.weights = weightsFrom(learnedWeights);  // auto's too
    o.device = parseDevice(device);
    for (auto [k, v] : params) applyParam(o, denoiseParams(), nb::cast<std::string>(k), v, "denoise");
    Image out;
    {
        nb::gil_scoped_release release;
        out = denoiseTemporal(window, center, tp, o);
    }
    return fromImage(std::move(out));
}

// A sequence from its files to files (include/atrous/sequence.h): the session `atrous denoise
// --sequence` runs. on_frame (or None) is called with each frame's dict as it is done.
nb::dict pyDenoiseSequence(const std::string& input, const std::string& out, const std::string& method,
                           const std::string& spatial, const std::string& device, nb::handle learnedWeights,
                           const std::vector<std::string>& passes, const std::string& layer, const std::string& addPass,
                           int start, int end, int step, float exposure, bool pngs, bool preview, nb::dict temporal,
                           nb::dict svgf, nb::dict params, nb::object onFrame) {
    SequenceDenoiseOptions o;
    o.method = method;
    o.device = parseDevice(device);
    for (auto [k, v] : temporal) applyParam(o.temporal, temporalParams(), nb::cast<std::string>(k), v, "temporal");
    for (auto [k, v] : svgf) applyParam(o.svgf, svgfParams(), nb::cast<std::string>(k), v, "SVGF");
    o.frame.method = parseDenoiseMethod(spatial);
    for (auto [k, v] : params) applyParam(o.frame, denoiseParams(), nb::cast<std::string>(k), v, "denoise");
    // Read once for the whole sequence, when a method of the run uses it.
    const DenoiseMethodInfo* still = findDenoiseMethod(method == "temporal" ? spatial : method);
    if (method == "svgf" ? o.svgf.learnedSpatial : still && still->usesWeights)
        o.frame.weights = o.svgfWeights = weightsFrom(learnedWeights);
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
        return d;
    };
    SequenceEvents events;
    if (!onFrame.is_none())
        events.frame = [&](const SequenceFrameReport& f) {
            nb::gil_scoped_acquire gil;
            onFrame(frameDict(f));
        };
    SequenceReport r;
    {
        nb::gil_scoped_release release;
        r = denoiseSequence(input, out, o, events);
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

// One render's files (readRenderFiles, include/atrous/io.h) as a dict of host arrays by buffer name.
// Python's keywords are the render table's rows (params.h); the library validates the ranges.
RenderSettings renderSettings(nb::dict params) {
    RenderSettings rs;
    for (auto [k, v] : params) applyParam(rs, renderParams(), nb::cast<std::string>(k), v, "render");
    return rs;
}

// The render's buffers as a dict of H x W x 3 arrays (motion only when the render made one).
nb::dict buffersDict(RenderBuffers&& b) {
    nb::dict d;
    for (const RenderBufferField& f : kRenderBufferFields)
        if (!(b.*f.image).empty()) d[f.name] = fromImage(std::move(b.*f.image));
    return d;
}

nb::dict pyRender(const std::string& scene, nb::dict params) {
    const RenderSettings rs = renderSettings(params);
    validateRenderSettings(rs);
    Scene s = Scene::loadByNameOrFile(scene);
    RenderBuffers b;
    {
        nb::gil_scoped_release release;
        b = render(s, rs);
    }
    return buffersDict(std::move(b));
}

// Frame `frame` of `frames` of an animated scene (atrous.render_sequence): the CLI's `render
// --frames` rule for times (frameTime) and seeds (seed + frame), motion against the previous frame.
nb::dict pyRenderFrame(const std::string& scene, int frame, int frames, const std::string& cameraPath, nb::dict params) {
    if (frames < 1) throw InputError("frames: must be at least 1 (got " + std::to_string(frames) + ")");
    if (frame < 0 || frame >= frames)
        throw InputError("frame " + std::to_string(frame) + " is outside 0.." + std::to_string(frames - 1));
    Scene s = Scene::loadByNameOrFile(scene);
    const CameraPath path = parseCameraPath(cameraPath);
    RenderSettings rs = renderSettings(params);
    validateRenderSettings(rs);
    rs.seed += uint32_t(frame);
    const float t = frameTime(frame, frames);
    const float tPrev = frame > 0 ? frameTime(frame - 1, frames) : t;
    RenderBuffers b;
    {
        nb::gil_scoped_release release;
        b = renderFrame(s, path, t, tPrev, rs);
    }
    nb::dict d = buffersDict(std::move(b));
    d["time"] = t;
    return d;
}

// Library errors name the field (`max_depth`, `device`, `camera_path`: ParamError) or the file,
// never a CLI flag, so Python shows them as they are: the field is the keyword.
}  // namespace

NB_MODULE(_core, m) {
    atrous::python::bindMethods(m);
    atrous::python::bindMetrics(m);
    atrous::python::bindVocabulary(m);
    m.doc() = "atrous native core (use the `atrous` package, not this module)";
    nb::register_exception_translator([](const std::exception_ptr& p, void*) {
        try {
            std::rethrow_exception(p);
        } catch (const InputError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        } catch (const atrous::RuntimeError& e) {
            PyErr_SetString(PyExc_RuntimeError, e.what());
        }
    });
    m.def("denoise", &pyDenoise, nb::arg("color"), nb::arg("albedo").none(), nb::arg("normal").none(),
          nb::arg("position").none(), nb::arg("depth").none(), nb::arg("variance").none(), nb::arg("ids").none(),
          nb::arg("emission").none(), nb::arg("method"), nb::arg("learned_weights").none(), nb::arg("params"));
    m.def("learned_planes", &pyLearnedPlanes, nb::arg("color"), nb::arg("variance").none(), nb::arg("albedo").none(),
          nb::arg("normal").none(), nb::arg("depth").none(), nb::arg("emission").none(), nb::arg("params"));
    m.def("render", &pyRender, nb::arg("scene"), nb::arg("params"));
    m.def("render_frame", &pyRenderFrame, nb::arg("scene"), nb::arg("frame"), nb::arg("frames"), nb::arg("camera_path"),
          nb::arg("params"));
    atrous::python::bindFiles(m);  // files.cpp: read_image, read_buffers, write_image
    m.def("denoise_params", [] { return paramRows(denoiseParams()); });
    // The still methods (denoiseMethods()): atrous.METHODS and the rows of atrous.denoise_methods().
    m.def("denoise_methods",
          [] { return methodRows(denoiseMethods(), "uses_weights", &DenoiseMethodInfo::usesWeights); });
    m.def("svgf_params", [] { return paramRows(svgfParams()); });
    m.def("temporal_params", [] { return paramRows(temporalParams()); });
    m.def("temporal_window_radius", [](nb::dict temporal) {
        TemporalParams tp;
        for (auto [k, v] : temporal) applyParam(tp, temporalParams(), nb::cast<std::string>(k), v, "temporal");
        validateTemporalParams(tp);
        return temporalWindowRadius(tp);
    });
    // The sequence methods (sequenceMethods(), include/atrous/temporal.h): atrous.SEQUENCE_METHODS.
    m.def("sequence_methods", [] { return methodRows(sequenceMethods(), "causal", &SequenceMethodInfo::causal); });
    m.def("denoise_temporal", &pyDenoiseTemporal, nb::arg("frames"), nb::arg("center"), nb::arg("method"),
          nb::arg("learned_weights").none(), nb::arg("device"), nb::arg("temporal"), nb::arg("params"));
    m.def("denoise_sequence", &pyDenoiseSequence, nb::arg("input"), nb::arg("out"), nb::arg("method"), nb::arg("spatial"),
          nb::arg("device"), nb::arg("learned_weights").none(), nb::arg("passes"), nb::arg("layer"), nb::arg("add_pass"),
          nb::arg("start"), nb::arg("end"), nb::arg("step"), nb::arg("exposure"), nb::arg("pngs"), nb::arg("preview"),
          nb::arg("temporal"), nb::arg("svgf"), nb::arg("params"), nb::arg("on_frame").none());
    m.def("render_params", [] { return paramRows(renderParams()); });
    m.def("resolve_denoise_params", [](nb::dict p) { return resolveParams(denoiseParams(), p, "denoise"); });
    m.def("resolve_svgf_params", [](nb::dict p) { return resolveParams(svgfParams(), p, "SVGF"); });
    m.def("builtin_scenes", [] { return builtinSceneNames(); });
    m.def("cuda_available", &cudaAvailable);
    m.def("cuda_compiled", &cudaCompiled);
    m.def("device_name", [](const std::string& d) { return deviceName(parseDevice(d)); });
    nb::class_<PySvgf>(m, "Svgf")
        .def(nb::init<const std::string&, nb::handle, nb::dict>(), nb::arg("device"), nb::arg("learned_weights").none(),
             nb::arg("params"))
        .def("denoise_frame", &PySvgf::denoiseFrame, nb::arg("color"), nb::arg("albedo").none(), nb::arg("normal").none(),
             nb::arg("depth").none(), nb::arg("ids").none(), nb::arg("motion").none(), nb::arg("emission").none(),
             nb::arg("position").none(), nb::arg("variance").none())
        .def("reset", &PySvgf::reset)
        .def_prop_ro("device", &PySvgf::device);
}

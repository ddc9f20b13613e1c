// atrous._core: the nanobind layer under the Python package (python/atrous/__init__.py holds the
// documented API and the argument rules). Arrays cross as H x W x C float32 with any strides, on
// the host or (CUDA builds) on the GPU; results are returned as new C-contiguous arrays on the
// same device. Library errors arrive in Python as ValueError (InputError) or RuntimeError.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>
#include <nanobind/stl/unordered_map.h>

#include <algorithm>
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
#include "atrous/param_set.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/image_io.h"
#include "arrays.h"
#include "frame.h"
#include "params.h"

namespace nb = nanobind;
using namespace atrous;

namespace atrous::python {
void bindMethods(nb::module_& m);  // methods.cpp: register_method
void bindMetrics(nb::module_& m);  // metrics.cpp: metrics, temporal_metrics
void bindFiles(nb::module_& m);    // files.cpp: read_image, read_buffers, write_image
void bindVocabulary(nb::module_& m);  // vocabulary.cpp: buffers, Weights, load_weights
void bindSequence(nb::module_& m);    // sequence.cpp: the sequence methods, their streams, denoise_sequence
LearnedWeights weightsFrom(nb::handle h);  // vocabulary.cpp: None, "", a path or a Weights
}

namespace {

using python::Array;
using python::Arrays;
using python::fromImage;
using python::toImage;
using python::weightsFrom;

// A keyword of the table (params.h) applied to the struct: python::applyParam on a set bound to it.
template <class S>
void applyParam(S& s, const ParamTable<S>& t, const std::string& k, const nb::handle& v, const char* what) {
    ParamSet set = ParamSet::bind(t, s);
    python::applyParam(set, k, v, what);
}

// What a set of keywords makes of the struct: {name: value} for every row (atrous' tests).
template <class S>
nb::dict resolveParams(const ParamTable<S>& t, nb::dict params, const char* what) {
    ParamSet set(t);
    python::applyParams(set, params, what);
    return python::paramValues(set);
}

// The table for Python (atrous.denoise_params(), atrous.svgf_params()): one dict per row.
template <class S>
nb::list paramRows(const ParamTable<S>& t) {
    return python::paramRows(ParamSet(t));
}

// The still methods' registry for Python (atrous.denoise_methods()): one dict per row.
nb::list stillMethodRows() {
    nb::list rows;
    for (const DenoiseMethodInfo& i : denoiseMethods()) {
        nb::dict d;
        d["name"] = i.name;
        d["summary"] = i.summary;
        d["uses_weights"] = readsWeights(i);
        d["registered"] = i.registered(), d["params"] = "denoise";
        // What the row reads (its cascade's buffers with the default options, and its parameter groups).
        nb::list reads;
        const BufferMask use = methodReads(i, DenoiseOptions{});
        for (int b = 0; b < kBufferCount; ++b)
            if (use.has(Buffer(b))) reads.append(bufferName(Buffer(b)));
        std::vector<std::string> groups;
        for (const ParamField<DenoiseOptions>& f : denoiseParams())
            if (readsParamGroup(i, f.group) && std::find(groups.begin(), groups.end(), f.group) == groups.end())
                groups.push_back(f.group);
        d["reads"] = reads;
        d["param_groups"] = groups;
        // A row that denoise() resolves into another per call (auto), with no cascade of its own.
        d["resolves"] = i.kind == CascadeKind::Auto;
        nb::list combines;
        for (DenoiseMethod c : i.reads.combines) combines.append(denoiseMethodName(c));
        d["combines"] = combines;
        rows.append(d);
    }
    return rows;
}

// The report of a denoise() call as a dict (atrous.denoise(..., report=True)).
nb::dict reportDict(const DenoiseReport& r) {
    nb::dict d;
    d["method_used"] = denoiseMethodName(r.methodUsed);
    d["noise_estimated"] = r.noiseEstimated, d["variance_ignored"] = r.varianceIgnored;
    d["noise_sigma"] = nb::make_tuple(r.noiseSigma[0], r.noiseSigma[1], r.noiseSigma[2]);
    d["non_finite_pixels"] = r.nonFinitePixels, d["fireflies_clamped"] = r.firefliesClamped;
    d["buffers_used"] = r.buffersUsed, d["milliseconds"] = r.milliseconds;
    nb::list stages;
    for (const StageTime& s : r.stages) stages.append(nb::make_tuple(s.name, s.milliseconds));
    d["stages"] = stages;
    d["copies"] = r.copies;
    return d;
}

// A frame of the caller's arrays, borrowed where they are (Arrays::strided: no copy), every
// buffer on the colour's device.
struct ArrayFrame {
    Arrays held;
    Frame frame;
    struct Arg {
        nb::handle obj;
        Buffer buffer;
        const char* what;  // the keyword
    };
    ArrayFrame(nb::handle color, std::initializer_list<Arg> args) {
        if (color.is_none()) throw InputError("color: an array is required");
        frame.color = held.strided(color, "color");
        for (const Arg& a : args) {
            const StridedImage s = held.strided(a.obj, a.what);
            if (s.valid() && s.device != frame.color.device())
                throw InputError(std::string(a.what) + ": lives on a different device than color");
            frame.set(a.buffer, s);
        }
    }
};

// atrous.denoise: the arrays handed to denoise() as they are (the colour, variance and emission
// are converted into the filter's planes by its first pass; the features the cascade reads are
// copied into planar storage, named in the report's `copies`). Returns (image, report or None).
nb::tuple pyDenoise(nb::handle color, nb::handle albedo, nb::handle normal, nb::handle position, nb::handle depth,
                    nb::handle variance, nb::handle ids, nb::handle emission, const std::string& method,
                    const std::string& device, nb::handle learnedWeights, nb::dict params, bool report) {
    ArrayFrame in(color, {{albedo, Buffer::Albedo, "albedo"}, {normal, Buffer::Normal, "normal"},
                          {position, Buffer::Position, "position"}, {depth, Buffer::Depth, "depth"},
                          {variance, Buffer::Variance, "variance"}, {ids, Buffer::ObjectId, "ids"},
                          {emission, Buffer::Emission, "emission"}});
    DenoiseOptions o;
    if (!method.empty()) o.method = parseDenoiseMethod(method);  // "": the library's default
    if (readsWeights(denoiseMethodInfo(o.method))) o.weights = weightsFrom(learnedWeights);  // auto's too
    // auto: the arrays' device (a CUDA colour on the GPU, numpy on the CPU); a result of a host
    // colour comes back to the host, one of a GPU colour stays there.
    o.device = device == "auto" ? in.frame.color.device() : parseDevice(device);
    if (o.device == Device::Cpu && in.frame.color.device() != Device::Cpu)
        throw InputError("device='cpu' with CUDA arrays: move them to the host first");
    for (auto [k, v] : params) applyParam(o, denoiseParams(), nb::cast<std::string>(k), v, "denoise");
    DenoiseResult r;
    {
        nb::gil_scoped_release release;
        if (report)
            r = denoiseWithReport(in.frame, o);
        else
            r.image = denoise(in.frame, o);
    }
    nb::object out = fromImage(std::move(r.image));
    return nb::make_tuple(out, report ? nb::object(reportDict(r.report)) : nb::none());
}

// The prepared planes of a still method (preparePlanes, by default the learned filter's): color,
// variance, albedo, normal, position, depth, ids (the features only when given and read),
// modulation and emission, on the host, for training and for checking a cascade.
nb::dict pyPreparedPlanes(nb::handle color, nb::handle variance, nb::handle albedo, nb::handle normal,
                          nb::handle depth, nb::handle emission, nb::handle position, nb::handle ids,
                          const std::string& method, nb::dict params) {
    ArrayFrame in(color, {{albedo, Buffer::Albedo, "albedo"}, {normal, Buffer::Normal, "normal"},
                          {position, Buffer::Position, "position"}, {depth, Buffer::Depth, "depth"},
                          {variance, Buffer::Variance, "variance"}, {ids, Buffer::ObjectId, "ids"},
                          {emission, Buffer::Emission, "emission"}});
    if (in.frame.color.device() != Device::Cpu) throw InputError("color: prepared_planes takes host (numpy) arrays");
    DenoiseOptions o;
    for (auto [k, v] : params) applyParam(o, denoiseParams(), nb::cast<std::string>(k), v, "denoise");
    // The planes of the learned method unless another is named, whatever the keywords say.
    o.method = method.empty() ? DenoiseMethod::Learned : parseDenoiseMethod(method);
    PreparedPlanes p;
    {
        nb::gil_scoped_release release;
        p = preparePlanes(in.frame, o);
    }
    nb::dict d;
    const std::pair<const char*, Image*> planes[] = {
        {"color", &p.color},       {"variance", &p.variance}, {"albedo", &p.albedo},         {"normal", &p.normal},
        {"position", &p.position}, {"depth", &p.depth},       {"ids", &p.ids},               {"modulation", &p.modulation},
        {"emission", &p.emission}};
    for (const auto& [name, img] : planes)
        if (!img->empty()) d[name] = fromImage(std::move(*img));
    return d;
}

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
    atrous::python::bindSequence(m);
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
    m.def("denoise", &pyDenoise, nb::arg("color").none(), nb::arg("albedo").none(), nb::arg("normal").none(),
          nb::arg("position").none(), nb::arg("depth").none(), nb::arg("variance").none(), nb::arg("ids").none(),
          nb::arg("emission").none(), nb::arg("method"), nb::arg("device"), nb::arg("learned_weights").none(),
          nb::arg("params"), nb::arg("report"));
    m.def("prepared_planes", &pyPreparedPlanes, nb::arg("color").none(), nb::arg("variance").none(),
          nb::arg("albedo").none(), nb::arg("normal").none(), nb::arg("depth").none(), nb::arg("emission").none(),
          nb::arg("position").none(), nb::arg("ids").none(), nb::arg("method"), nb::arg("params"));
    m.def("render", &pyRender, nb::arg("scene"), nb::arg("params"));
    m.def("render_frame", &pyRenderFrame, nb::arg("scene"), nb::arg("frame"), nb::arg("frames"), nb::arg("camera_path"),
          nb::arg("params"));
    atrous::python::bindFiles(m);  // files.cpp: read_image, read_buffers, write_image
    m.def("denoise_params", [] { return paramRows(denoiseParams()); });
    // The still methods (denoiseMethods()): atrous.METHODS and the rows of atrous.denoise_methods().
    m.def("denoise_methods", &stillMethodRows);
    // The built-in rows' names, for code about one of them (atrous.names), and the default.
    m.attr("EAW_METHOD") = denoiseMethodName(DenoiseMethod::Eaw);
    m.attr("SURE_METHOD") = denoiseMethodName(DenoiseMethod::Sure);
    m.attr("LEARNED_METHOD") = denoiseMethodName(DenoiseMethod::Learned);
    m.attr("BLEND_METHOD") = denoiseMethodName(DenoiseMethod::Blend);
    m.attr("REFINE_METHOD") = denoiseMethodName(DenoiseMethod::Refine);
    m.attr("DEFAULT_METHOD") = denoiseMethodName(DenoiseOptions{}.method);
    m.def("svgf_params", [] { return paramRows(svgfParams()); });
    m.def("temporal_params", [] { return paramRows(temporalParams()); });
    m.def("temporal_window_radius", [](nb::dict temporal) {
        TemporalParams tp;
        for (auto [k, v] : temporal) applyParam(tp, temporalParams(), nb::cast<std::string>(k), v, "temporal");
        validateTemporalParams(tp);
        return temporalWindowRadius(tp);
    });
    m.def("render_params", [] { return paramRows(renderParams()); });
    m.def("resolve_denoise_params", [](nb::dict p) { return resolveParams(denoiseParams(), p, "denoise"); });
    m.def("resolve_svgf_params", [](nb::dict p) { return resolveParams(svgfParams(), p, "SVGF"); });
    m.def("builtin_scenes", [] { return builtinSceneNames(); });
    m.def("cuda_available", &cudaAvailable);
    m.def("cuda_compiled", &cudaCompiled);
    m.def("device_name", [](const std::string& d) { return deviceName(parseDevice(d)); });
}

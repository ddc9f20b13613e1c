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
using python::Buffers;
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
        nb::list reads, groups;
        const BufferMask use = methodReads(i, DenoiseOptions{});
        for (int b = 0; b < kBufferCount; ++b)
            if (use.has(Buffer(b))) reads.append(bufferName(Buffer(b)));
        for (const ParamField<DenoiseOptions>& f : denoiseParams())
            if (readsParamGroup(i, f.group) && !groups.contains(f.group)) groups.append(f.group);
        d["reads"] = reads;
        d["param_groups"] = groups;
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
    if (readsWeights(denoiseMethodInfo(o.method))) o.weights = weightsFrom(learnedWeights);  // auto's too
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

// The learned filter's prepared planes (preparePlanes with method learned): d, var, albedo,
// normal, depth (the last three only when given), mod and emission, on the host, for training.
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
    o.method = DenoiseMethod::Learned;  // the planes of the learned method, whatever the keywords say
    PreparedPlanes p;
    {
        nb::gil_scoped_release release;
        p = preparePlanes(in, o);
    }
    nb::dict d;
    const std::pair<const char*, Image*> planes[] = {{"d", &p.color},        {"var", &p.variance}, {"albedo", &p.albedo},
                                                     {"normal", &p.normal}, {"depth", &p.depth},  {"mod", &p.modulation},
                                                     {"emission", &p.emission}};
    for (const auto& [name, img] : planes)
        if (!img->empty()) d[name] = fromImage(std::move(*img));
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
    m.def("denoise_methods", &stillMethodRows);
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

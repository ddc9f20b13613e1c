// atrous._core.register_method: a still method whose cascade is a Python function, as one row of
// the library's registry (registerDenoiseMethod, include/atrous/denoise.h). The function gets the
// prepared planes as H x W x C float32 views of the filter's own planar storage (no copies; valid
// during the call only) and writes the filtered colour into `out`.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/plugins.h"

namespace nb = nanobind;

namespace atrous::python {

namespace {

// A planar plane set as an H x W x C array over the same floats (strides in elements).
template <class... Extra>
nb::object planarView(const ImageView& v) {
    if (!v.valid()) return nb::none();
    const size_t shape[3] = {size_t(v.height), size_t(v.width), size_t(v.channels)};
    const int64_t strides[3] = {int64_t(v.width), 1, int64_t(v.plane())};
    // rv_policy::reference: a view of the planes (the default would copy an array without owner).
    return nb::ndarray<nb::numpy, float, Extra...>(v.data, 3, shape, nb::handle(), strides).cast(nb::rv_policy::reference);
}

// The Python function, held for the life of the program: registry rows are never removed, and a
// reference dropped at interpreter exit (after Python is gone) would crash, so it is never dropped.
struct PyCascade {
    PyObject* fn;
    void operator()(const PreparedView& p, const DenoiseOptions&, const ImageView& out) const {
        nb::gil_scoped_acquire gil;
        nb::dict planes;
        planes["color"] = planarView<nb::ro>(p.color);
        planes["variance"] = planarView<nb::ro>(p.variance);
        planes["albedo"] = planarView<nb::ro>(p.albedo);
        planes["normal"] = planarView<nb::ro>(p.normal);
        planes["position"] = planarView<nb::ro>(p.position);
        planes["depth"] = planarView<nb::ro>(p.depth);
        planes["ids"] = planarView<nb::ro>(p.ids);
        try {
            const nb::handle cascade(fn);
            cascade(planes, planarView<>(out));
        } catch (nb::python_error& e) {
            // Carried through the library as its RuntimeError (Python's RuntimeError), named.
            // The exception's own line ("KeyError: 'nope'"), the last of the traceback nanobind
            // renders: one line for the caller.
            std::string what = e.what();
            while (!what.empty() && what.back() == '\n') what.pop_back();
            throw RuntimeError("its cascade raised " + what.substr(what.rfind('\n') + 1));
        }
    }
};

}  // namespace

void bindMethods(nb::module_& m) {
    m.def("load_plugin", [](const std::string& path) {
        nb::gil_scoped_release release;
        loadPlugin(path);
    });
    m.def("register_method", [](const std::string& name, const std::string& summary, nb::callable cascade,
                                std::vector<std::string> reads) {
        DenoiseMethodInfo info;
        info.name = name.c_str(), info.summary = summary.c_str();
        for (const std::string& b : reads) {
            // The features a cascade may read, by their frame names ("ids": the object and material ids).
            bool found = false;
            for (Buffer f : {Buffer::Variance, Buffer::Albedo, Buffer::Normal, Buffer::Position, Buffer::Depth,
                             Buffer::ObjectId, Buffer::Emission})
                if (b == (f == Buffer::ObjectId ? "ids" : bufferName(f))) info.reads.buffers = info.reads.buffers.with(f), found = true;
            if (!found)
                throw InputError("register_method: reads: unknown buffer '" + b +
                                 "' (variance, albedo, normal, position, depth, ids, emission)");
        }
        PyObject* fn = cascade.ptr();
        info.cpu = PyCascade{fn};
        const DenoiseMethod added = registerDenoiseMethod(std::move(info));
        Py_INCREF(fn);  // the row's reference, once the row exists
        return static_cast<int>(added);
    });
}

}  // namespace atrous::python

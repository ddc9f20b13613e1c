// The library's vocabulary in Python: the buffer table (atrous.buffers(), include/atrous/buffers.h:
// each buffer's name, channels and convention) and atrous._core.Weights, the learned filter's
// network as a resource loaded once (LearnedWeights, include/atrous/learned.h), so a batch of
// denoise() calls or a sequence shares one parse of its weight file. Every learned_weights=
// argument takes one, a path or nothing.
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <string>

#include "atrous/buffers.h"
#include "atrous/learned.h"

namespace nb = nanobind;

namespace atrous::python {

LearnedWeights weightsFrom(nb::handle h) {
    if (h.is_none()) return {};
    if (nb::isinstance<LearnedWeights>(h)) return nb::cast<LearnedWeights>(h);
    const std::string path = nb::cast<std::string>(h);
    return path.empty() ? LearnedWeights{} : LearnedWeights::load(path);  // InputError names the file
}

void bindVocabulary(nb::module_& m) {
    m.def("buffers", [] {
        nb::list rows;
        for (int i = 0; i < kBufferCount; ++i) {
            const BufferInfo& b = bufferInfo(Buffer(i));
            nb::dict d;
            d["name"] = b.name;
            d["channels"] = b.channels;
            d["takes_grey"] = b.takesGrey;
            d["meaning"] = b.meaning;
            rows.append(d);
        }
        return rows;
    });
    nb::class_<LearnedWeights>(m, "Weights", "The learned filter's network, loaded once (atrous.load_weights).");
    m.def("load_weights", [](const std::string& path) { return LearnedWeights::load(path); }, nb::arg("path"));
    m.def("builtin_weights", [] { return LearnedWeights::builtin(); });
}

}  // namespace atrous::python

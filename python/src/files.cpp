// atrous._core's image files: read_image, read_buffers, write_image (python/atrous/__init__.py holds
// the documented API). Image files go through the library's readers and writers (OpenEXR, PFM, stb),
// so Python reads exactly what the CLI writes and the other way round; errors name the file
// (InputError), and the keywords, not the CLI's flags.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cctype>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "arrays.h"
#include "words.h"
#include "atrous/error.h"
#include "atrous/interop.h"
#include "atrous/io.h"
#include "atrous/io/alpha.h"
#include "atrous/io/image_io.h"

namespace nb = nanobind;

namespace atrous::python {

namespace {

nb::dict pyReadBuffers(const std::string& path, const std::vector<std::string>& passes, const std::string& layer) {
    RenderFiles r;
    try {
        nb::gil_scoped_release release;
        r = readRenderFiles(path, passes, layer);
    } catch (const InputError& e) {
        throw InputError(pythonWords(e.what(), {{"--in", "path"}, {"--pass", "passes"}, {"--layer", "layer"}}));
    }
    nb::dict d;
    for (auto& [name, img] : r.buffers) d[name.c_str()] = fromImage(std::move(img));
    return d;
}

// alpha: the file's alpha channel as a 4th (io::readAlpha), when it has one.
nb::object pyReadImage(const std::string& path, bool alpha) {
    Image img;
    {
        nb::gil_scoped_release release;
        img = atrous::readImage(path);
        if (alpha) {
            const Image a = io::readAlpha(path, {}, "", img.width(), img.height());
            img = io::withAlpha(std::move(img), a);
        }
    }
    return fromImage(std::move(img));
}

// `image` is H x W x 3, H x W x 4 (alpha), H x W x 1 or H x W (the array rule, arrays.h); one
// channel stays one channel so that PFM writes grey ("Pf") and EXR repeats it.
void pyWriteImage(const std::string& path, nb::handle image) {
    Arrays held;
    const StridedImage s = held.strided(image, path.c_str());
    if (s.channels == 2)
        throw InputError(path + ": expected an array of shape (H, W, 3), (H, W, 4), (H, W, 1) or (H, W), got 2 channels");
    Image img = importImage(s, s.channels, path.c_str());
    if (img.device() != Device::Cpu) img = img.to(Device::Cpu);  // the writers read host memory
    nb::gil_scoped_release release;
    atrous::writeImage(path, img);
}

}  // namespace

void bindFiles(nb::module_& m) {
    m.def("read_image", &pyReadImage, nb::arg("path"), nb::arg("alpha") = false);
    m.def("read_buffers", &pyReadBuffers, nb::arg("path"), nb::arg("passes"), nb::arg("layer"));
    m.def("write_image", &pyWriteImage, nb::arg("path"), nb::arg("image").none());
}

}  // namespace atrous::python

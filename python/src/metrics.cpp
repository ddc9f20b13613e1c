// atrous.metrics and atrous.temporal_metrics: the library's image metrics (include/atrous/metrics.h),
// the one relMSE every evaluation, test and training script reports.
#include <nanobind/nanobind.h>

#include <cstdint>

#include "arrays.h"
#include "atrous/metrics.h"

namespace atrous::python {

namespace {

Image hostImage(nb::handle a, const char* what) {
    Image img = toImage(a, what);
    return img.device() == Device::Cpu ? std::move(img) : img.to(Device::Cpu);
}

nb::dict pyMetrics(nb::handle image, nb::handle reference) {
    const Image a = hostImage(image, "image"), r = hostImage(reference, "reference");
    ImageMetrics m = computeMetrics(a, r);
    nb::dict d;
    d["mse"] = m.mse;
    d["relmse"] = m.relMse;
    d["psnr"] = m.psnr;
    d["ssim"] = m.ssim;
    d["non_finite_pixels"] = m.nonFinitePixels;
    d["reference_non_finite_pixels"] = m.referenceNonFinitePixels;
    return d;
}

// One step of a sequence: relMSE of the frame differences against the reference's, and tPSNR.
nb::dict pyTemporalMetrics(nb::handle image, nb::handle previous, nb::handle reference, nb::handle previousReference) {
    const TemporalMetrics m = computeTemporalMetrics(hostImage(image, "image"), hostImage(previous, "previous"),
                                                     hostImage(reference, "reference"),
                                                     hostImage(previousReference, "previous_reference"));
    nb::dict d;
    d["relmse"] = m.relMse;
    d["psnr"] = m.psnr;
    return d;
}

// The tonemap of the PSNR and SSIM (tonemapForMetrics), as an H x W x 3 array: what the metrics
// compare, and what ColorVideoVDP is shown (atrous.eval.cvvdp); with eight_bit, the library's
// 8-bit preview of it (tonemap8: the evaluation's crops, the corpus previews), uint8.
nb::object pyTonemap(nb::handle image, bool eightBit) {
    Image img = hostImage(image, "image");
    float* v = img.data();
    const size_t n = img.plane() * size_t(img.channels());
    if (!eightBit) {
        for (size_t i = 0; i < n; ++i) v[i] = tonemapForMetrics(v[i]);
        return fromImage(std::move(img));
    }
    const int w = img.width(), h = img.height(), ch = img.channels();
    auto* bytes = new uint8_t[n];
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < ch; ++c) bytes[(size_t(y) * w + x) * ch + c] = tonemap8(img(x, y, c));
    nb::capsule owner(bytes, [](void* p) noexcept { delete[] static_cast<uint8_t*>(p); });
    const size_t shape[3] = {size_t(h), size_t(w), size_t(ch)};
    return nb::ndarray<nb::numpy, uint8_t>(bytes, 3, shape, owner).cast();
}

}  // namespace

void bindMetrics(nb::module_& m) {
    m.def("metrics", &pyMetrics, nb::arg("image").none(), nb::arg("reference").none());
    m.def("temporal_metrics", &pyTemporalMetrics, nb::arg("image").none(), nb::arg("previous").none(),
          nb::arg("reference").none(), nb::arg("previous_reference").none());
    m.def("tonemap", &pyTonemap, nb::arg("image").none(), nb::arg("eight_bit"));
}

}  // namespace atrous::python

// atrous.metrics and atrous.temporal_metrics: the library's image metrics (include/atrous/metrics.h),
// the one relMSE every evaluation, test and training script reports.
#include <nanobind/nanobind.h>

#include "arrays.h"
#include "atrous/metrics.h"

namespace atrous::python {

namespace {

Image hostImage(const Array& a, const char* what) {
    Image img = toImage(a, what);
    return img.device() == Device::Cpu ? std::move(img) : img.to(Device::Cpu);
}

nb::dict pyMetrics(const Array& image, const Array& reference) {
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
nb::dict pyTemporalMetrics(const Array& image, const Array& previous, const Array& reference,
                           const Array& previousReference) {
    const TemporalMetrics m = computeTemporalMetrics(hostImage(image, "image"), hostImage(previous, "previous"),
                                                     hostImage(reference, "reference"),
                                                     hostImage(previousReference, "previous_reference"));
    nb::dict d;
    d["relmse"] = m.relMse;
    d["psnr"] = m.psnr;
    return d;
}

// The tonemap of the PSNR and SSIM (tonemapForMetrics), as an H x W x 3 array: what the metrics
// compare, and what ColorVideoVDP is shown (atrous.eval.cvvdp).
nb::object pyTonemap(const Array& image) {
    Image img = hostImage(image, "image");
    float* v = img.data();
    for (size_t i = 0, n = img.plane() * size_t(img.channels()); i < n; ++i) v[i] = tonemapForMetrics(v[i]);
    return fromImage(std::move(img));
}

}  // namespace

void bindMetrics(nb::module_& m) {
    m.def("metrics", &pyMetrics, nb::arg("image"), nb::arg("reference"));
    m.def("temporal_metrics", &pyTemporalMetrics, nb::arg("image"), nb::arg("previous"), nb::arg("reference"),
          nb::arg("previous_reference"));
    m.def("tonemap", &pyTonemap, nb::arg("image"));
}

}  // namespace atrous::python

// numpy (and DLPack CUDA) arrays to and from the library's images, for every binding file. The
// array rules (what an array may be: its dimensions, element type, device) are checked here, once,
// in C++; the channel counts and sizes by the library itself (importImage, denoise()). The Python
// package passes arrays through.
#pragma once
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <memory>
#include <vector>

#include "atrous/device.h"
#include "atrous/image.h"

namespace atrous::python {

namespace nb = nanobind;

using Array = nb::ndarray<nb::ro>;  // any dtype, shape, strides and device: checked by Arrays::strided

// The array rule, for every array Python hands to the library: an H x W x C (C = 1..4) or H x W
// array of float32 or float16, with any strides (negative ones too), on the host or (CUDA builds)
// on a CUDA device, taken where it is (a StridedImage over its memory, no copy); a float64 host
// array is converted to float32 here; anything that is not an array (a list) goes through
// numpy.asarray first. Another element type, another number of dimensions, or a device other than
// the CPU and CUDA is an InputError naming the keyword (`what`). An Arrays holds every array it
// described (and the float64 conversions) for as long as the library reads them.
class Arrays {
public:
    // The array's layout, borrowed; data null for None.
    StridedImage strided(nb::handle obj, const char* what);

private:
    std::vector<Array> mHeld;
    std::vector<std::unique_ptr<float[]>> mConverted;
};

// The array's device: the CPU or CUDA (InputError for another, or CUDA without a usable backend).
Device deviceOf(const Array& a, const char* what);
// An array copied into a planar Image of `channels` on the array's device (importImage's channel
// rule: one channel repeats), for the library's calls that take Images (the sequence methods, the
// metrics, the writers).
Image toImage(nb::handle obj, const char* what, int channels = 3);
// Hands an Image to Python as a C-contiguous H x W x C float32 array on the image's device.
nb::object fromImage(Image&& img);

}  // namespace atrous::python

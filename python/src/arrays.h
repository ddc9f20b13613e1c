// numpy (and DLPack CUDA) arrays to and from the library's planar Images, for every binding file.
#pragma once
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include "atrous/device.h"
#include "atrous/image.h"

namespace atrous::python {

namespace nb = nanobind;

using Array = nb::ndarray<nb::ro>;  // any dtype, shape, strides and device: checked by toImage

// The array's device: the CPU or CUDA (InputError for another, or CUDA without a usable backend).
Device deviceOf(const Array& a, const char* what);
// Copies a H x W x C (or H x W) float32 array into a planar Image of `channels` on the array's
// device (importImage's channel rule). InputError naming `what` otherwise.
Image toImage(const Array& a, const char* what, int channels = 3);
// Hands an Image to Python as a C-contiguous H x W x C float32 array on the image's device.
nb::object fromImage(Image&& img);

}  // namespace atrous::python

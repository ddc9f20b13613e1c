// numpy / DLPack arrays to and from Images (arrays.h).
#include "arrays.h"

#include <string>

#include "atrous/error.h"
#include "atrous/interop.h"

namespace atrous::python {

Device deviceOf(const Array& a, const char* what) {
    if (a.device_type() == nb::device::cpu::value) return Device::Cpu;
    if (a.device_type() == nb::device::cuda::value) {
        if (!cudaAvailable())
            throw InputError(std::string(what) + ": a CUDA array was given but this build of atrous has no usable CUDA backend");
        return Device::Cuda;
    }
    throw InputError(std::string(what) + ": arrays must live on the CPU or a CUDA device");
}

// Copies a H x W x C (or H x W) float32 array into a planar Image on the array's device.
Image toImage(const Array& a, const char* what, int channels) {
    if (a.dtype() != nb::dtype<float>())
        throw InputError(std::string(what) + ": expected float32 data");
    if (a.ndim() != 2 && a.ndim() != 3)
        throw InputError(std::string(what) + ": expected an array of shape (H, W, 3), got " + std::to_string(a.ndim()) + " dimensions");
    // nanobind's strides are in elements; StridedImage's in bytes.
    StridedImage s;
    s.data = a.data();
    s.type = DataType::Float32;
    s.height = int(a.shape(0));
    s.width = int(a.shape(1));
    s.channels = a.ndim() == 3 ? int(a.shape(2)) : 1;
    s.rowStride = a.stride(0) * int64_t(sizeof(float));
    s.pixelStride = a.stride(1) * int64_t(sizeof(float));
    s.channelStride = a.ndim() == 3 ? a.stride(2) * int64_t(sizeof(float)) : 0;
    s.device = deviceOf(a, what);
    if (a.shape(0) == 0 || a.shape(1) == 0) throw InputError(std::string(what) + ": empty array");
    return importImage(s, channels, what);
}

// Hands an Image to Python as a C-contiguous H x W x C float32 array on the image's device.
nb::object fromImage(Image&& img) {
    const Device dev = img.device();
    // Holds H x W x C floats, every one written by exportImage: no zero fill first.
    Image* inter = new Image(Image::uninitialized(img.width(), img.height(), img.channels(), dev));
    exportImage(img.view(), interleavedImage(inter->data(), DataType::Float32, img.width(), img.height(), img.channels(), dev),
                "result");
    nb::capsule owner(inter, [](void* p) noexcept { delete static_cast<Image*>(p); });
    const size_t shape[3] = {size_t(img.height()), size_t(img.width()), size_t(img.channels())};
    const int devType = dev == Device::Cuda ? nb::device::cuda::value : nb::device::cpu::value;
    if (dev == Device::Cpu) {
        nb::ndarray<nb::numpy, float> arr(inter->data(), 3, shape, owner);
        return arr.cast();
    }
    nb::ndarray<float> arr(inter->data(), 3, shape, owner, nullptr, nb::dtype<float>(), devType, 0);
    return arr.cast();
}

}  // namespace atrous::python

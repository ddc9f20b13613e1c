// numpy / DLPack arrays to and from the library's images (arrays.h): the array rule, once.
#include "arrays.h"

#include <string>

#include "atrous/error.h"
#include "atrous/interop.h"

namespace atrous::python {

namespace {

namespace dl = nb::dlpack;

bool isFloat(const Array& a, int bits) {
    return a.dtype().code == uint8_t(dl::dtype_code::Float) && a.dtype().bits == bits && a.dtype().lanes == 1;
}

std::string dtypeName(const Array& a) {
    static const char* const kCodes[] = {"int", "uint", "float", "", "bfloat", "complex", "bool"};
    const uint8_t code = a.dtype().code;
    const std::string kind = code < 7 && *kCodes[code] ? kCodes[code] : "dtype code " + std::to_string(code) + " of ";
    return code == uint8_t(dl::dtype_code::Bool) ? kind : kind + std::to_string(a.dtype().bits);
}

// The object as an array: an array (numpy, DLPack) as it is, anything else through numpy.asarray
// (a list of lists), a tensor that records gradients detached first.
Array arrayOf(nb::handle obj, const char* what) {
    Array a;
    if (nb::try_cast(obj, a, false)) return a;
    nb::object o = nb::borrow(obj);
    try {
        if (nb::hasattr(o, "detach")) o = o.attr("detach")();
        if (!nb::try_cast(o, a, false)) o = nb::module_::import_("numpy").attr("asarray")(o);
    } catch (nb::python_error&) {
        throw InputError(std::string(what) + ": expected an array, got " + nb::type_name(obj.type()).c_str());
    }
    if (!nb::try_cast(o, a, false))
        throw InputError(std::string(what) + ": expected an array of float32 or float16 (an H x W x C numpy array), got " +
                         nb::type_name(obj.type()).c_str());
    return a;
}

}  // namespace

Device deviceOf(const Array& a, const char* what) {
    if (a.device_type() == nb::device::cpu::value) return Device::Cpu;
    if (a.device_type() == nb::device::cuda::value) {
        if (!cudaAvailable())
            throw InputError(std::string(what) + ": a CUDA array was given but this build of atrous has no usable CUDA backend");
        return Device::Cuda;
    }
    throw InputError(std::string(what) + ": arrays must live on the CPU or a CUDA device");
}

StridedImage Arrays::strided(nb::handle obj, const char* what) {
    if (obj.is_none()) return {};
    Array a = arrayOf(obj, what);
    if (a.ndim() != 2 && a.ndim() != 3)
        throw InputError(std::string(what) + ": expected an array of shape (H, W, C) or (H, W), got " +
                         std::to_string(a.ndim()) + (a.ndim() == 1 ? " dimension" : " dimensions"));
    if (a.shape(0) == 0 || a.shape(1) == 0)
        throw InputError(std::string(what) + ": empty array (" + std::to_string(a.shape(0)) + " x " +
                         std::to_string(a.shape(1)) + ")");
    const Device device = deviceOf(a, what);
    const bool f32 = isFloat(a, 32), f16 = isFloat(a, 16), f64 = isFloat(a, 64) && device == Device::Cpu;
    if (!f32 && !f16 && !f64)
        throw InputError(std::string(what) + ": expected float32 or float16 data (float64 on the host is converted), got dtype " +
                         dtypeName(a));
    if (a.ndim() == 3 && (a.shape(2) < 1 || a.shape(2) > 4))
        throw InputError(std::string(what) + ": expected 1 to 4 channels, got " + std::to_string(a.shape(2)));
    StridedImage s;
    s.type = f16 ? DataType::Float16 : DataType::Float32;
    s.height = int(a.shape(0));
    s.width = int(a.shape(1));
    s.channels = a.ndim() == 3 ? int(a.shape(2)) : 1;
    s.device = device;
    // nanobind's strides are in elements; StridedImage's in bytes.
    const int64_t item = int64_t(a.itemsize());
    s.rowStride = a.stride(0) * item;
    s.pixelStride = a.stride(1) * item;
    s.channelStride = a.ndim() == 3 ? a.stride(2) * item : 0;
    s.data = a.data();
    if (f64) {
        // float32 copies, interleaved, in an array of our own.
        const size_t n = a.size();
        auto* out = new float[n];
        mConverted.emplace_back(out);
        const char* base = static_cast<const char*>(a.data());
        for (int y = 0, i = 0; y < s.height; ++y)
            for (int x = 0; x < s.width; ++x)
                for (int c = 0; c < s.channels; ++c)
                    out[i++] = float(*reinterpret_cast<const double*>(base + y * s.rowStride + x * s.pixelStride +
                                                                         c * s.channelStride));
        s = interleavedImage(out, DataType::Float32, s.width, s.height, s.channels);
    }
    mHeld.push_back(std::move(a));
    return s;
}

Image toImage(nb::handle obj, const char* what, int channels) {
    Arrays held;
    const StridedImage s = held.strided(obj, what);
    if (!s.valid()) throw InputError(std::string(what) + ": no array given");
    return importImage(s, channels, what);  // names `what` for an empty array or a channel mismatch
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

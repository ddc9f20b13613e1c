// The C API's entry points (include/atrous/atrous.h): each one runs its work inside guarded(),
// which turns every exception into an error code and a message on the device, so that nothing
// escapes into a C caller. The work itself is src/capi/capi_filter.cpp and capi_params.cpp.
#include <new>
#include <string>
#include <utility>

#include "atrous/device.h"
#include "atrous/error.h"
#include "atrous/params.h"
#include "capi/capi_impl.h"

using namespace atrous;
using atrous::capi::Failure;

void AtrousDeviceImpl::record(AtrousError code, const std::string& message) {
    std::lock_guard<std::mutex> lock(mMutex);
    if (mCode != ATROUS_ERROR_NONE) return;  // the first error since the last take()
    mCode = code;
    mMessage = message;
}

AtrousError AtrousDeviceImpl::take(const char** message) {
    std::lock_guard<std::mutex> lock(mMutex);
    const AtrousError code = mCode;
    mReturned.swap(mMessage);
    mMessage.clear();
    mCode = ATROUS_ERROR_NONE;
    if (message) *message = mReturned.c_str();
    return code;
}

namespace {

// The errors of calls without a device (a NULL handle, a failed atrousNewDevice), per thread.
AtrousDeviceImpl& orphanErrors() {
    thread_local AtrousDeviceImpl slot;
    return slot;
}

// Records "fn: message" (the first error since the last atrousGetDeviceError).
void record(AtrousDeviceImpl* d, AtrousError code, const char* fn, const char* message) noexcept {
    try {
        (d ? *d : orphanErrors()).record(code, std::string(fn) + ": " + message);
    } catch (...) {  // no memory left for the message: the error is lost, the caller is not
    }
}

// The library's RuntimeError for an allocation that failed ("out of host memory ...", "out of GPU
// memory ...").
bool outOfMemory(const char* what) {
    const std::string w = what;
    return w.rfind("out of ", 0) == 0 && w.find("memory") != std::string::npos;
}

// Runs `work`, returning its value, or `fallback` with the error recorded on `d` as "fn: message".
template <class Work, class T>
T guarded(AtrousDeviceImpl* d, const char* fn, Work&& work, T fallback) noexcept {
    try {
        return work();
    } catch (const Failure& e) {
        record(d, e.code, fn, e.message.c_str());
    } catch (const InputError& e) {  // ParamError included
        record(d, ATROUS_ERROR_INVALID_ARGUMENT, fn, e.what());
    } catch (const std::bad_alloc&) {
        record(d, ATROUS_ERROR_OUT_OF_MEMORY, fn, "out of memory");
    } catch (const std::exception& e) {
        bool oom = false;
        try {
            oom = outOfMemory(e.what());
        } catch (...) {
        }
        record(d, oom ? ATROUS_ERROR_OUT_OF_MEMORY : ATROUS_ERROR_UNKNOWN, fn, e.what());
    } catch (...) {
        record(d, ATROUS_ERROR_UNKNOWN, fn, "an unknown exception");
    }
    return fallback;
}

// The same for a filter's call; a NULL filter is an error of this thread's orphan slot.
template <class Work, class T>
T onFilter(AtrousFilter f, const char* fn, Work&& work, T fallback) noexcept {
    if (!f) {
        record(nullptr, ATROUS_ERROR_INVALID_ARGUMENT, fn, "filter is NULL");
        return fallback;
    }
    return guarded(f->device, fn, std::forward<Work>(work), fallback);
}

void releaseDevice(AtrousDeviceImpl* d) {
    if (d && d->refs.fetch_sub(1) == 1) delete d;
}

}  // namespace

extern "C" {

AtrousDevice atrousNewDevice(const char* type) {
    return guarded(
        nullptr, "atrousNewDevice",
        [&]() -> AtrousDevice {
            const std::string t = type ? type : "";
            Device dev = Device::Cpu;
            if (t == "cuda") {
                if (!cudaAvailable())
                    throw Failure{ATROUS_ERROR_UNSUPPORTED_HARDWARE,
                                  cudaCompiled()
                                      ? "type \"cuda\": no CUDA-capable GPU is available"
                                      : "type \"cuda\": this build of atrous has no CUDA backend"};
                dev = Device::Cuda;
            } else if (t.empty() || t == "default") {
                dev = cudaAvailable() ? Device::Cuda : Device::Cpu;
            } else if (t != "cpu") {
                throw Failure{ATROUS_ERROR_INVALID_ARGUMENT,
                              "type \"" + t + "\" is not a device (cpu, cuda or default)"};
            }
            AtrousDeviceImpl* d = new AtrousDeviceImpl;
            d->device = dev;
            return d;
        },
        AtrousDevice(nullptr));
}

void atrousRetainDevice(AtrousDevice d) {
    if (d)
        d->refs.fetch_add(1);
    else
        record(nullptr, ATROUS_ERROR_INVALID_ARGUMENT, "atrousRetainDevice", "device is NULL");
}

void atrousReleaseDevice(AtrousDevice d) {
    releaseDevice(d);
}

const char* atrousGetDeviceType(AtrousDevice d) {
    if (!d) {
        record(nullptr, ATROUS_ERROR_INVALID_ARGUMENT, "atrousGetDeviceType", "device is NULL");
        return nullptr;
    }
    return deviceToString(d->device);
}

AtrousError atrousGetDeviceError(AtrousDevice d, const char** message) {
    return (d ? *d : orphanErrors()).take(message);
}

AtrousFilter atrousNewFilter(AtrousDevice d, const char* method) {
    if (!d) {
        record(nullptr, ATROUS_ERROR_INVALID_ARGUMENT, "atrousNewFilter", "device is NULL");
        return nullptr;
    }
    return guarded(
        d, "atrousNewFilter",
        [&]() -> AtrousFilter {
            DenoiseOptions o;
            if (method && *method) {
                if (!findDenoiseMethod(method))
                    throw Failure{ATROUS_ERROR_INVALID_ARGUMENT, std::string("method \"") + method +
                                                                     "\" is not a method (" +
                                                                     denoiseMethodNames() + ")"};
                o.method = parseDenoiseMethod(method);
            }
            o.device = d->device;
            AtrousFilterImpl* f = new AtrousFilterImpl;
            f->options = o;
            f->device = d;
            d->refs.fetch_add(1);
            return f;
        },
        AtrousFilter(nullptr));
}

void atrousRetainFilter(AtrousFilter f) {
    onFilter(
        f, "atrousRetainFilter", [&] { return f->refs.fetch_add(1), 0; }, 0);
}

void atrousReleaseFilter(AtrousFilter f) {
    if (!f) return;  // as free(NULL)
    onFilter(
        f, "atrousReleaseFilter",
        [&] {
            if (f->refs.fetch_sub(1) == 1) {
                AtrousDeviceImpl* d = f->device;
                delete f;
                releaseDevice(d);
            }
            return 0;
        },
        0);
}

void atrousSetFilterImage(AtrousFilter f, const char* name, void* ptr, AtrousFormat format,
                          size_t width, size_t height, size_t byteOffset, size_t pixelByteStride,
                          size_t rowByteStride) {
    onFilter(
        f, "atrousSetFilterImage",
        [&] {
            return f->setImage(name, ptr, format, width, height, byteOffset, pixelByteStride,
                               rowByteStride),
                   0;
        },
        0);
}

void atrousUnsetFilterImage(AtrousFilter f, const char* name) {
    onFilter(
        f, "atrousUnsetFilterImage", [&] { return f->unsetImage(name), 0; }, 0);
}

void atrousSetFilterInt(AtrousFilter f, const char* name, int value) {
    onFilter(
        f, "atrousSetFilterInt", [&] { return f->setInt(name, value), 0; }, 0);
}

void atrousSetFilterFloat(AtrousFilter f, const char* name, float value) {
    onFilter(
        f, "atrousSetFilterFloat", [&] { return f->setFloat(name, value), 0; }, 0);
}

void atrousSetFilterBool(AtrousFilter f, const char* name, bool value) {
    onFilter(
        f, "atrousSetFilterBool", [&] { return f->setBool(name, value), 0; }, 0);
}

void atrousSetFilterString(AtrousFilter f, const char* name, const char* value) {
    onFilter(
        f, "atrousSetFilterString", [&] { return f->setString(name, value), 0; }, 0);
}

int atrousGetFilterInt(AtrousFilter f, const char* name) {
    return onFilter(
        f, "atrousGetFilterInt", [&] { return f->getInt(name); }, 0);
}

float atrousGetFilterFloat(AtrousFilter f, const char* name) {
    return onFilter(
        f, "atrousGetFilterFloat", [&] { return f->getFloat(name); }, 0.0f);
}

bool atrousGetFilterBool(AtrousFilter f, const char* name) {
    return onFilter(
        f, "atrousGetFilterBool", [&] { return f->getBool(name); }, false);
}

const char* atrousGetFilterString(AtrousFilter f, const char* name) {
    return onFilter(
        f, "atrousGetFilterString", [&] { return f->getString(name); },
        static_cast<const char*>(nullptr));
}

void atrousCommitFilter(AtrousFilter f) {
    onFilter(
        f, "atrousCommitFilter", [&] { return f->commit(), 0; }, 0);
}

void atrousExecuteFilter(AtrousFilter f) {
    onFilter(
        f, "atrousExecuteFilter", [&] { return f->execute(), 0; }, 0);
}

}  // extern "C"

// The C API's objects (include/atrous/atrous.h) behind its handles, in C++ over the public C++ API:
// a device (where filters run, and its error slot) and a filter (a method, its options, the
// borrowed images). src/capi/capi.cpp is the extern "C" layer that catches everything.
#pragma once
#include <atomic>
#include <mutex>
#include <string>

#include "atrous/atrous.h"
#include "atrous/denoise.h"
#include "atrous/image.h"

namespace atrous::capi {

// An error a call reports with its own code (InputError is ATROUS_ERROR_INVALID_ARGUMENT).
struct Failure {
    AtrousError code;
    std::string message;
};

// The images a filter borrows, by name: the frame's buffers, then the output.
enum Slot {
    kColor,
    kVariance,
    kAlbedo,
    kNormal,
    kPosition,
    kDepth,
    kIds,
    kEmission,
    kOutput,
    kSlots
};

}  // namespace atrous::capi

struct AtrousDeviceImpl {
    std::atomic<int> refs{1};
    atrous::Device device = atrous::Device::Cpu;

    // The first error since the last take(), and the text take() last handed out.
    void record(AtrousError code, const std::string& message);
    AtrousError take(const char** message);

  private:
    std::mutex mMutex;
    AtrousError mCode = ATROUS_ERROR_NONE;
    std::string mMessage, mReturned;
};

struct AtrousFilterImpl {
    std::atomic<int> refs{1};
    AtrousDeviceImpl* device = nullptr;  // one reference held
    atrous::DenoiseOptions options;

    // The borrowed images (StridedImage::data null = not set), as the filter reads them: already
    // narrowed to the channels a buffer takes (a FLOAT4 colour is its first three).
    atrous::StridedImage images[atrous::capi::kSlots];
    bool committed = false;
    bool ran = false;
    atrous::DenoiseReport report;  // the last execution's
    std::string text;              // atrousGetFilterString's last answer

    void setImage(const char* name, void* ptr, AtrousFormat format, size_t width, size_t height,
                  size_t byteOffset, size_t pixelByteStride, size_t rowByteStride);
    void unsetImage(const char* name);
    void setInt(const char* name, int value);
    void setFloat(const char* name, float value);
    void setBool(const char* name, bool value);
    void setString(const char* name, const char* value);
    int getInt(const char* name);
    float getFloat(const char* name);
    bool getBool(const char* name);
    const char* getString(const char* name);
    void commit();
    void execute();
};

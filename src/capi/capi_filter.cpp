// A C API filter (src/capi/capi_impl.h): its borrowed images, commit and execute. Every check that
// can fail runs before anything is written to the caller's output.
#include <algorithm>
#include <string>

#include "atrous/buffers.h"
#include "atrous/error.h"
#include "atrous/interop.h"
#include "capi/capi_impl.h"

using namespace atrous;
using atrous::capi::Failure;

namespace {

// How a slot takes an image with fewer channels than it wants: not at all, a grey image repeated
// into the three, or kept as it is (ids: the object id without a material id).
enum class One { No, Repeat, Keep };

struct SlotInfo {
    const char* name;
    Buffer buffer;
    int channels;  // what the filter reads; further channels of the caller's image are ignored
    One one;
};
// In capi::Slot's order. The output is written as RGB (a FLOAT4 output's alpha is left alone).
constexpr SlotInfo kSlotInfo[capi::kSlots] = {
    {"color", Buffer::Color, 3, One::Repeat},   {"variance", Buffer::Variance, 3, One::Repeat},
    {"albedo", Buffer::Albedo, 3, One::Repeat}, {"normal", Buffer::Normal, 3, One::No},
    {"position", Buffer::Position, 3, One::No}, {"depth", Buffer::Depth, 1, One::No},
    {"ids", Buffer::ObjectId, 2, One::Keep},    {"emission", Buffer::Emission, 3, One::Repeat},
    {"output", Buffer::Color, 3, One::No},
};

[[noreturn]] void invalid(const std::string& message) {
    throw Failure{ATROUS_ERROR_INVALID_ARGUMENT, message};
}

capi::Slot slotOf(const char* name) {
    if (!name) invalid("name is NULL");
    std::string names;
    for (int s = 0; s < capi::kSlots; ++s) {
        if (std::string(name) == kSlotInfo[s].name) return capi::Slot(s);
        names += std::string(s ? ", " : "") + kSlotInfo[s].name;
    }
    invalid(std::string("no image '") + name + "' (the names are " + names + ")");
}

struct FormatInfo {
    AtrousFormat format;
    DataType type;
    int channels;
    const char* name;
};
constexpr FormatInfo kFormats[] = {
    {ATROUS_FORMAT_FLOAT, DataType::Float32, 1, "FLOAT"},
    {ATROUS_FORMAT_FLOAT2, DataType::Float32, 2, "FLOAT2"},
    {ATROUS_FORMAT_FLOAT3, DataType::Float32, 3, "FLOAT3"},
    {ATROUS_FORMAT_FLOAT4, DataType::Float32, 4, "FLOAT4"},
    {ATROUS_FORMAT_HALF, DataType::Float16, 1, "HALF"},
    {ATROUS_FORMAT_HALF2, DataType::Float16, 2, "HALF2"},
    {ATROUS_FORMAT_HALF3, DataType::Float16, 3, "HALF3"},
    {ATROUS_FORMAT_HALF4, DataType::Float16, 4, "HALF4"},
};
const FormatInfo& formatInfo(AtrousFormat f) {
    for (const FormatInfo& i : kFormats)
        if (i.format == f) return i;
    invalid("format " + std::to_string(int(f)) + " is not an AtrousFormat");
}

// The channels of the planar image the filter makes of slot s's image.
int readChannels(capi::Slot s, const StridedImage& img) {
    return kSlotInfo[s].one == One::Keep ? img.channels : kSlotInfo[s].channels;
}

std::string sizeText(const StridedImage& s) {
    return std::to_string(s.width) + "x" + std::to_string(s.height);
}

}  // namespace

void AtrousFilterImpl::setImage(const char* name, void* ptr, AtrousFormat format, size_t width,
                                size_t height, size_t byteOffset, size_t pixelByteStride,
                                size_t rowByteStride) {
    committed = false;
    const capi::Slot s = slotOf(name);
    const SlotInfo& info = kSlotInfo[s];
    const FormatInfo& fmt = formatInfo(format);
    if (!ptr) invalid(std::string("ptr is NULL (\"") + name + "\")");
    const bool takes = fmt.channels >= info.channels || (fmt.channels == 1 && info.one != One::No);
    if (!takes)
        invalid(std::string("\"") + name + "\" needs " + std::to_string(info.channels) +
                " channels" + (info.one == One::Repeat ? " (or 1)" : "") + ", format " + fmt.name +
                " has " + std::to_string(fmt.channels));
    const size_t dim = size_t(kMaxImageDim);
    if (width < 1 || height < 1 || width > dim || height > dim)
        invalid(std::string("\"") + name + "\" is " + std::to_string(width) + "x" +
                std::to_string(height) + ": width and height must be in 1.." +
                std::to_string(kMaxImageDim));
    const size_t element = size_t(dataTypeBytes(fmt.type)), pixel = element * size_t(fmt.channels);
    const size_t px = pixelByteStride ? pixelByteStride : pixel;
    constexpr size_t kMaxStride = size_t(1) << 40;  // no image's; keeps the offsets below in range
    if (px < pixel)
        invalid("pixelByteStride " + std::to_string(px) + " is smaller than a " + fmt.name +
                " pixel (" + std::to_string(pixel) + " bytes)");
    if (px > kMaxStride) invalid("pixelByteStride " + std::to_string(px) + " is out of range");
    const size_t row = rowByteStride ? rowByteStride : px * width;
    if (row < px * width)
        invalid("rowByteStride " + std::to_string(row) + " is smaller than a row of " +
                std::to_string(width) + " pixels (" + std::to_string(px * width) + " bytes)");
    if (row > kMaxStride) invalid("rowByteStride " + std::to_string(row) + " is out of range");
    const char* data = static_cast<const char*>(ptr) + byteOffset;
    if (reinterpret_cast<uintptr_t>(data) % element || px % element || row % element)
        invalid(std::string("\"") + name +
                "\": ptr + byteOffset and the strides must be multiples of " +
                std::to_string(element) + " bytes (the " + fmt.name + " element)");
    StridedImage img;
    img.data = data, img.type = fmt.type, img.device = Device::Cpu;
    img.width = int(width), img.height = int(height),
    img.channels = std::min(fmt.channels, info.channels);
    img.pixelStride = int64_t(px), img.rowStride = int64_t(row),
    img.channelStride = int64_t(element);
    images[s] = img;
}

void AtrousFilterImpl::unsetImage(const char* name) {
    committed = false;
    images[slotOf(name)] = StridedImage{};
}

void AtrousFilterImpl::commit() {
    committed = false;
    const StridedImage& color = images[capi::kColor];
    for (capi::Slot s : {capi::kColor, capi::kOutput})
        if (!images[s].valid())
            throw Failure{ATROUS_ERROR_INVALID_OPERATION,
                          std::string("no \"") + kSlotInfo[s].name + "\" image was set"};
    for (int s = 0; s < capi::kSlots; ++s) {
        const StridedImage& img = images[s];
        if (img.valid() && (img.width != color.width || img.height != color.height))
            invalid(std::string("\"") + kSlotInfo[s].name + "\" is " + sizeText(img) +
                    " but \"color\" is " + sizeText(color));
    }
    validateDenoiseOptions(options);
    const DenoiseMethodInfo& m = denoiseMethodInfo(options.method);
    if (m.registered() && !(options.device == Device::Cuda ? m.cuda : m.cpu))
        throw Failure{ATROUS_ERROR_UNSUPPORTED_HARDWARE,
                      std::string("method '") + m.name + "' has no " +
                          (options.device == Device::Cuda ? "CUDA" : "CPU") + " path"};
    committed = true;
}

namespace {

// The one call into the library.
DenoiseResult runFilter(const Frame& frame, const DenoiseOptions& options) {
    return denoiseWithReport(frame, options);
}

}  // namespace

void AtrousFilterImpl::execute() {
    if (!committed)
        throw Failure{
            ATROUS_ERROR_INVALID_OPERATION,
            "the filter is not committed (call atrousCommitFilter after creating or changing it)"};
    // The caller's images as they are: denoise() reads the colour, variance and emission where
    // they are (converting them into its working planes) and copies the features it needs planar.
    Frame frame;
    for (int s = 0; s < capi::kOutput; ++s) {
        if (!images[s].valid()) continue;
        StridedImage img = images[s];
        img.channels = std::min(img.channels, readChannels(capi::Slot(s), images[s]));  // the first ones; one repeats
        frame.set(kSlotInfo[s].buffer, img);
    }
    DenoiseResult r = runFilter(frame, options);
    const Image out =
        r.image.device() == Device::Cpu ? std::move(r.image) : r.image.to(Device::Cpu);
    exportImage(out.view(), images[capi::kOutput], "output");
    report = std::move(r.report);
    ran = true;
}

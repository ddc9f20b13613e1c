// The C API (include/atrous/atrous.h) from C++, through the static library: its outputs equal
// denoise()'s on the same images bit for bit (every buffer, every built-in method, parameters set
// by name, grey and half inputs, padded and RGBA layouts); the devices, reference counts and the
// report; and bad input as an error code and a message naming the argument with the output left
// alone. tests/capi/c_denoise.c (ctest c_api_package) is the same API from a C program against the
// installed libatrous.so, compared with the CLI.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "atrous/atrous.h"
#include "atrous/denoise.h"
#include "atrous/interop.h"
#include "render_test_util.h"
#include "test_util.h"

namespace atrous {
namespace {

constexpr int kW = 32, kH = 24;

struct Rendered : test::RenderedInputs {
    Rendered() : RenderedInputs("cornell", kW, kH, 4, 3) {}
};
const Rendered& scene() {
    static const Rendered r;
    return r;
}

// An image as packed interleaved floats (H x W x C), and back.
std::vector<float> interleaved(const Image& img) {
    std::vector<float> v(img.size());
    exportImage(
        img.view(),
        interleavedImage(v.data(), DataType::Float32, img.width(), img.height(), img.channels()),
        "test");
    return v;
}
Image planar(const std::vector<float>& v, int channels) {
    return importImage(interleavedImage(v.data(), DataType::Float32, kW, kH, channels), channels,
                       "test");
}

AtrousFormat floatFormat(int channels) {
    return AtrousFormat(ATROUS_FORMAT_FLOAT + channels - 1);
}

std::string takeError(AtrousDevice d, AtrousError* code = nullptr) {
    const char* m = nullptr;
    const AtrousError e = atrousGetDeviceError(d, &m);
    if (code) *code = e;
    return e == ATROUS_ERROR_NONE ? std::string() : std::string(m);
}

// A CPU device and a filter of `method` with the given images set (interleaved copies it owns).
struct CFilter {
    AtrousDevice d = atrousNewDevice("cpu");
    AtrousFilter f = nullptr;
    std::vector<std::vector<float>> held;
    std::vector<float> out = std::vector<float>(size_t(kW) * kH * 3, -5.0f);

    explicit CFilter(const char* method) { f = atrousNewFilter(d, method); }
    ~CFilter() {
        atrousReleaseFilter(f);
        atrousReleaseDevice(d);
    }
    void set(const char* name, const Image* img) {
        if (!img || img->empty()) return;
        held.push_back(interleaved(*img));
        atrousSetFilterImage(f, name, held.back().data(), floatFormat(img->channels()), kW, kH, 0,
                             0, 0);
    }
    void setAll(const Frame& in) {
        set("color", in.color), set("variance", in.variance), set("albedo", in.albedo),
            set("normal", in.normal);
        set("position", in.position), set("depth", in.depth), set("ids", in.ids),
            set("emission", in.emission);
    }
    // Commits, executes and returns the output as a planar image; "" = no error.
    std::string execute(Image* result = nullptr) {
        atrousSetFilterImage(f, "output", out.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, 0, 0);
        atrousCommitFilter(f);
        atrousExecuteFilter(f);
        if (result) *result = planar(out, 3);
        return takeError(d);
    }
    bool outputUntouched() const {
        for (float v : out)
            if (v != -5.0f) return false;
        return true;
    }
};

Frame allBuffers() {
    const Rendered& r = scene();
    Frame in = r.inputs();
    in.position = &r.b.position, in.ids = &r.b.ids;
    return in;
}

TEST(CApi, EveryMethodWithEveryBufferEqualsDenoise) {
    for (const char* method :
         {"eaw", "sure", "learned", "blend", "auto", static_cast<const char*>(nullptr), ""}) {
        SCOPED_TRACE(method ? method : "(null)");
        CFilter run(method);
        run.setAll(allBuffers());
        Image got;
        ASSERT_EQ(run.execute(&got), "");
        DenoiseOptions o;
        o.method = method && *method ? parseDenoiseMethod(method) : DenoiseMethod::Auto;
        EXPECT_TRUE(test::sameImages(got, denoise(allBuffers(), o)));
        EXPECT_STREQ(atrousGetFilterString(run.f, "method"),
                     method && *method && std::string(method) != "auto" ? method : "blend");
        EXPECT_GT(atrousGetFilterFloat(run.f, "milliseconds"), 0.0f);
        EXPECT_EQ(takeError(run.d), "");
    }
}

TEST(CApi, ParametersByNameAndTheReport) {
    CFilter run("eaw");
    const Frame in = scene().inputs();
    run.set("color", in.color), run.set("albedo", in.albedo), run.set("normal", in.normal);
    atrousSetFilterInt(run.f, "levels", 3);
    atrousSetFilterFloat(run.f, "sigma_normal", 0.25f);
    atrousSetFilterBool(run.f, "firefly", false);
    atrousSetFilterInt(run.f, "color_scale", 4);  // an int for a float parameter
    atrousSetFilterInt(run.f, "demodulate", 0);   // 0 / 1 for a boolean
    atrousSetFilterString(run.f, "sure_mode", "james-stein");
    atrousSetFilterString(run.f, "sure_candidates", "0,0.5,1");
    Image got;
    ASSERT_EQ(run.execute(&got), "");
    DenoiseOptions o;
    o.method = DenoiseMethod::Eaw;
    o.eaw.levels = 3, o.eaw.sigmaNormal = 0.25f, o.firefly.enabled = false, o.eaw.colorScale = 4.0f,
    o.demodulate = false;
    o.sure.mode = SureMode::JamesStein, o.sure.candidates = {0.0f, 0.5f, 1.0f};
    Frame only;
    only.color = in.color, only.albedo = in.albedo, only.normal = in.normal;
    const DenoiseResult want = denoiseWithReport(only, o);
    EXPECT_TRUE(test::sameImages(got, want.image));
    EXPECT_EQ(atrousGetFilterInt(run.f, "levels"), 3);
    EXPECT_EQ(atrousGetFilterFloat(run.f, "sigma_normal"), 0.25f);
    EXPECT_EQ(atrousGetFilterFloat(run.f, "levels"), 3.0f);
    EXPECT_FALSE(atrousGetFilterBool(run.f, "firefly"));
    EXPECT_EQ(atrousGetFilterInt(run.f, "sure_mode"), 1);
    EXPECT_STREQ(atrousGetFilterString(run.f, "sure_mode"), "james-stein");
    EXPECT_STREQ(atrousGetFilterString(run.f, "sure_candidates"), "0,0.5,1");
    EXPECT_STREQ(atrousGetFilterString(run.f, "buffers"), want.report.buffersUsed.c_str());
    EXPECT_TRUE(atrousGetFilterBool(run.f, "noise_estimated"));
    EXPECT_EQ(atrousGetFilterInt(run.f, "nonfinite_pixels"), want.report.nonFinitePixels);
    EXPECT_EQ(atrousGetFilterInt(run.f, "fireflies_clamped"), 0);
    EXPECT_EQ(takeError(run.d), "");
    // The wrong kind, an unknown name, a report before any run: errors naming them.
    AtrousError code;
    atrousSetFilterFloat(run.f, "levels", 2.5f);
    EXPECT_NE(takeError(run.d, &code).find("parameter levels is an integer"), std::string::npos);
    EXPECT_EQ(code, ATROUS_ERROR_INVALID_ARGUMENT);
    atrousSetFilterBool(run.f, "levels", true);
    EXPECT_NE(takeError(run.d).find("levels"), std::string::npos);
    atrousSetFilterInt(run.f, "firefly", 2);
    EXPECT_NE(takeError(run.d).find("firefly is a boolean: 0 or 1 (got 2)"), std::string::npos);
    atrousSetFilterString(run.f, "sure_mode", "best");
    EXPECT_NE(takeError(run.d).find("sure_mode"), std::string::npos);
    atrousSetFilterString(run.f, "sure_candidates", "0,0,0,0,0,0,0,0,0");
    EXPECT_NE(takeError(run.d).find("sure_candidates must list 1..8 values"), std::string::npos);
    EXPECT_EQ(atrousGetFilterInt(run.f, "sigmas"), 0);
    EXPECT_NE(takeError(run.d).find("no parameter 'sigmas'"), std::string::npos);
    EXPECT_EQ(atrousGetFilterInt(run.f, "levels"), 3) << "a refused value was set";
    EXPECT_STREQ(atrousGetFilterString(run.f, "sure_candidates"), "0,0.5,1");
    CFilter fresh("eaw");
    EXPECT_EQ(atrousGetFilterFloat(fresh.f, "milliseconds"), 0.0f);
    EXPECT_NE(takeError(fresh.d, &code).find("'milliseconds' is known after atrousExecuteFilter"),
              std::string::npos);
    EXPECT_EQ(code, ATROUS_ERROR_INVALID_OPERATION);
    EXPECT_STREQ(atrousGetFilterString(fresh.f, "method"), "eaw");
}

// Half inputs are their values exactly: the same output as denoise() of those values in float.
TEST(CApi, HalfGreyAndNarrowedInputsAreTheirValues) {
    const Frame in = scene().inputs();
    auto quantised = [](const Image& img) {
        std::vector<uint16_t> h(img.size());
        exportImage(img.view(),
                    interleavedImage(h.data(), DataType::Float16, kW, kH, img.channels()), "q");
        return std::make_pair(
            h, importImage(interleavedImage(h.data(), DataType::Float16, kW, kH, img.channels()),
                           img.channels(), "q"));
    };
    auto [hc, qc] = quantised(*in.color);
    auto [hn, qn] = quantised(*in.normal);
    // A grey albedo (FLOAT, repeated into RGB) and the depth as the first channel of a FLOAT4.
    Image grey(kW, kH, 1);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) grey(x, y, 0) = in.albedo->operator()(x, y, 1);
    std::vector<float> greyData = interleaved(grey);
    std::vector<float> depth4(size_t(kW) * kH * 4, 123.0f);
    for (int i = 0; i < kW * kH; ++i) depth4[size_t(i) * 4] = in.depth->data()[i];
    CFilter run("sure");
    atrousSetFilterImage(run.f, "color", hc.data(), ATROUS_FORMAT_HALF3, kW, kH, 0, 0, 0);
    atrousSetFilterImage(run.f, "normal", hn.data(), ATROUS_FORMAT_HALF3, kW, kH, 0, 0, 0);
    atrousSetFilterImage(run.f, "albedo", greyData.data(), ATROUS_FORMAT_FLOAT, kW, kH, 0, 0, 0);
    atrousSetFilterImage(run.f, "depth", depth4.data(), ATROUS_FORMAT_FLOAT4, kW, kH, 0, 0, 0);
    Image got;
    ASSERT_EQ(run.execute(&got), "");
    const Image grey3 = importImage(grey.strided(), 3, "grey");
    Image depth1(kW, kH, 1);
    std::memcpy(depth1.data(), in.depth->data(), depth1.size() * sizeof(float));
    Frame q;
    q.color = &qc, q.normal = &qn, q.albedo = &grey3, q.depth = &depth1;
    DenoiseOptions o;
    o.method = DenoiseMethod::Sure;
    EXPECT_TRUE(test::sameImages(got, denoise(q, o)));
}

// Padded rows and pixels in, an RGBA output with padded rows (alpha and padding left alone), a
// half output within half an ulp of the float one, the output in the colour's own memory.
TEST(CApi, LayoutsAndInPlace) {
    const Frame in = scene().inputs();
    CFilter ref("eaw");
    ref.set("color", in.color), ref.set("albedo", in.albedo);
    Image want;
    ASSERT_EQ(ref.execute(&want), "");

    const std::vector<float> c = interleaved(*in.color);
    const size_t pixel = 5, row = size_t(kW) * pixel + 3;  // floats: RGB + 2 spare, 3 spare per row
    std::vector<float> padded(row * kH, 99.0f);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            std::memcpy(&padded[y * row + x * pixel], &c[(size_t(y) * kW + x) * 3], 12);
    const size_t orow = size_t(kW) * 4 + 2;
    std::vector<float> rgba(orow * kH + 1, -1.0f);  // + 1: the output starts at byte 4 (byteOffset)
    CFilter run("eaw");
    run.set("albedo", in.albedo);
    atrousSetFilterImage(run.f, "color", padded.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, pixel * 4,
                         row * 4);
    atrousSetFilterImage(run.f, "output", rgba.data(), ATROUS_FORMAT_FLOAT4, kW, kH, 4, 0,
                         orow * 4);
    atrousCommitFilter(run.f);
    atrousExecuteFilter(run.f);
    ASSERT_EQ(takeError(run.d), "");
    EXPECT_EQ(rgba[0], -1.0f);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const float* p = &rgba[1 + y * orow + x * 4];
            for (int k = 0; k < 3; ++k) ASSERT_EQ(p[k], want(x, y, k)) << x << "," << y;
            ASSERT_EQ(p[3], -1.0f);
        }
    EXPECT_EQ(rgba[1 + orow - 1], -1.0f);

    // HALF3 out: half an ulp of the float output at most (2^-11 relative, 2^-25 below 2^-14).
    std::vector<uint16_t> h(size_t(kW) * kH * 3);
    atrousSetFilterImage(run.f, "color", padded.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, pixel * 4,
                         row * 4);
    atrousSetFilterImage(run.f, "output", h.data(), ATROUS_FORMAT_HALF3, kW, kH, 0, 0, 0);
    atrousCommitFilter(run.f);
    atrousExecuteFilter(run.f);
    ASSERT_EQ(takeError(run.d), "");
    const Image half =
        importImage(interleavedImage(h.data(), DataType::Float16, kW, kH, 3), 3, "half");
    for (size_t i = 0; i < half.size(); ++i)
        ASSERT_LE(std::fabs(half.data()[i] - want.data()[i]),
                  std::ldexp(std::fabs(want.data()[i]), -11) + std::ldexp(1.0f, -25));

    // In place: the output is the colour's memory.
    std::vector<float> same = c;
    CFilter inPlace("eaw");
    inPlace.set("albedo", in.albedo);
    atrousSetFilterImage(inPlace.f, "color", same.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, 0, 0);
    atrousSetFilterImage(inPlace.f, "output", same.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, 0, 0);
    atrousCommitFilter(inPlace.f);
    atrousExecuteFilter(inPlace.f);
    ASSERT_EQ(takeError(inPlace.d), "");
    EXPECT_TRUE(test::sameImages(planar(same, 3), want));
}

TEST(CApi, DevicesAndReferences) {
    for (const char* t : {"cpu", "default", "", static_cast<const char*>(nullptr)}) {
        AtrousDevice d = atrousNewDevice(t);
        ASSERT_NE(d, nullptr) << (t ? t : "(null)");
        EXPECT_STREQ(atrousGetDeviceType(d),
                     t && std::string(t) == "cpu" ? "cpu" : (cudaAvailable() ? "cuda" : "cpu"));
        atrousReleaseDevice(d);
    }
    AtrousError code;
    EXPECT_EQ(atrousNewDevice("gpu"), nullptr);
    EXPECT_NE(takeError(nullptr, &code).find("atrousNewDevice: type \"gpu\" is not a device"),
              std::string::npos);
    EXPECT_EQ(code, ATROUS_ERROR_INVALID_ARGUMENT);
    if (!cudaAvailable()) {
        EXPECT_EQ(atrousNewDevice("cuda"), nullptr);
        EXPECT_NE(takeError(nullptr, &code).find("cuda"), std::string::npos);
        EXPECT_EQ(code, ATROUS_ERROR_UNSUPPORTED_HARDWARE);
    }
    EXPECT_EQ(takeError(nullptr), "") << "reading an error clears it";
    // A filter keeps its device: the device released first, the filter still runs and reports.
    const Frame in = scene().inputs();
    AtrousDevice d = atrousNewDevice("cpu");
    AtrousFilter f = atrousNewFilter(d, "eaw");
    atrousRetainFilter(f);
    atrousReleaseFilter(f);
    atrousRetainDevice(d);
    atrousReleaseDevice(d);
    std::vector<float> c = interleaved(*in.color), out(c.size());
    atrousSetFilterImage(f, "color", c.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, 0, 0);
    atrousSetFilterImage(f, "output", out.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, 0, 0);
    atrousSetFilterInt(f, "levels", 0);  // an error recorded on the device the filter holds
    atrousReleaseDevice(d);
    atrousCommitFilter(f);
    atrousExecuteFilter(f);
    EXPECT_GT(atrousGetFilterFloat(f, "milliseconds"), 0.0f);
    atrousReleaseFilter(f);
    atrousReleaseFilter(nullptr);  // nothing, as free(NULL)
    atrousReleaseDevice(nullptr);
    EXPECT_EQ(takeError(nullptr), "");
    atrousRetainDevice(nullptr);
    EXPECT_NE(takeError(nullptr).find("atrousRetainDevice: device is NULL"), std::string::npos);
}

// A committed eaw filter with a colour and the output.
void committed(CFilter& run) {
    run.set("color", scene().inputs().color);
    atrousSetFilterImage(run.f, "output", run.out.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, 0, 0);
    atrousCommitFilter(run.f);
}

// The error that came: its code and message, then the filter refusing to run (it is no longer
// committed) and the output untouched.
void expectRefused(CFilter& run, AtrousError want, const std::string& message) {
    AtrousError code;
    const std::string m = takeError(run.d, &code);
    EXPECT_EQ(code, want) << m;
    EXPECT_NE(m.find(message), std::string::npos) << m;
    atrousExecuteFilter(run.f);
    EXPECT_EQ(takeError(run.d, &code).find("atrousExecuteFilter: the filter is not committed"), 0u);
    EXPECT_EQ(code, ATROUS_ERROR_INVALID_OPERATION);
    EXPECT_TRUE(run.outputUntouched());
}

// Each bad call: its code, a message naming the function and the argument, the first error kept
// until read, and the output untouched (the filter refuses to run until committed again).
TEST(CApi, BadInputIsAnErrorAndWritesNothing) {
    const Frame in = scene().inputs();
    std::vector<float> albedo = interleaved(*in.albedo);
    struct ImageCase {
        const char* name;
        AtrousFormat format;
        size_t width, byteOffset, pixelByteStride;
        const char* message;
    };
    const size_t huge = size_t(1) << 50;
    const ImageCase cases[] = {
        {nullptr, ATROUS_FORMAT_FLOAT3, kW, 0, 0, "atrousSetFilterImage: name is NULL"},
        {"motion", ATROUS_FORMAT_FLOAT2, kW, 0, 0,
         "no image 'motion' (the names are color, variance"},
        {"albedo", AtrousFormat(77), kW, 0, 0, "format 77 is not an AtrousFormat"},
        {"albedo", ATROUS_FORMAT_HALF2, kW, 0, 0,
         "\"albedo\" needs 3 channels (or 1), format HALF2 has 2"},
        {"albedo", ATROUS_FORMAT_FLOAT3, kW, 2, 0, "must be multiples of 4 bytes"},
        {"albedo", ATROUS_FORMAT_FLOAT3, 0, 0, 0, "\"albedo\" is 0x24"},
        {"albedo", ATROUS_FORMAT_FLOAT3, kW, 0, huge,
         "pixelByteStride 1125899906842624 is out of range"},
    };
    for (const ImageCase& c : cases) {
        SCOPED_TRACE(c.message);
        CFilter run("eaw");
        committed(run);
        atrousSetFilterImage(run.f, c.name, albedo.data(), c.format, c.width, kH, c.byteOffset,
                             c.pixelByteStride, 0);
        expectRefused(run, ATROUS_ERROR_INVALID_ARGUMENT, c.message);
    }
    {
        CFilter run("eaw");
        committed(run);
        atrousUnsetFilterImage(run.f, "color");
        atrousCommitFilter(run.f);
        expectRefused(run, ATROUS_ERROR_INVALID_OPERATION,
                      "atrousCommitFilter: no \"color\" image was set");
    }
    {
        CFilter run("eaw");
        committed(run);
        atrousSetFilterInt(run.f, "sure_window", 0);
        atrousSetFilterInt(run.f, "levels", 0);
        expectRefused(run, ATROUS_ERROR_INVALID_ARGUMENT,
                      "atrousSetFilterInt: parameter sure_window must be in 1..10 (got 0)");
    }
    // A registered method with a CUDA cascade only: committing it on the CPU is unsupported
    // hardware.
    DenoiseMethodInfo gpuOnly;
    gpuOnly.name = "capi-gpu-only";
    gpuOnly.cuda = [](const PreparedView&, const DenoiseOptions&, const ImageView&) {};
    registerDenoiseMethod(gpuOnly);
    CFilter run("capi-gpu-only");
    run.set("color", in.color);
    AtrousError code;
    EXPECT_NE(run.execute().find("atrousCommitFilter: method 'capi-gpu-only' has no CPU path"),
              std::string::npos);
    atrousExecuteFilter(run.f);
    takeError(run.d, &code);
    EXPECT_EQ(code, ATROUS_ERROR_INVALID_OPERATION);
    EXPECT_TRUE(run.outputUntouched());
    // A NULL filter: the error of this thread's calls without a device.
    atrousCommitFilter(nullptr);
    EXPECT_EQ(takeError(nullptr, &code), "atrousCommitFilter: filter is NULL");
    EXPECT_EQ(code, ATROUS_ERROR_INVALID_ARGUMENT);
    EXPECT_EQ(atrousNewFilter(nullptr, "eaw"), nullptr);
    EXPECT_EQ(takeError(nullptr), "atrousNewFilter: device is NULL");
}

TEST(CApi, OnACudaDeviceTheSameAsDenoiseOnCuda) {
    if (!cudaAvailable()) GTEST_SKIP() << "no usable CUDA device";
    AtrousDevice d = atrousNewDevice("cuda");
    ASSERT_NE(d, nullptr);
    EXPECT_STREQ(atrousGetDeviceType(d), "cuda");
    const Frame in = scene().inputs();
    AtrousFilter f = atrousNewFilter(d, "eaw");
    std::vector<float> c = interleaved(*in.color), a = interleaved(*in.albedo), out(c.size());
    atrousSetFilterImage(f, "color", c.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, 0, 0);
    atrousSetFilterImage(f, "albedo", a.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, 0, 0);
    atrousSetFilterImage(f, "output", out.data(), ATROUS_FORMAT_FLOAT3, kW, kH, 0, 0, 0);
    atrousCommitFilter(f);
    atrousExecuteFilter(f);
    EXPECT_EQ(takeError(d), "");
    Frame only;
    only.color = in.color, only.albedo = in.albedo;
    DenoiseOptions o;
    o.method = DenoiseMethod::Eaw, o.device = Device::Cuda;
    EXPECT_TRUE(test::sameImages(planar(out, 3), denoise(only, o).to(Device::Cpu)));
    atrousReleaseFilter(f);
    atrousReleaseDevice(d);
}

}  // namespace
}  // namespace atrous

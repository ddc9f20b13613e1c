// A small program built against the installed atrous library (docs/cpp.md): reads a noisy colour
// image and optional feature buffers, denoises it with SURE-based À-Trous (or EAW), writes the
// result and prints what the filter did.
//
//   denoise_exr COLOR OUT [--variance F] [--albedo F] [--normal F] [--position F]
//               [--emission F] [--method sure|eaw] [--device cpu|cuda|auto]
//
// Files may be EXR, PFM or PNG (by extension). Exit code 0 on success, 2 on bad input (the message
// names the file or flag) with nothing written.
#include <atrous/denoise.h>
#include <atrous/device.h>
#include <atrous/error.h>
#include <atrous/io.h>

#include <cstdio>
#include <exception>
#include <map>
#include <string>

namespace {

void usage() {
    std::fprintf(
        stderr,
        "usage: denoise_exr COLOR OUT [--variance F] [--albedo F] [--normal F] [--position F]\n"
        "                   [--emission F] [--method sure|eaw] [--device cpu|cuda|auto]\n");
}

}  // namespace

int main(int argc, char** argv) {
    std::string colorPath, outPath, method = "sure", device = "cpu";
    std::map<std::string, std::string> buffers;  // flag name (without --) -> file
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg.rfind("--", 0) == 0) {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "denoise_exr: %s needs a value\n", arg.c_str());
                return 2;
            }
            const std::string name = arg.substr(2), value = argv[++i];
            if (name == "method")
                method = value;
            else if (name == "device")
                device = value;
            else if (name == "variance" || name == "albedo" || name == "normal" ||
                     name == "position" || name == "emission")
                buffers[name] = value;
            else {
                std::fprintf(stderr, "denoise_exr: unknown option %s\n", arg.c_str());
                usage();
                return 2;
            }
        } else if (colorPath.empty()) {
            colorPath = arg;
        } else if (outPath.empty()) {
            outPath = arg;
        } else {
            usage();
            return 2;
        }
    }
    if (colorPath.empty() || outPath.empty()) {
        usage();
        return 2;
    }

    try {
        // Everything is read and checked before the output is written (writeImage is atomic).
        atrous::DenoiseOptions options;
        options.method = atrous::parseDenoiseMethod(method);  // InputError for another word
        options.device = atrous::parseDevice(device);         // "auto": CUDA when a GPU is usable

        const atrous::Image color = atrous::readImage(colorPath);
        std::map<std::string, atrous::Image> images;
        for (const auto& [name, path] : buffers) images[name] = atrous::readImage(path);
        auto find = [&](const char* name) -> const atrous::Image* {
            auto it = images.find(name);
            return it == images.end() ? nullptr : &it->second;
        };
        atrous::Frame inputs;
        inputs.color = &color;
        inputs.variance = find("variance");
        inputs.albedo = find("albedo");
        inputs.normal = find("normal");
        inputs.position = find("position");
        inputs.emission = find("emission");  // a visible light is filtered apart (denoising.md)

        // Throws InputError for sizes that do not match the colour's or a negative variance.
        // denoiseWithReport: the image and what the run did (atrous::denoise gives the image alone).
        const atrous::DenoiseResult result = atrous::denoiseWithReport(inputs, options);
        const atrous::DenoiseReport& report = result.report;
        atrous::writeImage(outPath, result.image);

        std::printf("denoised %s (%dx%d) with %s on %s, buffers: %s\n", colorPath.c_str(),
                    color.width(), color.height(), atrous::denoiseMethodName(options.method),
                    atrous::deviceName(options.device).c_str(), report.buffersUsed.c_str());
        if (report.noiseEstimated)
            std::printf("no usable variance: noise sigma estimated as %.4g %.4g %.4g\n",
                        report.noiseSigma[0], report.noiseSigma[1], report.noiseSigma[2]);
        std::printf("fireflies clamped: %d, non-finite pixels: %d\n", report.firefliesClamped,
                    report.nonFinitePixels);
        std::printf("filter time %.2f ms:", report.milliseconds);
        for (const atrous::StageTime& s : report.stages)
            std::printf(" %s %.2f", s.name.c_str(), s.milliseconds);
        std::printf("\nwrote %s\n", outPath.c_str());
        return 0;
    } catch (const std::exception& e) {  // atrous::InputError (bad input), atrous::RuntimeError
        std::fprintf(stderr, "denoise_exr: error: %s\n", e.what());
        return 2;
    }
}

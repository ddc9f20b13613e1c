// `atrous compare`: MSE, relMSE, tonemapped PSNR and SSIM of images against a reference.
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atrous/error.h"
#include "atrous/metrics.h"
#include "commands.h"
#include "io/image_io.h"
#include "io/paths.h"

namespace atrous::cli {

namespace {

struct CompareArgs {
    std::string ref, errorMaps;
    std::vector<std::string> images;
    bool json = false;
};

void run(const CompareArgs& a) {
    if (a.images.empty()) throw InputError("compare: give at least one image to compare with --ref");
    if (!a.errorMaps.empty()) {
        // The error maps never overwrite an image being compared (io/paths.h).
        std::vector<std::string> inputs = a.images;
        inputs.push_back(a.ref);
        for (const std::string& img : a.images)
            for (const char* suffix : {"_se.exr", "_relse.exr"})
                io::refuseOverwrite("--error-maps",
                                    (std::filesystem::path(a.errorMaps) / (std::filesystem::path(img).stem().string() + suffix)).string(),
                                    inputs);
        io::ensureWritableDirectory(a.errorMaps);
    }
    // PNG is an 8-bit, clamped, display-encoded preview: accepted (LDR images can be compared), but
    // the figures are then not of the HDR radiance the metrics are meant for.
    // Notes go to stderr once every image is read: bad input stays one line there.
    std::vector<std::string> notes;
    auto notePng = [&](const std::string& p) {
        std::string ext = std::filesystem::path(p).extension().string();
        for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
        if (ext == ".png") notes.push_back("note: " + p + " is an 8-bit PNG preview, compared as its [0,1] values, not HDR radiance");
    };
    notePng(a.ref);
    Image ref = io::readImage(a.ref);
    std::vector<ImageMetrics> ms;
    std::vector<Image> imgs;
    for (const auto& p : a.images) {
        notePng(p);
        imgs.push_back(io::readImage(p));
        try {
            ms.push_back(computeMetrics(imgs.back(), ref));
        } catch (const InputError& e) {
            throw InputError("'" + p + "' vs reference '" + a.ref + "': " + e.what());
        }
        const ImageMetrics& m = ms.back();
        if (m.nonFinitePixels > 0)
            notes.push_back("note: " + p + " has " + std::to_string(m.nonFinitePixels) + " non-finite (NaN/Inf) pixels, counted as 0");
    }
    if (!ms.empty() && ms.front().referenceNonFinitePixels > 0)
        notes.push_back("note: reference " + a.ref + " has " + std::to_string(ms.front().referenceNonFinitePixels) +
                        " non-finite (NaN/Inf) pixels, counted as 0");
    for (const std::string& n : notes) std::fprintf(stderr, "%s\n", n.c_str());
    if (!a.errorMaps.empty()) {
        for (size_t i = 0; i < imgs.size(); ++i) {
            const std::string stem = std::filesystem::path(a.images[i]).stem().string();
            io::writeImage((std::filesystem::path(a.errorMaps) / (stem + "_se.exr")).string(), squaredErrorMap(imgs[i], ref));
            io::writeImage((std::filesystem::path(a.errorMaps) / (stem + "_relse.exr")).string(),
                           relativeErrorMap(imgs[i], ref));
        }
    }
    if (a.json) {
        nlohmann::json j;
        j["reference"] = a.ref;
        j["images"] = nlohmann::json::array();
        for (size_t i = 0; i < ms.size(); ++i)
            j["images"].push_back({{"path", a.images[i]},
                                   {"mse", ms[i].mse},
                                   {"relmse", ms[i].relMse},
                                   {"psnr", ms[i].psnr},
                                   {"ssim", ms[i].ssim},
                                   {"non_finite_pixels", ms[i].nonFinitePixels}});
        j["reference_non_finite_pixels"] = ms.empty() ? 0 : ms.front().referenceNonFinitePixels;
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("%-40s %14s %14s %10s %8s\n", "image", "MSE", "relMSE", "PSNR(dB)", "SSIM");
        for (size_t i = 0; i < ms.size(); ++i)
            std::printf("%-40s %14.6g %14.6g %10.3f %8.4f\n", a.images[i].c_str(), ms[i].mse, ms[i].relMse, ms[i].psnr,
                        ms[i].ssim);
    }
}

}  // namespace

void addCompareCommand(CLI::App& app) {
    auto a = std::make_shared<CompareArgs>();
    auto* cmd = app.add_subcommand("compare", "Compare images against a reference (MSE, relMSE, PSNR, SSIM)");
    cmd->add_option("--ref", a->ref, "Reference image (EXR/PFM)")->required();
    cmd->add_option("images", a->images, "Images to compare");
    cmd->add_flag("--json", a->json, "Print JSON");
    cmd->add_option("--error-maps", a->errorMaps, "Write <name>_se.exr and <name>_relse.exr error maps into DIR");
    cmd->callback([a] { run(*a); });
}

}  // namespace atrous::cli

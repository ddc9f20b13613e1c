// `atrous compare`: MSE, relMSE, tonemapped PSNR and SSIM of images against a reference; with
// --sequence, of denoised sequences against a reference sequence, with the temporal metrics.
#include <algorithm>
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
#include "io/sequence.h"

namespace atrous::cli {

namespace {

struct CompareArgs {
    std::string ref, errorMaps, sequence;
    std::vector<std::string> images;
    bool json = false;
};

// The frames of a sequence by number: a reference frame's reference.exr when it has one (`atrous
// render --frames --reference-spp`), else its colour (frame_NNNN.exr as `denoise --sequence` writes
// them, or any layout --sequence reads).
std::vector<std::pair<int, Image>> sequenceImages(const std::string& dir, bool preferReference) {
    std::vector<std::pair<int, Image>> out;
    for (const std::string& frame : io::listSequenceFrames(dir)) {
        io::SequenceFrame f = io::loadSequenceFrame(frame);
        out.emplace_back(f.index, preferReference && !f.reference.empty() ? std::move(f.reference) : std::move(f.color));
    }
    return out;
}

void runSequence(const CompareArgs& a) {
    if (!a.ref.empty() || !a.errorMaps.empty())
        throw InputError("--sequence REF_DIR: compares sequences; --ref and --error-maps are for images");
    if (a.images.empty()) throw InputError("compare --sequence REF_DIR: give at least one sequence directory to compare");
    const auto ref = sequenceImages(a.sequence, true);
    nlohmann::json j;
    j["reference"] = a.sequence;
    j["sequences"] = nlohmann::json::array();
    if (!a.json)
        std::printf("%-32s %7s %14s %10s %8s %14s %10s\n", "sequence", "frames", "relMSE", "PSNR(dB)", "SSIM", "temporal relMSE",
                    "tPSNR(dB)");
    for (const std::string& dir : a.images) {
        const auto seq = sequenceImages(dir, false);
        // The frames are matched by number: the same numbers in both, or one line naming the first that is not.
        for (size_t i = 0; i < std::max(seq.size(), ref.size()); ++i) {
            if (i >= seq.size() || i >= ref.size() || seq[i].first != ref[i].first) {
                const bool inRef = i < ref.size() && (i >= seq.size() || ref[i].first < seq[i].first);
                const int n = inRef ? ref[i].first : seq[i].first;
                throw InputError(dir + ": frame " + std::to_string(n) + (inRef ? " is missing (the reference " + a.sequence + " has it)"
                                                                             : " has no reference frame in " + a.sequence));
            }
        }
        double rel = 0, psnr = 0, ssim = 0, trel = 0, tpsnr = 0;
        for (size_t i = 0; i < seq.size(); ++i) {
            ImageMetrics m;
            try {
                m = computeMetrics(seq[i].second, ref[i].second);
                if (i > 0) {
                    const TemporalMetrics t = computeTemporalMetrics(seq[i].second, seq[i - 1].second, ref[i].second, ref[i - 1].second);
                    trel += t.relMse, tpsnr += t.psnr;
                }
            } catch (const InputError& e) {
                throw InputError(dir + ": frame " + std::to_string(seq[i].first) + " vs the reference's: " + e.what());
            }
            rel += m.relMse, psnr += m.psnr, ssim += m.ssim;
        }
        const double n = double(seq.size()), steps = std::max(1.0, n - 1.0);
        nlohmann::json s = {{"path", dir},           {"frames", seq.size()},       {"relmse", rel / n},
                            {"psnr", psnr / n},      {"ssim", ssim / n},           {"temporal_relmse", trel / steps},
                            {"tpsnr", tpsnr / steps}};
        if (a.json)
            j["sequences"].push_back(s);
        else
            std::printf("%-32s %7zu %14.6g %10.3f %8.4f %14.6g %10.3f\n", dir.c_str(), seq.size(), rel / n, psnr / n, ssim / n,
                        trel / steps, tpsnr / steps);
    }
    if (a.json) std::printf("%s\n", j.dump(2).c_str());
}

void run(const CompareArgs& a) {
    if (!a.sequence.empty()) return runSequence(a);
    if (a.ref.empty()) throw InputError("compare: give the reference image with --ref (or --sequence REF_DIR for sequences)");
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
    auto* cmd = app.add_subcommand("compare", "Compare images against a reference (MSE, relMSE, PSNR, SSIM), or sequences "
                                              "against a reference sequence (with temporal relMSE and tPSNR)");
    cmd->add_option("--ref", a->ref, "Reference image (EXR/PFM)");
    cmd->add_option("--sequence", a->sequence,
                    "Reference sequence (any layout --sequence reads; a frame's reference.exr when it has one): the "
                    "positional arguments are then sequences to compare with it (denoise --sequence's output "
                    "folders), frame by frame, with the temporal relMSE and tPSNR of frame-to-frame differences "
                    "(docs/eval.md)");
    cmd->add_option("images", a->images, "Images (or, with --sequence, sequence directories) to compare");
    cmd->add_flag("--json", a->json, "Print JSON");
    cmd->add_option("--error-maps", a->errorMaps, "Write <name>_se.exr and <name>_relse.exr error maps into DIR");
    cmd->callback([a] { run(*a); });
}

}  // namespace atrous::cli

// `atrous compare`: MSE, relMSE, tonemapped PSNR and SSIM of images against a reference; with
// --sequence, of denoised sequences against a reference sequence, with the temporal metrics and
// (where they are installed) HDR-FLIP and ColorVideoVDP; without a reference sequence, the
// reference-free flicker measure (compare_flicker.h).
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "atrous/error.h"
#include "atrous/metrics.h"
#include "commands.h"
#include "compare_flicker.h"
#include "progress.h"
#include "atrous/io/staged_dir.h"
#include "atrous/io/image_io.h"
#include "atrous/io/paths.h"
#include "atrous/io/sequence.h"

namespace atrous::cli {

namespace fs = std::filesystem;

namespace {

struct CompareArgs {
    std::string ref, errorMaps, sequence, video;
    std::string input;  // --input: the sequence whose motion places the frames for the flicker measure
    std::vector<std::string> images;
    bool json = false;
    bool noFlip = false, noCvvdp = false;
    bool noReference = false;
};

// Runs a shell command, returns what it printed (stdout; the caller adds 2>&1), its status in *rc.
std::string runCommand(const std::string& cmd, int* rc = nullptr) {
    std::string out;
    if (FILE* f = ::popen(cmd.c_str(), "r")) {
        char buf[512];
        while (std::fgets(buf, sizeof buf, f)) out += buf;
        const int status = ::pclose(f);
        if (rc) *rc = status;
    } else if (rc) {
        *rc = -1;
    }
    return out;
}

// The frames as EXR files for the external metrics (FLIP, ColorVideoVDP), in one temporary folder
// named for this process, removed with the object: each reference frame written once, each
// sequence's frames once (the next sequence's replace them).
class FrameFiles {
public:
    FrameFiles() {
        mDir = fs::temp_directory_path() / ("atrous-compare-" + std::to_string(::getpid()));
        std::error_code ec;
        fs::remove_all(mDir, ec);
        fs::create_directories(mDir, ec);
        if (ec) throw RuntimeError(mDir.string() + ": cannot create (" + ec.message() + ")");
    }
    ~FrameFiles() {
        std::error_code ec;
        fs::remove_all(mDir, ec);
    }
    FrameFiles(const FrameFiles&) = delete;
    FrameFiles& operator=(const FrameFiles&) = delete;
    const fs::path& dir() const { return mDir; }
    // The reference's frame `index` (written the first time) and the sequence's (written now).
    std::pair<std::string, std::string> frame(int index, const Image& ref, const Image& test) const {
        const std::string r = (mDir / ("ref_" + std::to_string(index) + ".exr")).string();
        const std::string t = (mDir / ("test_" + std::to_string(index) + ".exr")).string();
        if (!fs::exists(r)) atrous::writeImage(r, ref);
        atrous::writeImage(t, test);
        return {r, t};
    }

private:
    fs::path mDir;
};

// HDR-FLIP (NVIDIA's FLIP, the `flip` command of PyPI's flip-evaluator, which `make python` puts in
// .venv/bin) of a frame against the reference's, when `flip` is on PATH and says it is FLIP (`flip
// -h`; Debian has a line-ending converter of that name): `flip -r REF -t TEST -v 1` on the
// frames' files (FrameFiles), its "Mean: x" read.
// Off (enabled() false) when there is no such `flip`, or with --no-flip; a frame it fails on
// gives no value (nullopt) and one note on stderr, and the other metrics go on.
class FlipRunner {
public:
    explicit FlipRunner(bool wanted) {
        if (wanted) mExe = io::findOnPath("flip");
        if (!mExe.empty() && runCommand(io::shellQuote(mExe) + " -h 2>&1").find("FLIP") == std::string::npos) {
            logLine("note: no FLIP column: %s is not NVIDIA's FLIP (pip install flip-evaluator)\n",
                         mExe.c_str());
            mExe.clear();
            mNoted = true;
        }
    }
    bool enabled() const { return !mExe.empty(); }
    bool noted() const { return mNoted; }

    // refPath, testPath: the frame's files; `dir` takes FLIP's own outputs (none with -nerm -nexm).
    std::optional<double> frame(int index, const std::string& refPath, const std::string& testPath, const fs::path& dir) {
        int rc = 0;
        const std::string out = runCommand(io::shellQuote(mExe) + " -r " + io::shellQuote(refPath) + " -t " +
                                           io::shellQuote(testPath) + " -v 1 -nerm -nexm -d " + io::shellQuote(dir.string()) +
                                           " 2>&1", &rc);
        const size_t at = out.find("Mean:");
        if (rc == 0 && at != std::string::npos) return std::strtod(out.c_str() + at + 5, nullptr);
        logLine("note: FLIP (%s) failed on frame %d: %s\n", mExe.c_str(), index, out.substr(0, 200).c_str());
        return std::nullopt;
    }

private:
    std::string mExe;
    bool mNoted = false;
};

// ColorVideoVDP (PyPI's cvvdp) of a whole sequence against the reference's, in JOD (10: no visible
// difference), through the atrous Python package's `atrous-cvvdp` command (python/atrous/eval/
// cvvdp.py; `make python` puts it in .venv/bin; cvvdp itself is `pip install cvvdp`, with PyTorch):
// a list of the frames' files (FrameFiles), REFERENCE<TAB>TEST lines, handed to `atrous-cvvdp
// --pairs`, its "JOD: x" read. Off, with one note,
// when the command is not on PATH or its --check says cvvdp cannot run; off with --no-cvvdp. A
// sequence it fails on gives no value (nullopt) and one note.
class CvvdpRunner {
public:
    explicit CvvdpRunner(bool wanted) {
        if (!wanted) return;
        mExe = io::findOnPath("atrous-cvvdp");
        if (mExe.empty()) {
            mNote = "the atrous-cvvdp command (the atrous Python package's; make python puts it in .venv/bin) is not on PATH";
            return;
        }
        int rc = 0;
        const std::string out = runCommand(io::shellQuote(mExe) + " --check 2>&1", &rc);
        if (rc != 0) {
            mNote = lastLine(out);
            mExe.clear();
            return;
        }
    }
    bool enabled() const { return !mExe.empty(); }
    const std::string& note() const { return mNote; }  // why it is off ("" when on or not wanted)

    // files: each frame's reference and test file, in order; `dir` takes the list.
    std::optional<double> sequence(const std::string& name, const std::vector<std::pair<std::string, std::string>>& files,
                                   const fs::path& dir) {
        std::string pairs;
        for (const auto& [r, t] : files) pairs += r + "\t" + t + "\n";
        const std::string list = (dir / "pairs.txt").string();
        FILE* f = std::fopen(list.c_str(), "w");
        if (!f || std::fputs(pairs.c_str(), f) < 0 || std::fclose(f) != 0)
            throw RuntimeError(list + ": cannot write the list of frames for ColorVideoVDP");
        int rc = 0;
        const std::string out = runCommand(io::shellQuote(mExe) + " --pairs " + io::shellQuote(list) + " 2>&1", &rc);
        const size_t at = out.find("JOD:");
        if (rc == 0 && at != std::string::npos) return std::strtod(out.c_str() + at + 4, nullptr);
        logLine("note: ColorVideoVDP (%s) failed on %s: %s\n", mExe.c_str(), name.c_str(),
                     lastLine(out).c_str());
        return std::nullopt;
    }

private:
    // A Python error's last line says what went wrong (the first is "Traceback ...").
    static std::string lastLine(const std::string& out) {
        size_t end = out.find_last_not_of(" \n\r\t");
        if (end == std::string::npos) return "(no output)";
        const size_t start = out.rfind('\n', end);
        return out.substr(start == std::string::npos ? 0 : start + 1, end + 1 - (start == std::string::npos ? 0 : start + 1)).substr(0, 300);
    }
    std::string mExe, mNote;
};

// A label ffmpeg's drawtext takes as it is: letters, digits and "_-." (others become '_').
std::string plainLabel(const std::string& s) {
    std::string out;
    for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ? c : '_';
    return out.empty() ? "_" : out;
}

// --video: the sequences and the reference side by side, each labelled with its folder's name, at
// 24 frames per second (ffmpeg: PNG strips as `denoise --sequence` writes its previews, labels by
// drawtext), written to a temporary name and renamed.
void writeVideo(const std::string& path, const std::vector<std::string>& names,
                const std::vector<std::vector<std::pair<int, Image>>>& seqs) {
    const std::string ffmpeg = io::findOnPath("ffmpeg");
    if (ffmpeg.empty()) throw InputError("--video " + path + ": needs ffmpeg on PATH, and there is none");
    const fs::path out(path);
    const fs::path tmpDir = (out.has_parent_path() ? out.parent_path() : fs::path(".")) / (".atrous-video-" + out.stem().string());
    std::error_code ec;
    fs::remove_all(tmpDir, ec);
    fs::create_directories(tmpDir, ec);
    if (ec) throw RuntimeError(tmpDir.string() + ": cannot create (" + ec.message() + ")");
    const int w = seqs[0][0].second.width(), h = seqs[0][0].second.height(), gap = 4;
    const int n = int(seqs.size());
    std::string filter = "pad=ceil(iw/2)*2:ceil(ih/2)*2";
    const int fontSize = std::max(10, h / 14);
    for (int k = 0; k < n; ++k)
        filter += ",drawtext=text=" + plainLabel(fs::path(names[size_t(k)]).filename().string()) + ":x=" + std::to_string(k * (w + gap) + 4) +
                  ":y=4:fontsize=" + std::to_string(fontSize) + ":fontcolor=white:box=1:boxcolor=black@0.5";
    for (size_t i = 0; i < seqs[0].size(); ++i) {
        Image strip(n * w + (n - 1) * gap, h, 3);
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < strip.width(); ++x) strip(x, y, c) = 1.0f;  // white gaps
        for (int k = 0; k < n; ++k) {
            const Image& img = seqs[size_t(k)][i].second;
            for (int c = 0; c < 3; ++c)
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) strip(k * (w + gap) + x, y, c) = img(x, y, c);
        }
        char name[32];
        std::snprintf(name, sizeof name, "f%06zu.png", i);
        atrous::writeImage((tmpDir / name).string(), strip);
    }
    const std::string tmpVideo = (tmpDir / "video.mp4").string();
    const std::string cmd = io::shellQuote(ffmpeg) + " -nostdin -y -loglevel error -framerate 24 -i " + io::shellQuote((tmpDir / "f%06d.png").string()) +
                            " -vf " + io::shellQuote(filter) + " -pix_fmt yuv420p -f mp4 " + io::shellQuote(tmpVideo);
    const int rc = std::system(cmd.c_str());
    if (rc == 0) fs::rename(tmpVideo, out, ec);
    fs::remove_all(tmpDir);
    if (rc != 0) throw RuntimeError("--video " + path + ": ffmpeg failed (exit status " + std::to_string(rc) + ")");
    if (ec) throw RuntimeError("--video " + path + ": cannot move the video into place (" + ec.message() + ")");
}

// The flicker measure beside the reference's metrics, when something places the frames: --input, or
// the reference sequence's own motion vectors or Position pass. Null otherwise.
std::unique_ptr<FlickerGuide> referenceGuide(const CompareArgs& a, std::vector<std::string>* notes) {
    std::string dir = a.input;
    if (dir.empty()) {
        int w = 0, h = 0;
        const std::vector<std::string> present = io::validateSequence(io::listSequenceFrames(a.sequence), w, h);
        for (const char* b : {"motion", "position"})
            if (std::find(present.begin(), present.end(), b) != present.end()) dir = a.sequence;
    }
    return dir.empty() ? nullptr : std::make_unique<FlickerGuide>(FlickerGuide::load(dir, notes));
}

void runSequence(const CompareArgs& a) {
    if (!a.ref.empty() || !a.errorMaps.empty())
        throw InputError("--sequence REF_DIR: compares sequences; --ref and --error-maps are for images");
    if (a.noReference || a.images.empty()) {
        // No reference: the sequence given with --sequence is judged too (the first), by the flicker measure.
        if (!a.video.empty()) throw InputError("--video: shows the sequences beside a reference; drop --no-reference");
        FlickerCompareArgs f;
        f.sequences.push_back(a.sequence);
        f.sequences.insert(f.sequences.end(), a.images.begin(), a.images.end());
        f.input = a.input;
        f.json = a.json;
        return runFlickerCompare(f);
    }
    if (!a.video.empty()) {
        std::vector<std::string> inputs = a.images;
        inputs.push_back(a.sequence);
        io::refuseOverwrite("--video", a.video, inputs);
        if (io::extensionOf(a.video) != ".mp4") throw InputError("--video " + a.video + ": write an .mp4");
    }
    auto ref = sequenceImages(a.sequence, true);
    std::vector<std::vector<std::pair<int, Image>>> all;
    nlohmann::json j;
    j["reference"] = a.sequence;
    j["sequences"] = nlohmann::json::array();
    FlipRunner flip(!a.noFlip);
    if (!a.noFlip && !flip.enabled() && !flip.noted())
        logLine("note: no FLIP column: the flip command (pip install flip-evaluator; make python puts it in "
                             ".venv/bin) is not on PATH\n");
    CvvdpRunner cvvdp(!a.noCvvdp);
    if (!cvvdp.note().empty()) logLine("note: no CVVDP column: %s\n", cvvdp.note().c_str());
    // Written once for both external metrics, only when one of them runs.
    const std::unique_ptr<FrameFiles> files = flip.enabled() || cvvdp.enabled() ? std::make_unique<FrameFiles>() : nullptr;
    std::vector<std::string> notes;
    const std::unique_ptr<FlickerGuide> guide = referenceGuide(a, &notes);
    for (const std::string& n : notes) logLine("%s\n", n.c_str());
    if (guide) {
        // The measure's floor on this sequence: what the reference itself changes where it reprojects.
        const FlickerMetrics rf = guide->measure(ref, a.sequence);
        j["reference_flicker"] = rf.relMse;
        if (!a.json)
            resultLine("flicker (no reference needed): the reference's own is %.6g, %.1f%% of its pixels reproject (motion of %s)\n",
                        rf.relMse, 100.0 * rf.reprojected, guide->dir().c_str());
    }
    if (!a.json)
        resultLine("%-32s %7s %14s %10s %8s %14s %10s%s%s%s\n", "sequence", "frames", "relMSE", "PSNR(dB)", "SSIM", "temporal relMSE",
                    "tPSNR(dB)", guide ? "        flicker" : "", flip.enabled() ? "     FLIP" : "", cvvdp.enabled() ? " CVVDP(JOD)" : "");
    for (const std::string& dir : a.images) {
        auto seq = sequenceImages(dir, false);
        // The frames are matched by number: the same numbers in both, or one line naming the first that is not.
        for (size_t i = 0; i < std::max(seq.size(), ref.size()); ++i) {
            if (i >= seq.size() || i >= ref.size() || seq[i].first != ref[i].first) {
                const bool inRef = i < ref.size() && (i >= seq.size() || ref[i].first < seq[i].first);
                const int n = inRef ? ref[i].first : seq[i].first;
                throw InputError(dir + ": frame " + std::to_string(n) + (inRef ? " is missing (the reference " + a.sequence + " has it)"
                                                                             : " has no reference frame in " + a.sequence));
            }
        }
        double rel = 0, psnr = 0, ssim = 0, trel = 0, tpsnr = 0, flipSum = 0;
        bool flipOk = flip.enabled();
        std::vector<std::pair<std::string, std::string>> frameFiles;  // for FLIP and ColorVideoVDP
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
            if (files) frameFiles.push_back(files->frame(seq[i].first, ref[i].second, seq[i].second));
            if (flipOk) {
                const std::optional<double> f =
                    flip.frame(seq[i].first, frameFiles.back().first, frameFiles.back().second, files->dir());
                flipOk = f.has_value();
                if (f) flipSum += *f;
            }
        }
        const double n = double(seq.size()), steps = std::max(1.0, n - 1.0);
        nlohmann::json s = {{"path", dir},           {"frames", seq.size()},       {"relmse", rel / n},
                            {"psnr", psnr / n},      {"ssim", ssim / n},           {"temporal_relmse", trel / steps},
                            {"tpsnr", tpsnr / steps}};
        const double flicker = guide ? guide->measure(seq, dir).relMse : 0.0;
        s["flicker"] = guide ? nlohmann::json(flicker) : nlohmann::json(nullptr);
        s["flip"] = flipOk ? nlohmann::json(flipSum / n) : nlohmann::json(nullptr);
        const std::optional<double> jod = cvvdp.enabled() ? cvvdp.sequence(dir, frameFiles, files->dir()) : std::nullopt;
        s["cvvdp"] = jod ? nlohmann::json(*jod) : nlohmann::json(nullptr);
        if (a.json) {
            j["sequences"].push_back(s);
        } else {
            resultLine("%-32s %7zu %14.6g %10.3f %8.4f %14.6g %10.3f", dir.c_str(), seq.size(), rel / n, psnr / n, ssim / n,
                        trel / steps, tpsnr / steps);
            if (guide) resultLine(" %14.6g", flicker);
            if (flip.enabled()) flipOk ? resultLine(" %8.4f", flipSum / n) : resultLine(" %8s", "-");
            if (cvvdp.enabled()) jod ? resultLine(" %10.4f", *jod) : resultLine(" %10s", "-");
            resultLine("\n");
        }
        if (!a.video.empty()) all.push_back(std::move(seq));  // every frame has the reference's size (computeMetrics)
    }
    if (!a.video.empty()) {
        std::vector<std::string> names = a.images;
        names.push_back("reference");
        all.push_back(std::move(ref));
        writeVideo(a.video, names, all);
        j["video"] = a.video;
        if (!a.json) resultLine("video: %s (%s | reference)\n", a.video.c_str(), a.images.size() == 1 ? a.images[0].c_str() : "the sequences");
    }
    if (a.json) resultLine("%s\n", j.dump(2).c_str());
}

void run(const CompareArgs& a) {
    if (!a.sequence.empty()) return runSequence(a);
    if (!a.video.empty()) throw InputError("--video: compares sequences; give --sequence REF_DIR");
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
    Image ref = atrous::readImage(a.ref);
    std::vector<ImageMetrics> ms;
    std::vector<Image> imgs;
    for (const auto& p : a.images) {
        notePng(p);
        imgs.push_back(atrous::readImage(p));
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
    for (const std::string& n : notes) logLine("%s\n", n.c_str());
    if (!a.errorMaps.empty()) {
        for (size_t i = 0; i < imgs.size(); ++i) {
            const std::string stem = std::filesystem::path(a.images[i]).stem().string();
            atrous::writeImage((std::filesystem::path(a.errorMaps) / (stem + "_se.exr")).string(), squaredErrorMap(imgs[i], ref));
            atrous::writeImage((std::filesystem::path(a.errorMaps) / (stem + "_relse.exr")).string(),
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
        resultLine("%s\n", j.dump(2).c_str());
    } else {
        resultLine("%-40s %14s %14s %10s %8s\n", "image", "MSE", "relMSE", "PSNR(dB)", "SSIM");
        for (size_t i = 0; i < ms.size(); ++i)
            resultLine("%-40s %14.6g %14.6g %10.3f %8.4f\n", a.images[i].c_str(), ms[i].mse, ms[i].relMse, ms[i].psnr,
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
                    "(docs/eval.md), and the flicker measure when --input (or the reference) has motion. Alone, or "
                    "with --no-reference: a sequence to judge without a reference (the flicker measure)");
    cmd->add_option("images", a->images, "Images (or, with --sequence, sequence directories) to compare");
    addFlickerOptions(*cmd, a->noReference, a->input);  // --no-reference, --input
    cmd->add_option("--video", a->video,
                    "With --sequence: write an .mp4 of the sequences and the reference side by side, each labelled "
                    "with its folder's name (needs ffmpeg)");
    cmd->add_flag("--json", a->json, "Print JSON");
    cmd->add_flag("--no-flip", a->noFlip,
                  "With --sequence: no FLIP column (by default the mean HDR-FLIP over the frames when the flip command "
                  "of pip's flip-evaluator is on PATH)");
    cmd->add_flag("--no-cvvdp", a->noCvvdp,
                  "With --sequence: no ColorVideoVDP column (by default the JOD of each sequence when the atrous-cvvdp "
                  "command of the atrous Python package is on PATH and pip's cvvdp is installed beside it)");
    cmd->add_option("--error-maps", a->errorMaps, "Write <name>_se.exr and <name>_relse.exr error maps into DIR");
    addVerbosityFlags(*cmd);
    cmd->callback([a] { run(*a); });
}

}  // namespace atrous::cli

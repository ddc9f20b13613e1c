#include "denoise_sequence.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <future>
#include <memory>
#include <sstream>
#include <vector>

#include "atrous/error.h"
#include "atrous/temporal.h"
#include "cli_flags.h"
#include "core/timer.h"
#include "io/buffer_set.h"
#include "io/image_io.h"
#include "io/paths.h"
#include "io/sequence.h"
#include "sequence_checks.h"

namespace fs = std::filesystem;

namespace atrous::cli {

namespace {

// Mean squared error over all channels, skipping non-finite reference values.
double meanSquaredError(const Image& a, const Image& b) {
    double sum = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
        double d = double(a.data()[i]) - double(b.data()[i]);
        if (std::isfinite(d)) {
            sum += d * d;
            ++n;
        }
    }
    return n ? sum / double(n) : 0.0;
}

// Encodes the PNGs of `outDir` (the staging directory) into outDir/preview.mp4; messages name
// `finalDir`, where the video ends up.
void writeAnimatedPreview(const std::string& outDir, int firstIndex, bool quiet, const std::string& finalDir) {
    std::string ffmpeg = findOnPath("ffmpeg");
    if (ffmpeg.empty()) {
        std::printf("ffmpeg is not on PATH: skipping the animated preview (the per-frame PNGs are in %s)\n", finalDir.c_str());
        return;
    }
    std::string finalPath = (fs::path(outDir) / "preview.mp4").string();
    std::string tmpPath = (fs::path(outDir) / ".preview.tmp.mp4").string();
    // Even dimensions for yuv420p; 24 frames per second.
    std::string cmd = shellQuote(ffmpeg) + " -nostdin -y -loglevel error -framerate 24 -start_number " +
                      std::to_string(firstIndex) + " -i " + shellQuote((fs::path(outDir) / "frame_%04d.png").string()) +
                      " -vf " + shellQuote("pad=ceil(iw/2)*2:ceil(ih/2)*2") + " -pix_fmt yuv420p -f mp4 " + shellQuote(tmpPath);
    int rc = std::system(cmd.c_str());
    std::error_code ec;
    if (rc != 0) {
        fs::remove(tmpPath, ec);
        std::printf("warning: ffmpeg failed (exit status %d); no animated preview written\n", rc);
        return;
    }
    fs::rename(tmpPath, finalPath, ec);
    if (ec) {
        fs::remove(tmpPath, ec);
        std::printf("warning: could not rename the animated preview into place\n");
        return;
    }
    if (!quiet) std::printf("animated preview: %s\n", (fs::path(finalDir) / "preview.mp4").c_str());
}

}  // namespace

void addSvgfOptions(CLI::App& cmd, SvgfParams& p) {
    addParamOptions(cmd, p, svgfParams(), [](const ParamField<SvgfParams>&) { return "SVGF (--method svgf)"; });
}

void addTemporalOptions(CLI::App& cmd, TemporalParams& p) {
    addParamOptions(cmd, p, temporalParams(), [](const ParamField<TemporalParams>&) {
        return "Temporal (--method temporal, the default with --sequence)";
    });
}

std::string shellQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += (c == '\'') ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::string findOnPath(const std::string& name) {
    const char* path = std::getenv("PATH");
    if (!path) return "";
    std::stringstream ss(path);
    std::string dir;
    while (std::getline(ss, dir, ':')) {
        if (dir.empty()) continue;
        fs::path candidate = fs::path(dir) / name;
        std::error_code ec;
        if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
    return "";
}

namespace {

// OUTDIR's contents are built in a hidden sibling directory and moved into place only when every
// frame has been denoised, so bad input that the header check cannot see (a truncated EXR) leaves
// OUTDIR as it was. The sibling sits in OUTDIR's parent so the final rename stays on one file system.
class StagedOutput {
public:
    explicit StagedOutput(const std::string& outDir) {
        mOut = fs::path(outDir).lexically_normal();
        if (mOut.filename().empty()) mOut = mOut.parent_path();  // "out/" -> "out"
        std::error_code ec;
        if (fs::exists(mOut, ec) && !fs::is_directory(mOut, ec))
            throw InputError("--out '" + outDir + "': exists and is not a directory");
        if (fs::is_directory(mOut, ec) && ::access(mOut.c_str(), W_OK | X_OK) != 0)
            throw InputError("--out '" + outDir + "': output directory is not writable");
        const fs::path parent = mOut.has_parent_path() ? mOut.parent_path() : fs::path(".");
        // Parents created here are removed again on failure (nothing is left behind).
        for (fs::path p = parent; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) mCreatedParent = p;
        mStage = parent / ("." + mOut.filename().string() + ".partial-" + std::to_string(::getpid()));
        fs::remove_all(mStage, ec);  // a leftover of a killed run with the same pid
        if (!fs::create_directories(mStage, ec) || ec)
            throw InputError("--out '" + outDir + "': cannot create the output directory (" +
                             (ec ? ec.message() : std::string("it could not be made")) + ")");
    }
    ~StagedOutput() {
        if (mCommitted) return;
        std::error_code ec;
        fs::remove_all(mStage, ec);
        if (!mCreatedParent.empty()) fs::remove_all(mCreatedParent, ec);
    }
    StagedOutput(const StagedOutput&) = delete;
    StagedOutput& operator=(const StagedOutput&) = delete;

    std::string stage() const { return mStage.string(); }

    // Moves the staged files into OUTDIR. An absent or empty OUTDIR is replaced by the staging
    // directory in one rename. A non-empty OUTDIR keeps its other files; this run's files replace
    // those of the same name, and the frame_NNNN.exr/.png (and preview.mp4) of an earlier run
    // that this run did not write are removed, named in one line on stderr.
    void commit() {
        std::error_code ec;
        bool emptyOut = !fs::exists(mOut, ec) || fs::is_empty(mOut, ec);
        if (emptyOut) {
            fs::rename(mStage, mOut, ec);
            if (!ec) {
                mCommitted = true;
                return;
            }
            fs::create_directories(mOut, ec);  // the rename failed: move file by file instead
        }
        std::vector<std::string> written;
        for (auto it = fs::directory_iterator(mStage, ec); !ec && it != fs::directory_iterator(); it.increment(ec))
            written.push_back(it->path().filename().string());
        if (ec) throw RuntimeError(mStage.string() + ": cannot list the staged output (" + ec.message() + ")");
        for (const auto& name : written) {
            fs::rename(mStage / name, mOut / name, ec);
            if (ec) throw RuntimeError((mOut / name).string() + ": cannot move the result into place (" + ec.message() + ")");
        }
        mCommitted = true;
        fs::remove_all(mStage, ec);
        auto wrote = [&](const std::string& name) { return std::find(written.begin(), written.end(), name) != written.end(); };
        std::vector<std::string> removed;
        for (const char* ext : {".exr", ".png"}) {
            auto r = io::removeSequenceEntries(mOut.string(), ext,
                                               [&](int index) { return wrote(io::sequenceFrameName(index) + ext); });
            removed.insert(removed.end(), r.begin(), r.end());
        }
        if (!wrote("preview.mp4") && fs::is_regular_file(mOut / "preview.mp4", ec)) {
            fs::remove(mOut / "preview.mp4", ec);
            if (!ec) removed.push_back("preview.mp4");
        }
        if (!removed.empty()) {
            std::sort(removed.begin(), removed.end());
            std::string list = removed.front();
            if (removed.size() > 1) list += (removed.size() > 2 ? ", ..., " : ", ") + removed.back();
            std::fprintf(stderr, "denoise: removed %zu file%s of an earlier run from %s (%s)\n", removed.size(),
                         removed.size() == 1 ? "" : "s", mOut.c_str(), list.c_str());
        }
    }

private:
    fs::path mOut, mStage, mCreatedParent;
    bool mCommitted = false;
};

}  // namespace

int runSequenceDenoise(const SequenceDenoiseArgs& args) {
    const bool svgf = args.method == "svgf", temporal = args.method == "temporal";
    if (!findSequenceMethod(args.method) && !findDenoiseMethod(args.method))
        throw InputError("--method '" + args.method + "' cannot denoise a sequence (expected " + sequenceMethodNames() +
                         ", " + denoiseMethodNames() + ")");
    if (args.sequenceDir.empty()) throw InputError("--sequence: no directory given");
    if ((svgf || temporal) && args.range.step > 1)
        throw InputError("--step " + std::to_string(args.range.step) + ": " +
                         (svgf ? "SVGF carries its history from one frame to the next"
                               : "the temporal method averages neighbouring frames") +
                         ", and the motion vectors do not span skipped frames (use --step 1, or a per-frame --method)");
    if (args.outDir.empty()) throw InputError("--out: no output directory given");
    if (!(args.exposure > 0.0f)) throw InputError("--exposure must be > 0");

    // Everything that can be checked before writing is checked first; what only decoding finds
    // (a truncated EXR) fails inside the loop, before anything reaches OUTDIR (StagedOutput).
    // OUTDIR in the sequence directory would take its frame_NNNN.exr names (io/paths.h).
    // (A pattern's frames are in its directory.)
    io::refuseOutputInside("--out", args.outDir, io::sequenceFolder(args.sequenceDir));
    std::vector<std::string> frames = io::listSequenceFrames(args.sequenceDir, args.range);
    if (!args.addPass.empty() && !io::isLayeredSequenceFrame(frames.front()))
        throw InputError("--add-pass '" + args.addPass + "': copies a layered EXR frame, and " + args.sequenceDir +
                         " holds frames of plain EXRs");
    int width = 0, height = 0;
    const std::vector<std::string> present = io::validateSequence(frames, width, height, args.layers);
    std::unique_ptr<SvgfDenoiser> svgfDenoiser;
    DenoiseOptions options = args.frameOptions;
    if (temporal) validateTemporalParams(args.temporal);
    if (svgf) {
        // The weight file was read and checked by cmd_denoise.cpp, before the frames.
        svgfDenoiser = std::make_unique<SvgfDenoiser>(args.svgf, args.device, args.svgfLearnedWeights);
    } else {
        // (temporal: frameOptions.method is the still method run on the average, --spatial)
        if (!temporal) options.method = parseDenoiseMethod(args.method);
        options.device = args.device;
        validateDenoiseOptions(options);
        // A bad --learned-weights file has failed already, in cmd_denoise.cpp (its one caller).
    }
    DenoiseReport frameReport;
    options.report = &frameReport;
    StagedOutput staged(args.outDir);
    const std::string stage = staged.stage();

    // Frames are read in order; frame i is denoised once frames up to i + radius are in (temporal;
    // the other methods: radius 0). `window` holds frames winFirst .. the last read.
    const size_t radius = temporal ? size_t(args.temporal.radius) : 0;
    std::deque<io::SequenceFrame> window;
    size_t winFirst = 0;
    int firstIndex = 0;
    std::vector<ReprojectionCheck> checks(frames.size());
    TemporalCache temporalCache;  // each frame prepared once for all the windows it is in
    bool idsTrusted = true, warnedSign = false, notedMotion = false;
    CameraFit prevCamera;  // the previous frame's, for motion from positions
    // Pipelined: frame N+1 is read and frame N-1 written (EXR and PNG) on other threads while
    // frame N is filtered. An error in either reaches this thread through its future, in frame
    // order; nothing reaches OUTDIR before every frame is done (StagedOutput).
    auto load = [&](size_t i) { return io::loadSequenceFrame(frames[i], present, args.layers); };
    std::future<io::SequenceFrame> next = std::async(std::launch::async, load, size_t(0));
    std::future<void> writing;
    Timer wall;
    double filterMs = 0.0;

    auto refsOf = [&](const io::SequenceFrame& f) {
        io::BufferRefs refs = io::refsOf(f);  // every buffer the frame has, through the one input assembly
        if (!idsTrusted) refs.set(io::Buffer::ObjectId, nullptr);
        return refs;
    };
    auto denoiseOne = [&](size_t i) {
        io::SequenceFrame& f = window[i - winFirst];
        const std::string name = io::sequenceFrameName(f.index);
        const ReprojectionCheck& check = checks[i];
        Timer timer;
        Image out;
        TemporalReport temporalReport;
        const double mseIn = f.reference.empty() ? 0.0 : meanSquaredError(f.color, f.reference);
        try {
            if (svgf) {
                out = svgfDenoiser->denoiseFrame(io::svgfFrame(refsOf(f)));
            } else if (temporal) {
                std::vector<io::BufferRefs> refs;
                std::vector<SvgfFrame> frameSet;
                for (const io::SequenceFrame& w : window) refs.push_back(refsOf(w));
                for (const io::BufferRefs& r : refs) frameSet.push_back(io::svgfFrame(r));
                std::vector<long long> ids;
                for (size_t j = 0; j < window.size(); ++j) ids.push_back((long long)(winFirst + j));
                out = denoiseTemporal(frameSet, i - winFirst, args.temporal, options, &temporalReport, &temporalCache,
                                      &ids);
                frameReport.methodUsed = temporalReport.spatial.methodUsed;
            } else {
                // The frame's colour, variance and emission are not read after this: the filter works
                // in their storage.
                const DenoiseInputs in = io::denoiseInputs(refsOf(f));
                DenoiseBuffers bufs;
                bufs.color = &f.color;
                bufs.variance = f.variance.empty() ? nullptr : &f.variance;
                bufs.emission = f.emission.empty() ? nullptr : &f.emission;
                bufs.albedo = in.albedo, bufs.normal = in.normal, bufs.position = in.position;
                bufs.depth = in.depth, bufs.ids = in.ids;
                out = denoise(bufs, options);
            }
        } catch (const InputError& e) {
            // The library names the buffer; the message names the frame's file too.
            throw InputError(io::withSourceFile(e.what(), [&](const std::string& b) { return f.fileOf(b); }, f.dir));
        }
        double ms = timer.ms();
        filterMs += ms;
        const double mseOut = f.reference.empty() ? 0.0 : meanSquaredError(out, f.reference);
        if (writing.valid()) writing.get();  // frame N-1's files, and its errors, before frame N's
        writing = std::async(std::launch::async, [&, name, layered = f.layered, img = std::make_shared<Image>(std::move(out))] {
            const std::string exrOut = (fs::path(stage) / (name + ".exr")).string();
            if (!args.addPass.empty())
                io::writeExrWithLayers(exrOut, *layered, {io::ExrOutLayer{args.addPass, img.get()}});
            else
                io::writeImage(exrOut, *img);
            io::writePng((fs::path(stage) / (name + ".png")).string(), *img, args.exposure);
        });
        if (args.quiet) return;
        const bool resolved = args.method == "auto" || (temporal && options.method == DenoiseMethod::Auto);
        std::printf("%s: %s", name.c_str(), args.method.c_str());
        if (temporal)
            std::printf(" (+-%zu frames, %.1f averaged per pixel in %.0f ms; then %s%s%s)", radius,
                        temporalReport.meanFrames, temporalReport.gatherMs, denoiseMethodName(options.method),
                        resolved ? " -> " : "", resolved ? denoiseMethodName(frameReport.methodUsed) : "");
        else if (resolved)
            std::printf(" -> %s", denoiseMethodName(frameReport.methodUsed));
        else if (svgf && args.svgf.learnedSpatial)
            std::printf(" (learned spatial)");
        std::printf(" %.1f ms", ms);
        if (check.tested > 0) std::printf(", %.0f%% reprojects onto the previous frame", 100 * check.kept);
        if (!f.reference.empty()) std::printf(", MSE vs reference %.6g (input %.6g)", mseOut, mseIn);
        std::printf("\n");
        std::fflush(stdout);
    };

    size_t nextOut = 0;
    for (size_t i = 0; i < frames.size(); ++i) {
        io::SequenceFrame f = next.get();
        if (i + 1 < frames.size()) next = std::async(std::launch::async, load, i + 1);
        const std::string name = io::sequenceFrameName(f.index);
        if (i == 0) firstIndex = f.index;
        // No motion vectors but a Position pass (LuxCore): motion from each frame's fitted camera.
        const bool usesMotion = svgf || (temporal && radius > 0);
        if (usesMotion && f.motion.empty() && !f.position.empty()) {
            const CameraFit fit = fitCamera(f.position);
            f.motion = motionFromPositions(f.position, fit, prevCamera);  // frame 0: no previous, NaN (no history)
            if (i > 0 && !notedMotion) {
                if (prevCamera.ok)
                    std::printf("denoise: note: the frames have no motion vectors: motion from the Position pass (a "
                                "camera fitted per frame, median reprojection error %.2f px)\n",
                                prevCamera.medianErrorPx);
                else
                    std::printf("denoise: note: the frames have no motion vectors, and no pinhole camera fits their "
                                "Position pass (median reprojection error %.2g px): no motion\n",
                                prevCamera.medianErrorPx);
                notedMotion = true;
            }
            prevCamera = fit;
        }
        // Other renderers' sequences: how much reprojects, with which sign, and whether ids hold.
        ReprojectionCheck& check = checks[i];
        if (!window.empty()) {
            const io::SequenceFrame& prev = window.back();
            check = checkReprojection(f.depth, f.normal, f.ids, f.motion, prev.depth, prev.normal, prev.ids);
        }
        if (usesMotion && f.motion.empty() && !notedMotion) {
            std::printf("denoise: note: the frames have no motion vectors: %s\n",
                        svgf ? "SVGF assumes nothing moves on screen"
                             : "the temporal method takes them as still and leaves out what the depth, normal and "
                               "colour tests find moved");
            notedMotion = true;
        }
        if (check.tested >= 64 && !warnedSign && check.keptNegated > check.kept + 0.2 && check.keptNegated > 0.5) {
            std::printf("denoise: warning: %s: the motion vectors look like the opposite sign convention (%.0f%% of the "
                         "frame reprojects as given, %.0f%% negated); atrous wants previous - current, in pixels, y down\n",
                         name.c_str(), 100 * check.kept, 100 * check.keptNegated);
            warnedSign = true;
        }
        if (idsTrusted && !f.ids.empty() && check.tested >= 64 && check.kept > 0.2 && check.idsAgree < 0.9) {
            std::printf("denoise: note: %s: the ids change between frames (%.0f%% agree after reprojection): not used "
                         "from here on (Mitsuba renumbers shapes when a scene is loaded)\n",
                         name.c_str(), 100 * check.idsAgree);
            idsTrusted = false;
        }
        if (temporal) {
            // Each frame is checked as it arrives, so a bad value is named by its own file (the
            // window's checks would name the frame being denoised).
            try {
                checkTemporalFrame(io::svgfFrame(refsOf(f)));
            } catch (const InputError& e) {
                throw InputError(io::withSourceFile(e.what(), [&](const std::string& b) { return f.fileOf(b); }, f.dir));
            }
        }
        window.push_back(std::move(f));
        // Denoise every frame whose window is complete (at the end: all that are left).
        for (; nextOut < frames.size() && (nextOut + radius <= i || i + 1 == frames.size()); ++nextOut) {
            denoiseOne(nextOut);
            // Keep the frames the next one's window needs, and always the last read (the next check's).
            while (winFirst + radius < nextOut + 1 && window.size() > 1) {
                window.pop_front();
                ++winFirst;
            }
        }
    }
    if (writing.valid()) writing.get();
    if (!args.quiet)
        std::printf("sequence: %zu frames, filter %.1f ms per frame, %.1f ms per frame in all (reading and writing "
                    "overlapped with filtering)\n",
                    frames.size(), filterMs / double(frames.size()), wall.ms() / double(frames.size()));
    if (args.preview) writeAnimatedPreview(stage, firstIndex, args.quiet, args.outDir);
    staged.commit();
    return 0;
}

}  // namespace atrous::cli

// The sequence session (include/atrous/sequence.h): what `atrous denoise --sequence`, Python's
// atrous.denoise_sequence and the Blender add-on run. Frames are read in order on another thread
// (frame N+1 while N is filtered) and written on a third (frame N-1), errors reaching this thread
// in frame order through the futures; nothing reaches OUTDIR before every frame is done
// (io::StagedDir).
#include "atrous/sequence.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <future>
#include <memory>

#include "atrous/error.h"
#include "atrous/timer.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/image_io.h"
#include "atrous/io/paths.h"
#include "io/reprojection_check.h"
#include "atrous/io/sequence.h"
#include "atrous/io/staged_dir.h"

namespace fs = std::filesystem;

namespace atrous {

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

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    return buf;
}

// Encodes the staged PNGs into stage/preview.mp4 (24 fps). Returns "" when it did, else a note
// saying why not.
std::string writeAnimatedPreview(const std::string& stage, int firstIndex, const std::string& finalDir) {
    const std::string ffmpeg = io::findOnPath("ffmpeg");
    if (ffmpeg.empty())
        return "ffmpeg is not on PATH: skipping the animated preview (the per-frame PNGs are in " + finalDir + ")";
    const std::string finalPath = (fs::path(stage) / "preview.mp4").string();
    const std::string tmpPath = (fs::path(stage) / ".preview.tmp.mp4").string();
    // Even dimensions for yuv420p.
    const std::string cmd = io::shellQuote(ffmpeg) + " -nostdin -y -loglevel error -framerate 24 -start_number " +
                            std::to_string(firstIndex) + " -i " +
                            io::shellQuote((fs::path(stage) / "frame_%04d.png").string()) + " -vf " +
                            io::shellQuote("pad=ceil(iw/2)*2:ceil(ih/2)*2") + " -pix_fmt yuv420p -f mp4 " +
                            io::shellQuote(tmpPath);
    const int rc = std::system(cmd.c_str());
    std::error_code ec;
    if (rc != 0) {
        fs::remove(tmpPath, ec);
        return "warning: ffmpeg failed (exit status " + std::to_string(rc) + "); no animated preview written";
    }
    fs::rename(tmpPath, finalPath, ec);
    if (ec) {
        fs::remove(tmpPath, ec);
        return "warning: could not rename the animated preview into place";
    }
    return "";
}

// What is checked before any frame is read.
void checkOptions(const std::string& input, const std::string& outDir, const SequenceDenoiseOptions& o) {
    const bool svgf = o.method == "svgf", temporal = o.method == "temporal";
    if (!findSequenceMethod(o.method) && !findDenoiseMethod(o.method))
        throw InputError("--method '" + o.method + "' cannot denoise a sequence (expected " + sequenceMethodNames() +
                         ", " + denoiseMethodNames() + ")");
    if (input.empty()) throw InputError("--sequence: no directory given");
    if (o.step < 1) throw InputError("--step " + std::to_string(o.step) + ": must be at least 1");
    if ((svgf || temporal) && o.step > 1)
        throw InputError("--step " + std::to_string(o.step) + ": " +
                         (svgf ? "SVGF carries its history from one frame to the next"
                               : "the temporal method averages neighbouring frames") +
                         ", and the motion vectors do not span skipped frames (use --step 1, or a per-frame --method)");
    if (outDir.empty()) throw InputError("--out: no output directory given");
    if (!(o.exposure > 0.0f)) throw InputError("--exposure must be > 0");
    if (temporal) validateTemporalParams(o.temporal);
    if (svgf) validateSvgfParams(o.svgf);
}

}  // namespace

SequenceReport denoiseSequence(const std::string& input, const std::string& outDir, const SequenceDenoiseOptions& args,
                               const SequenceEvents& events) {
    checkOptions(input, outDir, args);
    const bool svgf = args.method == "svgf", temporal = args.method == "temporal";
    SequenceReport report;
    auto note = [&](const std::string& line) {
        report.notes.push_back(line);
        if (events.note) events.note(line);
    };
    io::SequenceOptions layers;
    layers.passes = io::parsePassRequests(args.passes);
    layers.viewLayer = args.viewLayer;
    io::FrameRange range;
    range.start = args.start, range.end = args.end, range.step = args.step;

    // Everything that can be checked before writing is checked first; what only decoding finds
    // (a truncated EXR) fails inside the loop, before anything reaches OUTDIR (StagedDir).
    // OUTDIR in the sequence directory would take its frame_NNNN.exr names (io/paths.h).
    // (A pattern's frames are in its directory.)
    io::refuseOutputInside("--out", outDir, io::sequenceFolder(input));
    std::vector<std::string> frames = io::listSequenceFrames(input, range);
    if (!args.addPass.empty() && !io::isLayeredSequenceFrame(frames.front()))
        throw InputError("--add-pass '" + args.addPass + "': copies a layered EXR frame, and " + input +
                         " holds frames of plain EXRs");
    const std::vector<std::string> present = io::validateSequence(frames, report.width, report.height, layers);
    report.buffers = present;
    std::unique_ptr<SvgfDenoiser> svgfDenoiser;
    DenoiseOptions options = args.frame;
    if (svgf) {
        svgfDenoiser = std::make_unique<SvgfDenoiser>(args.svgf, args.device, args.svgfWeights);
    } else {
        // (temporal: frame.method is the still method run on the average)
        if (!temporal) options.method = parseDenoiseMethod(args.method);
        options.device = args.device;
        validateDenoiseOptions(options);
    }
    DenoiseReport frameReport;
    io::StagedDir staged("--out", outDir);
    const std::string stage = staged.stage();

    // The static window (TemporalParams::staticRadius) needs the renderer's own motion vectors:
    // motion fitted to positions or estimated from colours (below) sees a moving object as still.
    TemporalParams temporalParams = args.temporal;
    if (std::find(present.begin(), present.end(), "motion") == present.end()) temporalParams.staticRadius = 0;
    // Frames are read in order; frame i is denoised once frames up to i + lookahead are in
    // (temporal: its window's radius, 0 when causal; the other methods: 0). `window` holds frames
    // winFirst .. the last read, at most radius behind the one denoised.
    const size_t radius = temporal ? size_t(temporalWindowRadius(temporalParams)) : 0;
    const size_t lookahead = temporal && !args.temporal.causal ? radius : 0;
    std::deque<io::SequenceFrame> window;
    size_t winFirst = 0;
    int firstIndex = 0;
    std::vector<io::ReprojectionCheck> checks(frames.size());
    TemporalCache temporalCache;  // each frame prepared once for all the windows it is in
    bool idsTrusted = true, warnedSign = false, notedMotion = false;
    CameraFit prevCamera;  // the previous frame's, for motion from positions
    auto load = [&](size_t i) { return io::loadSequenceFrame(frames[i], present, layers); };
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
        const io::ReprojectionCheck& check = checks[i];
        Timer timer;
        Image out;
        TemporalReport temporalReport;
        SequenceFrameReport r;
        r.index = f.index;
        r.input = f.dir;
        r.output = (fs::path(outDir) / (name + ".exr")).string();
        r.hasReference = !f.reference.empty();
        r.mseInput = r.hasReference ? meanSquaredError(f.color, f.reference) : 0.0;
        try {
            if (svgf) {
                out = svgfDenoiser->denoiseFrame(refsOf(f));
            } else if (temporal) {
                std::vector<Frame> frameSet;
                for (const io::SequenceFrame& w : window) frameSet.push_back(refsOf(w));
                std::vector<long long> ids;
                for (size_t j = 0; j < window.size(); ++j) ids.push_back((long long)(winFirst + j));
                TemporalResult tr =
                    denoiseTemporalWithReport(frameSet, i - winFirst, temporalParams, options, &temporalCache, &ids);
                out = std::move(tr.image);
                temporalReport = std::move(tr.report);
                frameReport = temporalReport.spatial;
            } else {
                // The frame's colour, variance and emission are not read after this: handed over.
                DenoiseBuffers bufs = io::handOver(refsOf(f), f.color, &f.variance, &f.emission);
                DenoiseResult dr = denoiseWithReport(bufs, options);
                out = std::move(dr.image);
                frameReport = std::move(dr.report);
            }
        } catch (const InputError& e) {
            // The library names the buffer; the message names the frame's file too.
            throw InputError(io::withSourceFile(e.what(), [&](const std::string& b) { return f.fileOf(b); }, f.dir));
        }
        r.milliseconds = timer.ms();
        filterMs += r.milliseconds;
        if (r.hasReference) r.mse = meanSquaredError(out, f.reference);
        if (writing.valid()) writing.get();  // frame N-1's files, and its errors, before frame N's
        writing = std::async(std::launch::async, [&, name, layered = f.layered, img = std::make_shared<Image>(std::move(out))] {
            const std::string exrOut = (fs::path(stage) / (name + ".exr")).string();
            if (!args.addPass.empty())
                io::writeExrWithLayers(exrOut, *layered, {io::ExrOutLayer{args.addPass, img.get()}});
            else
                atrous::writeImage(exrOut, *img);
            if (args.pngs) io::writePng((fs::path(stage) / (name + ".png")).string(), *img, args.exposure);
        });
        const bool resolved = args.method == "auto" || (temporal && options.method == DenoiseMethod::Auto);
        r.methodUsed = svgf ? "svgf" : denoiseMethodName(frameReport.methodUsed);
        r.method = args.method;
        if (temporal)
            r.method += format(" (%s%d frames%s, %.1f averaged per pixel in %.0f ms; then %s%s%s)",
                               args.temporal.causal ? "causal, -" : "+-", args.temporal.radius,
                               radius > size_t(args.temporal.radius)
                                   ? format(" (+-%zu where nothing moves)", radius).c_str()
                                   : "",
                               temporalReport.meanFrames, temporalReport.gatherMs, denoiseMethodName(options.method),
                               resolved ? " -> " : "", resolved ? r.methodUsed.c_str() : "");
        else if (resolved)
            r.method += " -> " + r.methodUsed;
        else if (svgf && args.svgf.learnedSpatial)
            r.method += " (learned spatial)";
        if (check.tested > 0) r.reprojected = check.kept;
        r.line = name + ": " + r.method + format(" %.1f ms", r.milliseconds);
        if (check.tested > 0) r.line += format(", %.0f%% reprojects onto the previous frame", 100 * check.kept);
        if (r.hasReference) r.line += format(", MSE vs reference %.6g (input %.6g)", r.mse, r.mseInput);
        report.frames.push_back(r);
        if (events.frame) events.frame(report.frames.back());
    };

    size_t nextOut = 0;
    for (size_t i = 0; i < frames.size(); ++i) {
        io::SequenceFrame f = next.get();
        if (i + 1 < frames.size()) next = std::async(std::launch::async, load, i + 1);
        const std::string name = io::sequenceFrameName(f.index);
        if (i == 0) firstIndex = f.index;
        // No motion vectors but a Position pass (LuxCore): motion from each frame's fitted camera.
        bool estimated = false;  // motion from the colours (below): not the user's vectors to judge
        const bool usesMotion = svgf || (temporal && radius > 0);
        if (usesMotion && f.motion.empty() && !f.position.empty()) {
            const CameraFit fit = fitCamera(f.position);
            f.motion = motionFromPositions(f.position, fit, prevCamera);  // frame 0: no previous, NaN (no history)
            if (i > 0 && !notedMotion) {
                if (prevCamera.ok)
                    note(format("denoise: note: the frames have no motion vectors: motion from the Position pass (a "
                                "camera fitted per frame, median reprojection error %.2f px)",
                                prevCamera.medianErrorPx));
                else
                    note(format("denoise: note: the frames have no motion vectors, and no pinhole camera fits their "
                                "Position pass (median reprojection error %.2g px): no motion",
                                prevCamera.medianErrorPx));
                notedMotion = true;
            }
            prevCamera = fit;
        } else if (usesMotion && f.motion.empty() && !f.color.empty()) {
            // Neither vectors nor positions (a renderer that writes colour, albedo and normal):
            // motion from the colours themselves, block matching against the previous frame (the
            // first has none: no history; the frames' sizes were checked above).
            f.motion = estimateMotion(f.color, window.empty() ? nullptr : &window.back().color);
            estimated = !window.empty();
            if (estimated && !notedMotion)
                note("denoise: note: the frames have no motion vectors and no Position pass: motion estimated "
                     "from the frames' colours (block matching, docs/temporal.md)");
            notedMotion = notedMotion || estimated;
        }
        // Other renderers' sequences: how much reprojects, with which sign, and whether ids hold.
        io::ReprojectionCheck& check = checks[i];
        if (!window.empty() && !estimated) {
            const io::SequenceFrame& prev = window.back();
            check = io::checkReprojection(f.depth, f.normal, f.ids, f.motion, prev.depth, prev.normal, prev.ids);
        }
        if (usesMotion && f.motion.empty() && !notedMotion) {
            note(std::string("denoise: note: the frames have no motion vectors: ") +
                 (svgf ? "SVGF assumes nothing moves on screen"
                       : "the temporal method takes them as still and leaves out what the depth, normal and colour "
                         "tests find moved"));
            notedMotion = true;
        }
        if (check.tested >= 64 && !warnedSign && check.keptNegated > check.kept + 0.2 && check.keptNegated > 0.5) {
            note(format("denoise: warning: %s: the motion vectors look like the opposite sign convention (%.0f%% of the "
                        "frame reprojects as given, %.0f%% negated); atrous wants previous - current, in pixels, y down",
                        name.c_str(), 100 * check.kept, 100 * check.keptNegated));
            warnedSign = true;
        }
        if (idsTrusted && !f.ids.empty() && check.tested >= 64 && check.kept > 0.2 && check.idsAgree < 0.9) {
            note(format("denoise: note: %s: the ids change between frames (%.0f%% agree after reprojection): not used "
                        "from here on (Mitsuba renumbers shapes when a scene is loaded)",
                        name.c_str(), 100 * check.idsAgree));
            idsTrusted = false;
        }
        if (temporal) {
            // Each frame is checked as it arrives, so a bad value is named by its own file (the
            // window's checks would name the frame being denoised).
            try {
                checkTemporalFrame(refsOf(f));
            } catch (const InputError& e) {
                throw InputError(io::withSourceFile(e.what(), [&](const std::string& b) { return f.fileOf(b); }, f.dir));
            }
        }
        window.push_back(std::move(f));
        // Denoise every frame whose window is complete (at the end: all that are left).
        for (; nextOut < frames.size() && (nextOut + lookahead <= i || i + 1 == frames.size()); ++nextOut) {
            denoiseOne(nextOut);
            // Keep the frames the next one's window needs, and always the last read (the next check's).
            while (winFirst + radius < nextOut + 1 && window.size() > 1) {
                window.pop_front();
                ++winFirst;
            }
        }
    }
    if (writing.valid()) writing.get();
    report.filterMsPerFrame = filterMs / double(frames.size());
    report.wallMsPerFrame = wall.ms() / double(frames.size());
    if (args.preview && args.pngs) {
        const std::string problem = writeAnimatedPreview(stage, firstIndex, outDir);
        if (problem.empty())
            report.preview = (fs::path(outDir) / "preview.mp4").string();
        else
            note(problem);
    }
    const std::string removed = staged.commit();
    if (!removed.empty()) {
        report.notes.push_back("denoise: " + removed);
        if (events.warning) events.warning(report.notes.back());
    }
    return report;
}

}  // namespace atrous

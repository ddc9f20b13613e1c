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
#include "atrous/sequence_methods.h"
#include "atrous/temporal.h"
#include "atrous/timer.h"
#include "atrous/io/alpha.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/image_io.h"
#include "atrous/io/paths.h"
#include "io/reprojection_check.h"
#include "atrous/io/sequence.h"
#include "atrous/io/sequence_output.h"
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

// Encodes the staged PNGs (`pngs`, in frame order, named as the frames are) into
// stage/preview.mp4 (24 fps), through hard links numbered 0, 1, ... in a hidden folder of the
// stage (the frames' own names need not share one numbering). Returns "" when it did, else a note
// saying why not.
std::string writeAnimatedPreview(const std::string& stage, const std::vector<std::string>& pngs, const std::string& finalDir) {
    const std::string ffmpeg = io::findOnPath("ffmpeg");
    if (ffmpeg.empty())
        return "ffmpeg is not on PATH: skipping the animated preview (the per-frame PNGs are in " + finalDir + ")";
    const fs::path links = fs::path(stage) / ".preview-frames";
    std::error_code ec;
    fs::create_directories(links, ec);
    for (size_t i = 0; i < pngs.size() && !ec; ++i) {
        const fs::path from = fs::path(stage) / pngs[i], to = links / format("%06zu.png", i);
        fs::create_hard_link(from, to, ec);
        if (ec) fs::copy_file(from, to, ec);
    }
    if (ec) {
        fs::remove_all(links, ec);
        return "warning: could not prepare the frames of the animated preview; none written";
    }
    const std::string finalPath = (fs::path(stage) / "preview.mp4").string();
    const std::string tmpPath = (fs::path(stage) / ".preview.tmp.mp4").string();
    // Even dimensions for yuv420p.
    const std::string cmd = io::shellQuote(ffmpeg) + " -nostdin -y -loglevel error -framerate 24 -start_number 0 -i " +
                            io::shellQuote((links / "%06d.png").string()) + " -vf " +
                            io::shellQuote("pad=ceil(iw/2)*2:ceil(ih/2)*2") + " -pix_fmt yuv420p -f mp4 " +
                            io::shellQuote(tmpPath);
    const int rc = std::system(cmd.c_str());
    fs::remove_all(links, ec);
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

// The method's row, null for a still method run frame by frame.
const SequenceMethodInfo* rowOf(const std::string& method) { return findSequenceMethod(method); }

// What is checked before any frame is read.
void checkOptions(const std::string& input, const SequenceDenoiseOptions& o, const std::string& method) {
    const SequenceMethodInfo* row = rowOf(method);
    if (!row && !findDenoiseMethod(method))
        throw InputError("--method '" + method + "' cannot denoise a sequence (expected " + sequenceMethodNames() +
                         ", " + denoiseMethodNames() + ")");
    if (input.empty()) throw InputError("--sequence: no directory given");
    if (o.step < 1) throw InputError("--step " + std::to_string(o.step) + ": must be at least 1");
    if (row && o.step > 1)
        throw InputError("--step " + std::to_string(o.step) + ": " + row->acrossFrames +
                         ", and the motion vectors do not span skipped frames (use --step 1, or a per-frame --method)");
    if (!(o.exposure > 0.0f)) throw InputError("--exposure must be > 0");
    if (row && !o.params.empty()) {
        if (std::string(o.params.set()) != row->params.set())
            throw InputError("--method " + method + ": its parameters are the table '" + row->params.set() + "', not '" +
                             o.params.set() + "'");
        o.params.validate();
    } else if (row) {
        row->params.validate();
    }
}

// The InputError of a frame's buffer, naming the frame's file too (the library names the buffer).
[[noreturn]] void rethrowNamingFile(const InputError& e, const io::SequenceFrame& f) {
    throw InputError(io::withSourceFile(e.what(), [&](const std::string& b) { return f.fileOf(b); }, f.dir));
}

// One run: frames are read in order (the next one on another thread), given motion where they have
// none, checked against the previous frame, pushed into the method's denoiser, and each frame it
// hands back is written (on a third thread) into the staged folder.
class Session {
public:
    Session(const std::string& input, const std::string& outDir, const SequenceDenoiseOptions& args,
            const SequenceEvents& events)
        : mInput(input), mOutDir(outDir), mArgs(args), mEvents(events),
          mMethod(args.method.empty() ? sequenceMethods().front().name : args.method), mRow(rowOf(mMethod)) {}

    SequenceReport run();

private:
    using FramePtr = std::shared_ptr<io::SequenceFrame>;
    void note(const std::string& line) {
        mReport.notes.push_back(line);
        if (mEvents.note) mEvents.note(line);
    }
    void start();
    bool fillMotion(io::SequenceFrame& f, size_t i);
    void checkAgainstPrevious(const io::SequenceFrame& f, size_t i, bool estimated);
    void push(FramePtr f);
    void outputFrame();
    void writeFrame(const std::string& name, const FramePtr& frame, Image out);
    void finishFrame(SequenceFrameReport& r, const SequenceOutput& out, const std::string& name);
    void writePreviewAndCommit();

    const std::string mInput, mOutDir;
    io::SequenceOutputNames mNames;  // mOutDir parsed: the output folder, the frames' names
    std::vector<std::string> mPngs;  // the previews written, in order (preview.mp4's frames)
    const SequenceDenoiseOptions& mArgs;
    const SequenceEvents& mEvents;
    const std::string mMethod;
    const SequenceMethodInfo* mRow;
    SequenceReport mReport;
    io::SequenceOptions mLayers;
    std::vector<std::string> mFrames, mPresent;
    std::unique_ptr<io::StagedDir> mStaged;
    std::unique_ptr<SequenceDenoiser> mDenoiser;
    bool mUsesMotion = false;
    std::deque<FramePtr> mPending;  // pushed, not yet handed back: the front is the next to come out
    FramePtr mPrev;                 // the last frame read (motion from colours, the reprojection check)
    std::vector<io::ReprojectionCheck> mChecks;
    StreamMotion mMotion;  // frames without motion vectors
    bool mIdsTrusted = true, mWarnedSign = false, mNotedMotion = false;
    std::future<void> mWriting;
    double mFilterMs = 0.0;
};

// Everything that can be checked before writing is checked first; what only decoding finds (a
// truncated EXR) fails inside the loop, before anything reaches OUTDIR (StagedDir).
void Session::start() {
    checkOptions(mInput, mArgs, mMethod);
    mNames = io::parseSequenceOutput("--out", mOutDir);
    mLayers.passes = io::parsePassRequests(mArgs.passes);
    mLayers.viewLayer = mArgs.viewLayer;
    io::FrameRange range;
    range.start = mArgs.start, range.end = mArgs.end, range.step = mArgs.step;
    // Outputs never overwrite inputs: the output folder is neither the sequence's folder nor inside
    // it (io/paths.h; a pattern's frames are in its folder), and the frames keep their names.
    io::refuseOutputInside("--out", mNames.dir, io::sequenceFolder(mInput));
    mFrames = io::listSequenceFrames(mInput, range);
    if (!mArgs.addPass.empty() && !io::isLayeredSequenceFrame(mFrames.front()))
        throw InputError("--add-pass '" + mArgs.addPass + "': copies a layered EXR frame, and " + mInput +
                         " holds frames of plain EXRs");
    mPresent = io::validateSequence(mFrames, mReport.width, mReport.height, mLayers);
    mReport.buffers = mPresent;
    SequenceSetup setup;
    setup.device = mArgs.device;
    setup.params = mArgs.params;
    setup.still = mArgs.frame;
    // The static window (TemporalParams::staticRadius) needs the renderer's own motion vectors:
    // motion fitted to positions or estimated from colours (below) sees a moving object as still.
    setup.motionGiven = std::find(mPresent.begin(), mPresent.end(), "motion") != mPresent.end();
    mDenoiser = makeSequenceDenoiser(mMethod, setup);
    mUsesMotion = mDenoiser->reads().has(Buffer::Motion);
    mStaged = std::make_unique<io::StagedDir>("--out", mNames.dir);
    mChecks.resize(mFrames.size());
}

// No motion vectors but a Position pass (LuxCore): motion from each frame's fitted camera; neither
// (a renderer that writes colour, albedo and normal): motion from the colours themselves, block
// matching against the previous frame (the first has none: no history; the frames' sizes were
// checked above). Returns whether the motion was estimated from the colours against a previous
// frame (not the user's vectors to judge).
bool Session::fillMotion(io::SequenceFrame& f, size_t i) {
    if (!mUsesMotion || !f.motion.empty() || f.color.empty()) return false;
    const Frame prev = mPrev ? io::refsOf(*mPrev) : Frame();
    f.motion = mMotion.next(io::refsOf(f), mPrev ? &prev : nullptr);  // frame 0: no previous, NaN (no history)
    if (mMotion.from() == StreamMotion::From::Positions) {
        if (i > 0 && !mNotedMotion) {
            const CameraFit& camera = *mMotion.previousCamera();
            if (camera.ok)
                note(format("denoise: note: the frames have no motion vectors: motion from the Position pass (a "
                            "camera fitted per frame, median reprojection error %.2f px)",
                            camera.medianErrorPx));
            else
                note(format("denoise: note: the frames have no motion vectors, and no pinhole camera fits their "
                            "Position pass (median reprojection error %.2g px): no motion",
                            camera.medianErrorPx));
            mNotedMotion = true;
        }
        return false;
    }
    const bool estimated = mPrev != nullptr;
    if (estimated && !mNotedMotion)
        note("denoise: note: the frames have no motion vectors and no Position pass: motion estimated "
             "from the frames' colours (block matching, docs/temporal.md)");
    mNotedMotion = mNotedMotion || estimated;
    return estimated;
}

// Other renderers' sequences: how much reprojects, with which sign, and whether ids hold (ids that
// change between frames are left out of every frame from here on).
void Session::checkAgainstPrevious(const io::SequenceFrame& f, size_t i, bool estimated) {
    const std::string name = fs::path(f.dir).filename().string();
    io::ReprojectionCheck& check = mChecks[i];
    if (mPrev && !estimated)
        check = io::checkReprojection(f.depth, f.normal, f.ids, f.motion, mPrev->depth, mPrev->normal, mPrev->ids);
    if (mUsesMotion && f.motion.empty() && !mNotedMotion) {
        note(std::string("denoise: note: the frames have no motion vectors: ") +
             (mRow ? mRow->withoutMotion : "they are taken as still"));
        mNotedMotion = true;
    }
    if (check.tested >= 64 && !mWarnedSign && check.keptNegated > check.kept + 0.2 && check.keptNegated > 0.5) {
        note(format("denoise: warning: %s: the motion vectors look like the opposite sign convention (%.0f%% of the "
                    "frame reprojects as given, %.0f%% negated); atrous wants previous - current, in pixels, y down",
                    name.c_str(), 100 * check.kept, 100 * check.keptNegated));
        mWarnedSign = true;
    }
    if (mIdsTrusted && !f.ids.empty() && check.tested >= 64 && check.kept > 0.2 && check.idsAgree < 0.9) {
        note(format("denoise: note: %s: the ids change between frames (%.0f%% agree after reprojection): not used "
                    "from here on (Mitsuba renumbers shapes when a scene is loaded)",
                    name.c_str(), 100 * check.idsAgree));
        mIdsTrusted = false;
        mDenoiser->ignore(Buffer::ObjectId);
    }
}

// The frame into the denoiser (which checks it as it arrives, so that a bad value is named by its
// own file), then every frame it can hand back.
void Session::push(FramePtr f) {
    try {
        mDenoiser->push({io::refsOf(*f), f});  // every buffer the frame has, through the one input assembly
    } catch (const InputError& e) {
        rethrowNamingFile(e, *f);
    }
    mPending.push_back(std::move(f));
    while (mDenoiser->ready()) outputFrame();
}

// The frame's colour alpha (an RGBA EXR's A, Blender's Combined.A), read on the writing thread, is
// written beside the denoised colour unchanged (io/alpha.h, as the still path does).
void Session::writeFrame(const std::string& name, const FramePtr& frame, Image out) {
    if (mWriting.valid()) mWriting.get();  // frame N-1's files, and its errors, before frame N's
    const std::string stage = mStaged->stage();
    mWriting = std::async(std::launch::async, [this, stage, name, frame, rgb = std::make_shared<Image>(std::move(out))] {
        const std::string exrOut = (fs::path(stage) / (name + ".exr")).string();
        const auto img = std::make_shared<Image>(io::withAlpha(std::move(*rgb), io::readFrameAlpha(*frame, mLayers)));
        const std::vector<std::string> channels = img->channels() == 4 ? std::vector<std::string>{"R", "G", "B", "A"}
                                                                       : std::vector<std::string>{"R", "G", "B"};
        if (!mArgs.addPass.empty())
            io::writeExrWithLayers(exrOut, *frame->layered, {io::ExrOutLayer{mArgs.addPass, img.get(), channels}});
        else
            writeImage(exrOut, *img);
        if (mArgs.pngs) io::writePng((fs::path(stage) / (name + ".png")).string(), *img, mArgs.exposure);
    });
}

// The frame's report: what the method says it did, the reprojection check, the line.
void Session::finishFrame(SequenceFrameReport& r, const SequenceOutput& out, const std::string& name) {
    const io::ReprojectionCheck& check = mChecks[out.index];
    r.methodUsed = out.methodUsed;
    r.method = mMethod + out.detail;
    if (check.tested > 0) r.reprojected = check.kept;
    r.line = name + ": " + r.method + format(" %.1f ms", r.milliseconds);
    if (check.tested > 0) r.line += format(", %.0f%% reprojects onto the previous frame", 100 * check.kept);
    if (r.hasReference) r.line += format(", MSE vs reference %.6g (input %.6g)", r.mse, r.mseInput);
    mReport.frames.push_back(r);
    if (mEvents.frame) mEvents.frame(mReport.frames.back());
}

// The next frame out of the denoiser, written and reported.
void Session::outputFrame() {
    const FramePtr f = mPending.front();
    const std::string name = mNames.stem(f->dir, f->index);
    SequenceFrameReport r;
    r.index = f->index;
    r.position = int(mReport.frames.size()) + 1;
    r.count = int(mFrames.size());
    r.input = f->dir;
    r.output = (fs::path(mNames.dir) / (name + ".exr")).string();
    if (mArgs.pngs) mPngs.push_back(name + ".png");
    r.hasReference = !f->reference.empty();
    r.mseInput = r.hasReference ? meanSquaredError(f->color, f->reference) : 0.0;
    Timer timer;
    SequenceOutput out;
    try {
        out = mDenoiser->next();
    } catch (const InputError& e) {
        rethrowNamingFile(e, *f);
    }
    r.milliseconds = timer.ms();
    mFilterMs += r.milliseconds;
    if (r.hasReference) r.mse = meanSquaredError(out.image, f->reference);
    mPending.pop_front();
    writeFrame(name, f, std::move(out.image));
    finishFrame(r, out, name);
}

void Session::writePreviewAndCommit() {
    if (mArgs.preview && mArgs.pngs) {
        const std::string problem = writeAnimatedPreview(mStaged->stage(), mPngs, mNames.dir);
        if (problem.empty())
            mReport.preview = (fs::path(mNames.dir) / "preview.mp4").string();
        else
            note(problem);
    }
    const std::string removed = mStaged->commit();
    if (!removed.empty()) {
        mReport.notes.push_back("denoise: " + removed);
        if (mEvents.warning) mEvents.warning(mReport.notes.back());
    }
}

SequenceReport Session::run() {
    start();
    auto load = [&](size_t i) { return io::loadSequenceFrame(mFrames[i], mPresent, mLayers); };
    std::future<io::SequenceFrame> next = std::async(std::launch::async, load, size_t(0));
    Timer wall;
    for (size_t i = 0; i < mFrames.size(); ++i) {
        FramePtr f = std::make_shared<io::SequenceFrame>(next.get());
        if (i + 1 < mFrames.size()) next = std::async(std::launch::async, load, i + 1);
        const bool estimated = fillMotion(*f, i);
        checkAgainstPrevious(*f, i, estimated);
        mPrev = f;
        push(std::move(f));
    }
    // The frames left, without the later neighbours they would have had.
    mDenoiser->finish();
    while (mDenoiser->ready()) outputFrame();
    if (mWriting.valid()) mWriting.get();
    mReport.filterMsPerFrame = mFilterMs / double(mFrames.size());
    mReport.wallMsPerFrame = wall.ms() / double(mFrames.size());
    writePreviewAndCommit();
    return mReport;
}

}  // namespace

SequenceReport denoiseSequence(const std::string& input, const std::string& outDir, const SequenceDenoiseOptions& args,
                               const SequenceEvents& events) {
    Session session(input, outDir, args, events);
    return session.run();
}

}  // namespace atrous

// `atrous denoise`: EAW, SURE-À-Trous or the learned filter on a render directory or on individual EXR/PFM buffers.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>
#include <cstdio>
#include <deque>
#include <iterator>
#include <map>
#include <filesystem>
#include <memory>
#include <string>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/learned.h"
#include "atrous/sequence_methods.h"
#include "cli_flags.h"
#include "commands.h"
#include "atrous/timer.h"
#include "denoise_sequence.h"
#include "input_flags.h"
#include "progress.h"
#include "still_output.h"
#include "atrous/srgb.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/image_io.h"
#include "atrous/io/paths.h"

namespace atrous::cli {

namespace {

struct DenoiseArgs {
    InputFlags input;                  // --in, --color, ..., --pass, --layer (input_flags.h)
    std::string out, sequence;
    std::string addPass;               // --add-pass
    std::string ldrColor;              // oidnDenoise's --ldr FILE
    bool ldr = false, srgb = false;    // LDR input: output clamped to [0, 1]; --srgb: sRGB-encoded
    std::string oidnFilter = "RT", oidnQuality;  // oidnDenoise's -f, -q (accepted; see addOidnFlags)
    bool oidnCleanAux = false;
    std::string method = denoiseMethodName(DenoiseOptions{}.method);  // the library's default still method
    std::string device = "auto";
    std::string spatial = method;  // --spatial: the still method of a sequence method that ends with one
    io::FrameRange range;  // --start, --end, --step (with --sequence)
    DenoiseOptions opt;  // the filter parameters' flags write here (params.h's table)
    std::string learnedWeights;  // --learned-weights: loaded once into opt.weights
    std::deque<ParamSet> sequenceParams;  // each sequence method's parameters (sequenceMethods()' order): their flags write here
    std::vector<std::string> positional;  // `atrous denoise IN OUT`: IN as --in takes it, OUT as --out
    int threads = 0;                      // --threads: 0 = all cores
    float exposure = 1.0f;                // --exposure: of a .png output and a sequence's previews
};

// `atrous denoise IN OUT` (or `--in IN OUT`, `IN --out OUT`, `--sequence DIR OUT`): the
// positionals fill --out first (the last one), then --in; a positional that differs from its
// flag's value, or one too many, is an InputError.
void takePositionals(DenoiseArgs& a) {
    std::vector<std::string> pos = a.positional;
    if (pos.size() > 2) throw InputError("'" + pos[2] + "': one argument too many (atrous denoise IN OUT)");
    for (const std::string& p : pos)
        if (p.empty()) throw InputError("IN OUT: an empty path (atrous denoise IN OUT)");
    auto fill = [&](std::string& slot, const char* flag, const char* what) {
        if (pos.empty()) return;
        if (!slot.empty() && slot != pos.back())
            throw InputError(std::string(flag) + " '" + slot + "' and the " + what + " '" + pos.back() +
                             "' differ: give it once (atrous denoise IN OUT, or --in IN --out OUT)");
        slot = pos.back();
        pos.pop_back();
    };
    if (pos.size() == 2 || a.out.empty()) fill(a.out, "--out", "positional OUT");
    const bool inGiven = !a.input.file[int(io::Buffer::Color)].empty() || !a.ldrColor.empty() || !a.sequence.empty();
    if (!pos.empty() && inGiven)
        throw InputError("'" + pos.back() + "': one argument too many (the input is given by " +
                         (a.sequence.empty() ? "--color/--hdr/--ldr" : "--sequence") + ")");
    fill(a.input.in, "--in", "positional IN");
    if (a.out.empty()) throw InputError("--out is required (atrous denoise IN OUT, or --in IN --out OUT)");
}

// Option groups: the flags of one method are ignored by the others (a note says which).
const char* const kGroupBuffers = "Buffers (without --sequence)";

// The learned filter's group: the still methods that read its weights, and the sequence methods
// whose parameters make them read it (svgf --svgf-learned-spatial); from the registries.
std::string learnedGroup() {
    std::string g;
    for (const DenoiseMethodInfo& m : denoiseMethods())
        if (readsWeights(m)) g += (g.empty() ? "" : "|") + std::string(m.name);
    g = "Learned (--method " + g;
    for (const SequenceMethodInfo& m : sequenceMethods()) {
        const int row = m.weightsParam ? m.params.find(m.weightsParam) : -1;
        if (row >= 0) g += std::string(", or ") + m.name + " " + m.params.rows()[size_t(row)].flag;
    }
    return g + ")";
}

// The sequence methods that end with a still method (--spatial's), by name ("a or b" for two).
std::string spatialMethods() {
    std::string s;
    for (const SequenceMethodInfo& m : sequenceMethods())
        if (m.stillMethod) s += (s.empty() ? "" : " or ") + std::string(m.name);
    return s;
}

// Whether a flag's group is a sequence method's other than `method` (its flags are then ignored).
bool otherSequenceGroup(const std::string& group, const std::string& method) {
    for (const SequenceMethodInfo& m : sequenceMethods())
        if (group == sequenceGroup(m, true)) return method != m.name;
    return false;
}

// The help group of a still parameter: its stage's title and the methods that read it, from the
// registry (readsParamGroup); kept for the program's life (CLI11 copies it, the flag helpers take
// a C string).
const char* paramHelpGroup(const ParamField<DenoiseOptions>& f) {
    static std::map<std::string, std::string> titles;
    std::string& text = titles[f.group];
    if (!text.empty()) return text.c_str();
    text = denoiseGroupTitle(f.group);
    const std::vector<std::string>& stages = stillStageGroups();
    if (std::find(stages.begin(), stages.end(), std::string(f.group)) != stages.end()) return (text += " (every still method)").c_str();
    std::string who;
    for (const DenoiseMethodInfo& m : denoiseMethods())
        if (readsParamGroup(m, f.group)) who += (who.empty() ? "" : ", ") + std::string(m.name);
    return (text += " (--method " + who + ")").c_str();
}

// The row of denoiseParams() whose flag is `flag`, or null.
const ParamField<DenoiseOptions>* denoiseField(const std::string& flag) {
    for (const ParamField<DenoiseOptions>& f : denoiseParams())
        if (denoiseParams().flag(f) == flag) return &f;
    return nullptr;
}

// One note line on stderr naming the given flags that the chosen method (or --sequence) ignores:
// a still parameter whose group the still method that runs does not read (its registry row's
// reads), the weights where nothing reads them, a sequence method's flags with another method.
// still: the still method that runs (--spatial's with a sequence method that ends with one; null
// with one that does not). learnedSequence: a sequence method whose parameters read
// --learned-weights (svgf --svgf-learned-spatial).
void noteIgnoredFlags(const CLI::App& cmd, const std::string& method, const DenoiseMethodInfo* still, bool sequence,
                      bool learnedSequence) {
    const std::string groupLearned = learnedGroup();
    std::string ignored, ignoredSeq;
    for (const CLI::Option* opt : cmd.get_options()) {
        if (opt->count() == 0) continue;
        const std::string& g = opt->get_group();
        bool unused = otherSequenceGroup(g, method) ||
                      (g == groupLearned && !(still && readsWeights(*still)) && !learnedSequence);
        if (const ParamField<DenoiseOptions>* f = denoiseField(opt->get_name()))
            unused = !still || !readsParamGroup(*still, f->group);
        if (unused) ignored += (ignored.empty() ? "" : ", ") + opt->get_name();
        if (g == kGroupBuffers && sequence) ignoredSeq += (ignoredSeq.empty() ? "" : ", ") + opt->get_name();
    }
    if (!ignored.empty()) logLine("denoise: note: ignored with --method %s: %s\n", method.c_str(), ignored.c_str());
    // A buffer file given beside --sequence would not be read: refused, not noted (issue 29).
    if (!ignoredSeq.empty())
        throw InputError(ignoredSeq + ": a sequence's frames bring their own buffers (--sequence DIR); drop " +
                         (ignoredSeq.find(',') == std::string::npos ? "it" : "them"));
}

// --out FILE: its directory must exist and be a directory (checked before any work).
void checkOutputFile(const std::string& out) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(out).has_parent_path() ? fs::path(out).parent_path() : fs::path(".");
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
        throw InputError("--out '" + out + "': " + dir.string() + " is not a directory");
    if (!fs::exists(dir, ec)) throw InputError("--out '" + out + "': output directory " + dir.string() + " does not exist");
    if (fs::is_directory(out, ec)) throw InputError("--out '" + out + "': is a directory (give a file name)");
}

// The files of a still (--in/--color, --out checked): InputError before anything is read.
io::BufferFiles stillFiles(const DenoiseArgs& a) {
    const std::string ext = io::extensionOf(a.out);
    if (ext != ".exr" && ext != ".pfm" && ext != ".png")
        throw InputError("--out '" + a.out + "': unsupported extension (use .exr, .pfm or .png)");
    if (a.exposure != 1.0f && ext != ".png")
        throw InputError("--exposure: scales a .png output (and a sequence's .png previews); --out is " + ext);
    if (a.input.in.empty() == a.input.file[int(io::Buffer::Color)].empty())
        throw InputError("give exactly one of --in RENDER_DIR, --in LAYERED.exr or --color FILE (--hdr/--ldr)");
    checkOutputFile(a.out);
    io::BufferFiles files = bufferFiles(a.input);  // input_flags.h
    io::refuseOverwrite("--out", a.out, io::inputFiles(files));
    return files;
}

// Writes a still's output: a copy of the layered input with the pass added (--add-pass), a .png
// at --exposure, else by the extension.
void writeStill(const DenoiseArgs& a, const io::BufferSet& set, const Image& out) {
    if (!a.addPass.empty())
        io::writeExrWithLayers(a.out, *set.layered,
                               {io::ExrOutLayer{a.addPass, &out, out.channels() == 4 ? std::vector<std::string>{"R", "G", "B", "A"}
                                                                                    : std::vector<std::string>{"R", "G", "B"}}});
    else if (io::extensionOf(a.out) == ".png")
        io::writePng(a.out, out, a.exposure);
    else
        atrous::writeImage(a.out, out);
}

void srgbToLinear(Image& img) {
    for (size_t i = 0; i < img.plane() * size_t(img.channels()); ++i) img.data()[i] = srgbDecode(img.data()[i]);
}

// --method none: no filter, the colour written as read (a format conversion: a noisy EXR to a PNG
// preview), with its alpha, an LDR input's clamp and --srgb as for a denoised colour; a NaN/Inf
// value is written as 0 (said so), as no output holds one.
void runNone(const DenoiseArgs& a) {
    if (!a.sequence.empty()) throw InputError("--method none: converts a still (--in/--color), not a --sequence");
    io::BufferFiles files = stillFiles(a);
    files.wanted = [](io::Buffer b, const bool*) { return b == io::Buffer::Color; };
    io::BufferSet set = io::loadBuffers(files);
    if (!a.addPass.empty() && (!set.layered || io::extensionOf(a.out) != ".exr"))
        throw InputError("--add-pass '" + a.addPass + "' writes a copy of a layered EXR: give --in FILE.exr and --out COPY.exr");
    const StillExtras extras = readStillExtras(files, set, a.ldr);
    Image& color = set.image[int(io::Buffer::Color)];
    if (a.srgb && !extras.ldrFile) srgbToLinear(color);
    int nonFinite = 0;
    for (size_t i = 0; i < color.plane() * size_t(color.channels()); ++i)
        if (!std::isfinite(color.data()[i])) color.data()[i] = 0.0f, ++nonFinite;
    const int width = color.width(), height = color.height();
    bool alphaDropped = false;
    const Image out = stillOutput(std::move(color), extras, a.srgb, a.out, &alphaDropped);
    writeStill(a, set, out);
    resultLine("denoise: method none (no filter: the colour written as read), %dx%d\n", width, height);
    logLine("%s", stillExtrasLines(extras, a.out, alphaDropped).c_str());
    if (nonFinite > 0) logLine("denoise: %d NaN/Inf colour values written as 0\n", nonFinite);
    resultLine("denoise: wrote %s\n", a.out.c_str());
}

// --spatial, the still method of a sequence method that ends with one (`row`): whether it applies;
// InputError when it was given to another method or names no still method.
bool checkSpatial(const DenoiseArgs& a, const CLI::App& cmd, const SequenceMethodInfo* row) {
    const bool spatial = row && row->stillMethod;
    if (cmd.count("--spatial") > 0 && !spatial)
        throw InputError("--spatial: the still method of --method " + spatialMethods() +
                         (sequenceMethods().front().stillMethod ? " (the default with --sequence)" : "") +
                         "; --method is " + a.method);
    if (spatial && !findDenoiseMethod(a.spatial))
        throw InputError("--spatial: unknown still method '" + a.spatial + "' (expected " + denoiseMethodNames() + ")");
    return spatial;
}

// --sequence DIR: the library's session with the still options a.opt and the sequence method's
// parameters (null for a still method).
void runSequence(const DenoiseArgs& a, const ParamSet* params) {
    if (!a.input.in.empty() || !a.input.file[int(io::Buffer::Color)].empty())
        throw InputError("--sequence DIR denoises the frames of DIR: drop --in/--color");
    SequenceDenoiseArgs s;
    s.sequenceDir = a.sequence;
    s.outDir = a.out;
    SequenceDenoiseOptions& so = s.options;
    so.method = a.method;
    so.device = a.opt.device;
    if (params) so.params = *params;
    so.frame = a.opt;
    withFlag("--pass", [&] { return io::parsePassRequests(a.input.passes); });  // its own message first
    so.passes = a.input.passes;
    so.viewLayer = a.input.layer;
    so.addPass = a.addPass;
    so.start = a.range.start, so.end = a.range.end, so.step = a.range.step;
    so.exposure = a.exposure;
    runSequenceDenoise(s);
}

void run(DenoiseArgs& a, const CLI::App& cmd) {
    takePositionals(a);
    const auto threadLimit = limitThreads(a.threads);  // for the whole run
    if (!(a.exposure > 0.0f) || !std::isfinite(a.exposure)) throw InputError("--exposure: must be > 0");
    if (!a.ldrColor.empty()) {
        if (!a.input.file[int(io::Buffer::Color)].empty()) throw InputError("--ldr: give the colour once (--color/--hdr or --ldr)");
        a.input.file[int(io::Buffer::Color)] = a.ldrColor;
        a.ldr = true;
    }
    if (a.srgb && !a.ldr) throw InputError("--srgb: only with --ldr (an sRGB-encoded LDR colour)");
    if (a.oidnFilter != "RT")
        throw InputError("-f/--filter: '" + a.oidnFilter + "' is not supported (atrous denoises RT images: use RT)");
    DenoiseOptions& o = a.opt;
    const bool sequence = !a.sequence.empty();
    if (a.method == "none") {
        runNone(a);
        return;
    }
    for (const char* f : {"--start", "--end", "--step"})
        if (!sequence && cmd.count(f) > 0) throw InputError(std::string(f) + ": picks frames of a --sequence; give one");
    // A sequence without --method: the first sequence method (temporal: the frames around each one).
    if (sequence && cmd.count("--method") == 0) a.method = sequenceMethods().front().name;
    const SequenceMethodInfo* row = findSequenceMethod(a.method);
    if (!row && !findDenoiseMethod(a.method))
        throw InputError("--method: unknown denoise method '" + a.method + "' (expected " + denoiseMethodNames() +
                         ", or with --sequence " + sequenceMethodNames() + ")");
    if (row && !sequence)
        throw InputError("--method " + a.method + " denoises animated sequences: give --sequence DIR (and an output directory)");
    const bool spatial = checkSpatial(a, cmd, row);
    o.method = row && !spatial ? DenoiseMethod::Sure : parseDenoiseMethod(spatial ? a.spatial : a.method);
    checkParamFlags(o, denoiseParams(), cmd);
    const ParamSet* params = nullptr;  // the row's, as its flags set them
    for (size_t i = 0; row && i < sequenceMethods().size(); ++i)
        if (&sequenceMethods()[i] == row) params = &a.sequenceParams[i];
    if (params) checkParamFlags(*params, cmd);
    o.device = parseDevice(a.device);
    const bool learnedSequence = row && sequenceMethodReadsWeights(*row, *params);
    const DenoiseMethodInfo* still = row && !spatial ? nullptr : findDenoiseMethod(spatial ? a.spatial : a.method);
    noteIgnoredFlags(cmd, a.method, still, sequence, learnedSequence);
    // A bad weight file fails here, before any buffer is read or anything written.
    LearnedWeights weights;
    if (((still && readsWeights(*still)) || learnedSequence) && !a.learnedWeights.empty())
        weights = withFlag("--learned-weights", [&] { return LearnedWeights::load(a.learnedWeights); });
    o.weights = weights;  // loaded once: denoise() does not read the file again
    if (sequence) {
        runSequence(a, params);
        return;
    }
    const std::string ext = io::extensionOf(a.out);
    io::BufferFiles files = stillFiles(a);
    // Only the buffers the method reads are decoded (auto: by the buffers present).
    files.wanted = [&](io::Buffer b, const bool present[io::kBufferCount]) {
        const DenoiseMethod m = resolveDenoiseMethod(o.method, present[int(io::Buffer::Albedo)], present[int(io::Buffer::Normal)]);
        return denoiseReads(o, m).has(b);
    };
    Timer readTimer;
    io::BufferSet set = io::loadBuffers(files);
    // LDR colour, alpha, no finite pixel (still_output.h): checked before anything is denoised.
    const StillExtras extras = readStillExtras(files, set, a.ldr);
    const double readMs = readTimer.ms();
    if (!a.addPass.empty() && (!set.layered || ext != ".exr"))
        throw InputError("--add-pass '" + a.addPass + "' writes a copy of a layered EXR: give --in FILE.exr and --out COPY.exr");
    Image& color = set.image[int(io::Buffer::Color)];
    if (a.srgb && !extras.ldrFile) srgbToLinear(color);  // an 8-bit file is decoded by its reader
    const int width = color.width(), height = color.height();
    const bool albedoGiven = set.get(io::Buffer::Albedo) != nullptr;
    // The colour, variance and emission were read to be denoised: the filter works in their
    // storage (DenoiseBuffers) and they are not read afterwards.
    DenoiseBuffers in = handOver(io::refsOf(set), color, &set.image[int(io::Buffer::Variance)],
                                     &set.image[int(io::Buffer::Emission)]);
    static constexpr io::Buffer kLabelled[] = {io::Buffer::Color,    io::Buffer::Variance, io::Buffer::Albedo,
                                              io::Buffer::Normal,   io::Buffer::Position, io::Buffer::Depth,
                                              io::Buffer::ObjectId, io::Buffer::Emission};
    static const char* const kLibraryNames[] = {"color", "variance", "albedo", "normal", "position", "depth", "ids", "emission"};
    Timer t;
    DenoiseResult result;
    try {
        result = denoiseWithReport(in, o);
    } catch (const InputError& e) {
        // Name the buffer's file: library messages name the buffer ("variance buffer has ...").
        throw InputError(io::withSourceFile(e.what(), [&](const std::string& name) {
            for (size_t i = 0; i < std::size(kLabelled); ++i)
                if (name == kLibraryNames[i]) return set.from[int(kLabelled[i])];
            return std::string();
        }, ""));
    }
    const double ms = t.ms();
    const DenoiseReport& rep = result.report;
    bool alphaDropped = false;
    const Image out = stillOutput(std::move(result.image), extras, a.srgb, a.out, &alphaDropped);
    Timer writeTimer;
    writeStill(a, set, out);
    const double writeMs = writeTimer.ms();
    const std::string method = o.method == DenoiseMethod::Auto
                                   ? std::string("auto -> ") + denoiseMethodName(rep.methodUsed) +
                                         (rep.methodUsed == DenoiseMethod::Blend ? " (albedo and normal given)"
                                                                                : " (the learned filter needs an albedo and a normal)")
                                   : std::string(denoiseMethodName(o.method));
    // Results on stdout (the method that ran, the file written); the rest on stderr (progress.h).
    resultLine("denoise: method %s on %s, %dx%d, buffers used: %s\n", method.c_str(), deviceToString(o.device), width, height,
                rep.buffersUsed.c_str());
    if (rep.noiseEstimated)
        logLine("denoise: no variance buffer: noise estimated from the image, per pixel (docs/algorithms.md), at least "
                    "the global MAD sigma = %.4g %.4g %.4g%s\n",
                    rep.noiseSigma[0], rep.noiseSigma[1], rep.noiseSigma[2], albedoGiven && o.demodulate ? " (of the demodulated colour)" : "");
    logLine("%s", stillExtrasLines(extras, a.out, alphaDropped).c_str());
    if (rep.nonFinitePixels > 0)
        logLine("denoise: %d pixels had NaN/Inf colour, treated as missing\n", rep.nonFinitePixels);
    if (o.firefly.enabled)
        verbose("denoise: fireflies clamped: %d pixels, mean luminance %.6g -> %.6g\n", rep.firefliesClamped,
                    rep.meanLuminanceIn, rep.meanLuminanceAfterFirefly);
    if (!set.skipped.empty()) {
        std::string list;
        for (io::Buffer b : set.skipped)
            if (b != io::Buffer::MaterialId) list += (list.empty() ? "" : ", ") + std::string(io::bufferName(b));
        verbose("denoise: not read (unused by %s): %s\n", denoiseMethodName(rep.methodUsed), list.c_str());
    }
    resultLine("denoise: read %.2f ms, filter %.2f ms, total %.2f ms, write %.2f ms, wrote %s\n", readMs, rep.milliseconds, ms,
                writeMs, a.out.c_str());
    if (!rep.stages.empty()) {  // the filter's own stages (DenoiseReport::stages), with -v
        std::string line = "denoise: stages ms:";
        char buf[96];
        for (size_t i = 0; i < rep.stages.size(); ++i) {
            std::snprintf(buf, sizeof buf, "%s %.2f", rep.stages[i].name.c_str(), rep.stages[i].milliseconds);
            line += std::string(i ? ", " : " ") + buf;
        }
        verbose("%s\n", line.c_str());
    }
}

}  // namespace

void addDenoiseCommand(CLI::App& app) {
    auto a = std::make_shared<DenoiseArgs>();
    auto* cmd = app.add_subcommand(
        "denoise", "Denoise a render with EAW, SURE-based a-trous wavelets or the learned a-trous filter, or an animated "
                   "sequence (also SVGF)");
    cmd->add_option("IN OUT", a->positional,
                    "atrous denoise IN OUT: IN as --in takes it (a render folder, a layered EXR), OUT as --out (the "
                    "flags do the same; with --sequence DIR or --color FILE, one positional is OUT)")
        ->type_name("");
    addInputFlags(*cmd, a->input, "", kGroupBuffers);  // --in/-i, --pass, --layer, --color/--hdr; the buffers' files
    cmd->add_option("--add-pass", a->addPass,
                    "With --in FILE.exr: write --out as a copy of FILE with the denoised colour added as this pass "
                    "(with --sequence of layered EXRs: each output frame is such a copy of its frame)");
    cmd->add_option("--sequence", a->sequence,
                    "Sequence directory: frame_NNNN/ folders (atrous render --frames), numbered frame folders of "
                    "another renderer (0001/ with LuxCore's RGB.exr, ALBEDO.exr ...), numbered files per buffer "
                    "(color_0001.exr, albedo_0001.exr ...) or numbered layered EXRs (Blender's render0001.exr ...; "
                    "--pass, --layer and --add-pass apply to every frame); or a pattern (DIR/render####.exr, "
                    "DIR/render%04d.exr). --out is then a directory (never the sequence directory or inside it) or a "
                    "pattern such as clean/####.exr");
    cmd->add_option("--start", a->range.start, "With --sequence: the first frame number to denoise (default: the first)");
    cmd->add_option("--end", a->range.end, "With --sequence: the last frame number to denoise (default: the last)");
    cmd->add_option("--step", a->range.step, "With --sequence: denoise every step-th frame from --start")
        ->capture_default_str();
    cmd->add_option("--ldr", a->ldrColor, "Noisy LDR colour in [0, 1] (oidnDenoise's --ldr): the output is clamped to [0, 1]");
    cmd->add_flag("--srgb", a->srgb, "With --ldr: the colour is sRGB-encoded (decoded before, encoded after; a PNG/JPEG always is, and a "
                  ".png output is always encoded)");
    cmd->add_option("--out,-o", a->out,
                    "Output file (.exr, .pfm or .png); with --sequence, an output directory where each frame keeps "
                    "its input's name (render0001.exr -> OUT/render0001.exr, a frame folder 0001/ -> OUT/0001.exr; "
                    "+ .png previews, + preview.mp4), or a pattern OUT/clean####.exr (or %04d): the frame number "
                    "zero-padded to the count of #'s. Written only once every frame is denoised (on error it is "
                    "left as it was); an existing folder keeps its other files, files of the same name are "
                    "replaced, and an earlier run's frame_NNNN.exr/.png this run does not write (and an old "
                    "preview.mp4) are removed, named in a note on stderr (or OUT, the last positional)");
    std::string methodHelp;
    for (const DenoiseMethodInfo& m : denoiseMethods()) methodHelp += std::string(m.name) + ": " + m.summary + "; ";
    for (const SequenceMethodInfo& m : sequenceMethods())
        methodHelp += std::string(m.name) + " (with --sequence): " + m.summary + "; ";
    cmd->add_option("--method", a->method, methodHelp + "none: no filter, the colour written as read (a conversion: a "
                    "noisy EXR to a PNG); the output line says which method ran")
        ->capture_default_str();
    for (const SequenceMethodInfo& m : sequenceMethods())
        if (m.stillMethod) {  // in the first such method's group
            cmd->add_option("--spatial", a->spatial, "With --method " + spatialMethods() + ": the still method it ends with")
                ->capture_default_str()
                ->group(sequenceGroup(m, true));
            break;
        }
    cmd->add_option("--learned-weights", a->learnedWeights,
                    "Weight file of the learned filter (version 4, or 3; docs/learned.md; default: the built-in weights)")
        ->group(learnedGroup());
    cmd->add_option("--device,-d", a->device, "cpu | cuda | auto (cuda when a GPU is present; oidnDenoise's 'default' = auto)")
        ->capture_default_str()
        ->transform([](std::string v) { return v == "default" ? std::string("auto") : v; });  // the device auto
    // oidnDenoise's other flags, so that a script written for it runs unchanged (docs/inputs.md).
    const char* kGroupOidn = "oidnDenoise compatibility";
    cmd->add_option("-f,--filter", a->oidnFilter, "oidnDenoise's filter type: RT only")->group(kGroupOidn);
    cmd->add_option("-q,--quality", a->oidnQuality, "oidnDenoise's quality (accepted, no effect: use --method)")->group(kGroupOidn);
    cmd->add_flag("--clean_aux", a->oidnCleanAux, "oidnDenoise's noise-free-features flag (accepted: atrous's "
                  "features are edge stops, never filtered)")->group(kGroupOidn);
    // One flag per parameter (params.h): --levels, --sigma-normal, --no-firefly, --sure-window, ...
    addParamOptions(*cmd, a->opt, denoiseParams(), paramHelpGroup);
    addSequenceOptions(*cmd, a->sequenceParams);
    cmd->add_option("--threads", a->threads, "CPU worker threads (TBB; 0 = all cores)")->capture_default_str();
    cmd->add_option("--exposure", a->exposure,
                    "Exposure of a .png output and of a sequence's .png previews: png = srgb(clamp(exposure x value, 0, "
                    "1)), as Python's exposure; the EXRs are never scaled")
        ->capture_default_str();
    addVerbosityFlags(*cmd);
    cmd->callback([a, cmd] { run(*a, *cmd); });
}

}  // namespace atrous::cli

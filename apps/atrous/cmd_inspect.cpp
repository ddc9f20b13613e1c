// `atrous inspect FILE.exr`: the parts, layers and channels of an EXR, and which of them
// `atrous denoise --in FILE.exr` would take for each buffer (the same io::mapPasses).
// `--export DIR` also writes those buffers, as atrous reads them (io::loadBuffers: every
// convention applied), as plain EXRs in DIR. A render directory (color.exr, albedo.exr, ...: a
// Mitsuba separate-files render has that layout) is taken as `denoise --in DIR` takes it.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "atrous/error.h"
#include "cli_flags.h"
#include "commands.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "atrous/io/pass_map.h"
#include "atrous/io/paths.h"
#include "atrous/io/sequence.h"

namespace atrous::cli {

namespace fs = std::filesystem;

namespace {

struct InspectArgs {
    std::string file, layer, exportDir;
    std::vector<std::string> passes;
};

// The file name of buffer b in an export (and in a render directory); the ids take object_id's slot.
std::string exportName(io::Buffer b) {
    if (b == io::Buffer::ObjectId) return "ids.exr";
    return std::string(io::bufferName(b)) + ".exr";
}

// A buffer as a plain 3-channel image: 1 channel repeated, 2 (motion) with B = 0.
Image asRgb(const Image& src) {
    if (src.channels() == 3) {
        Image out(src.width(), src.height(), 3);
        std::copy(src.data(), src.data() + src.size(), out.data());
        return out;
    }
    Image out(src.width(), src.height(), 3);
    const size_t n = src.plane();
    for (int c = 0; c < 3; ++c) {
        const int from = src.channels() == 1 ? 0 : c;
        if (from >= src.channels()) continue;  // stays 0
        std::copy(src.data() + size_t(from) * n, src.data() + size_t(from + 1) * n, out.data() + size_t(c) * n);
    }
    return out;
}

// Writes every buffer of `set` into dir (each file atomically); removes the files of buffers this
// input has not (an earlier export's), so that DIR describes this input alone.
void exportBuffers(const io::BufferSet& set, const std::string& dir) {
    io::ensureWritableDirectory(dir);
    std::vector<std::pair<std::string, Image>> files;
    for (int b = 0; b < io::kBufferCount; ++b) {
        if (io::Buffer(b) == io::Buffer::MaterialId) continue;  // inside ids.exr (G)
        const Image* img = set.get(io::Buffer(b));
        if (img) files.emplace_back(exportName(io::Buffer(b)), asRgb(*img));
    }
    for (const auto& [name, img] : files) io::writeExr((fs::path(dir) / name).string(), img);
    for (int b = 0; b < io::kBufferCount; ++b) {
        if (io::Buffer(b) == io::Buffer::MaterialId || set.get(io::Buffer(b))) continue;
        const fs::path stale = fs::path(dir) / exportName(io::Buffer(b));
        std::error_code ec;
        if (fs::is_regular_file(stale, ec) && fs::remove(stale, ec))
            std::printf("export: removed %s (an earlier export's: this input has no %s)\n", stale.string().c_str(),
                        io::bufferName(io::Buffer(b)));
    }
    std::printf("export: wrote");
    for (const auto& f : files) std::printf(" %s", f.first.c_str());
    std::printf(" to %s\n", dir.c_str());
}

io::BufferSet load(const InspectArgs& a, const std::vector<io::PassRequest>& requests) {
    io::BufferFiles f;
    f.in = a.file;
    f.passes = requests;
    f.viewLayer = a.layer;
    return io::loadBuffers(f);
}

// --export DIR never writes (or removes as an earlier export's) a file the input is read from.
void refuseExportOverInputs(const InspectArgs& a, const std::vector<io::PassRequest>& requests) {
    if (a.exportDir.empty()) return;
    io::BufferFiles f;
    f.in = a.file;
    f.passes = requests;
    const std::vector<std::string> inputs = io::inputFiles(f);
    for (int b = 0; b < io::kBufferCount; ++b)
        io::refuseOverwrite("--export", (fs::path(a.exportDir) / exportName(io::Buffer(b))).string(), inputs);
}

// A sequence (a folder of frames, or a pattern such as DIR/render####.exr): its layout, and what
// `denoise --sequence` takes per buffer (the first frame's file; every frame has the same buffers,
// validateSequence checks it).
void inspectSequence(const InspectArgs& a, const std::vector<io::PassRequest>& requests) {
    if (!a.exportDir.empty())
        throw InputError("--export: writes the buffers of one frame; give one frame of the sequence " + a.file);
    io::SequenceOptions so;
    so.passes = requests;
    so.viewLayer = a.layer;
    const std::vector<std::string> frames = io::listSequenceFrames(a.file);
    int w = 0, h = 0;
    const std::vector<std::string> present = io::validateSequence(frames, w, h, so);
    const io::SequenceFrame first = io::loadSequenceFrame(frames.front(), present, so);
    std::printf("%s: sequence of %zu frame%s (%s ... %s), %dx%d\natrous denoise --sequence %s takes, in every frame:\n",
                a.file.c_str(), frames.size(), frames.size() == 1 ? "" : "s", fs::path(frames.front()).filename().c_str(),
                fs::path(frames.back()).filename().c_str(), w, h, a.file.c_str());
    for (const char* name : io::kSequenceBuffers) {
        const bool has = std::find(present.begin(), present.end(), name) != present.end();
        std::printf("  %-12s %s\n", name, has ? (first.fileOf(name) + " ...").c_str() : "-");
    }
}

// A folder without a colour file of its own, or a frame pattern (an existing file is inspected as one).
bool isSequence(const std::string& file) {
    std::error_code ec;
    if (fs::is_directory(file, ec)) return io::dirBufferFile(file, "color").empty();
    return !fs::exists(file, ec) && io::isSequencePattern(file);
}

void run(const InspectArgs& a) {
    const std::vector<io::PassRequest> requests = withFlag("--pass", [&] { return io::parsePassRequests(a.passes); });
    if (isSequence(a.file)) return inspectSequence(a, requests);
    refuseExportOverInputs(a, requests);
    std::error_code ec;
    if (fs::is_directory(a.file, ec)) {  // a render directory: what denoise --in DIR takes
        const io::BufferSet set = load(a, requests);
        if (!a.exportDir.empty()) io::ensureWritableDirectory(a.exportDir);
        std::printf("%s: render directory, %dx%d\natrous denoise --in %s takes:\n", a.file.c_str(),
                    set.image[0].width(), set.image[0].height(), a.file.c_str());
        for (int b = 0; b < io::kBufferCount; ++b)
            std::printf("  %-12s %s\n", io::bufferName(io::Buffer(b)), set.from[b].empty() ? "-" : set.from[b].c_str());
        if (!a.exportDir.empty()) exportBuffers(set, a.exportDir);
        return;
    }
    const io::ExrInfo info = io::inspectExr(a.file);
    // With --export, read every buffer and check DIR first: bad input stops here, before anything is
    // printed or written.
    std::unique_ptr<io::BufferSet> set;
    if (!a.exportDir.empty()) {
        set = std::make_unique<io::BufferSet>(load(a, requests));
        io::ensureWritableDirectory(a.exportDir);
    }
    std::printf("%s: %dx%d, %zu part%s, %zu channels\n", a.file.c_str(), info.width, info.height, info.parts.size(),
                info.parts.size() == 1 ? "" : "s", info.channels.size());
    for (size_t p = 0; p < info.parts.size(); ++p)
        std::printf("  part %zu: '%s' %s %dx%d\n", p, info.parts[p].name.c_str(), info.parts[p].type.c_str(),
                    info.parts[p].width, info.parts[p].height);
    std::printf("layers:\n");
    for (const io::ExrLayer& l : info.layers) std::printf("  %s\n", io::describeLayer(info, l).c_str());
    const io::PassMap m = io::mapPasses(info, requests, a.layer);
    std::printf("atrous denoise --in %s takes:\n", a.file.c_str());
    for (int b = 0; b < io::kBufferCount; ++b) {
        const io::PassChoice& c = m.pass[size_t(b)];
        std::string what = "-";
        if (c.found()) {
            what.clear();
            for (int ch : c.channels) what += (what.empty() ? "" : ",") + info.channels[size_t(ch)].fullName;
            what += "  (" + c.rule + ")";
        }
        std::printf("  %-12s %s\n", io::bufferName(io::Buffer(b)), what.c_str());
    }
    if (!m.pass[size_t(io::Buffer::Color)].found())
        std::printf("no colour pass: name one with --pass color=LAYER\n");
    std::string moments;
    for (const io::ExrLayer& l : info.layers)
        if (io::isSecondMomentLayer(l)) moments += (moments.empty() ? "" : ", ") + l.name;
    if (!moments.empty())
        std::printf("not taken: %s (Mitsuba's moment integrator: second moments of the samples, not buffers)\n",
                    moments.c_str());
    if (set) {
        for (const std::string& n : set->notes) std::printf("note: %s\n", n.c_str());
        exportBuffers(*set, a.exportDir);
    }
}

}  // namespace

void addInspectCommand(CLI::App& app) {
    auto a = std::make_shared<InspectArgs>();
    auto* cmd = app.add_subcommand("inspect", "List the parts, layers and channels of an EXR and the passes atrous denoise takes");
    cmd->add_option("file", a->file, "EXR file, a render directory (color.exr, albedo.exr, ...), or a sequence (a folder of frames, or a pattern "
                      "DIR/render####.exr): what denoise --sequence takes per buffer")->required();
    cmd->add_option("--pass", a->passes, "BUFFER=NAME, as for atrous denoise (repeatable)");
    cmd->add_option("--layer", a->layer, "View layer, as for atrous denoise");
    cmd->add_option("--export", a->exportDir,
                    "Write the buffers atrous takes from FILE, every convention applied (normals, depth background "
                    "1e30, albedo in [0, 1], Blender's Vector as atrous motion, ids R object G material), into DIR "
                    "as color.exr, albedo.exr, normal.exr, depth.exr, ... (3-channel EXRs, each written atomically)");
    cmd->callback([a] { run(*a); });
}

}  // namespace atrous::cli

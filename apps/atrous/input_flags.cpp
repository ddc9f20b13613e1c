// The still input flags (input_flags.h).
#include "input_flags.h"

#include <cctype>
#include <cstring>
#include <iterator>

#include "atrous/io/pass_map.h"
#include "cli_flags.h"

namespace atrous::cli {

namespace {

// The buffers with a file flag of their own, their flags (with aliases) and help lines.
struct FileFlag {
    io::Buffer buffer;
    const char* names;  // CLI11's "--albedo,--alb"
    const char* help;
};
constexpr FileFlag kFileFlags[] = {
    {io::Buffer::Color, "--color,--hdr",
     "Noisy colour (EXR/PFM, HDR; --hdr as in oidnDenoise). An 8-bit PNG/JPEG is LDR: sRGB-decoded to [0, 1], "
     "denoised, clamped to [0, 1] (docs/inputs.md, \"LDR input\"); its alpha, like an EXR's, is passed through"},
    {io::Buffer::Variance, "--variance", "Per-channel variance of the pixel mean"},
    {io::Buffer::Albedo, "--albedo,--alb", "Albedo buffer (a layered EXR: its albedo pass)"},
    {io::Buffer::Normal, "--normal,--nrm", "Normal buffer, world or camera space"},
    {io::Buffer::Position, "--position", "World-space position buffer"},
    {io::Buffer::Depth, "--depth", "View depth buffer"},
    {io::Buffer::ObjectId, "--ids", "Mesh id (R) / material id (G) buffer"},
    {io::Buffer::Emission, "--emission", "Emitted radiance of the primary hit (filtered around, added back)"},
};

}  // namespace

bool InputFlags::any() const {
    bool given = !in.empty() || !passes.empty() || !layer.empty();
    for (const std::string& s : file) given = given || !s.empty();
    return given;
}

void addInputFlags(CLI::App& cmd, InputFlags& f, const std::string& group, const std::string& bufferGroup) {
    auto in = [&](CLI::Option* o, const std::string& g) {
        if (!g.empty()) o->group(g);
    };
    in(cmd.add_option("--in,-i", f.in,
                   "Render directory (color.exr, variance.exr, albedo.exr, normal.exr, ...; LuxCore's RGB.exr, "
                   "ALBEDO.exr, ...) or a layered EXR (Blender multilayer, Mitsuba aov): its passes are taken by name "
                   "(atrous inspect FILE shows which)"),
       group);
    in(cmd.add_option("--pass", f.passes,
                      "BUFFER=NAME: take BUFFER (color, variance, albedo, normal, position, depth, object_id, "
                      "material_id, emission, motion) from the layer or channel NAME of a layered EXR (repeatable)"),
       group);
    in(cmd.add_option("--layer", f.layer, "View layer of a layered EXR with several (Blender: the ViewLayer name)"), group);
    for (const FileFlag& ff : kFileFlags)
        in(cmd.add_option(ff.names, f.file[int(ff.buffer)], ff.help), ff.buffer == io::Buffer::Color ? group : bufferGroup);
}

const char* bufferFlag(io::Buffer b) {
    static const char* const kFlags[] = {"--color", "--variance", "--albedo", "--normal", "--position", "--depth", "--ids"};
    if (b == io::Buffer::Emission) return "--emission";
    return int(b) < int(std::size(kFlags)) ? kFlags[int(b)] : "";
}

io::BufferFiles bufferFiles(const InputFlags& f) {
    io::BufferFiles files;
    files.in = f.in;
    for (const FileFlag& ff : kFileFlags) files.file[int(ff.buffer)] = f.file[int(ff.buffer)];
    files.viewLayer = f.layer;
    files.passes = withFlag("--pass", [&] { return io::parsePassRequests(f.passes); });
    return files;
}

std::string shellQuote(const std::string& word) {
    bool safe = !word.empty();
    for (char c : word)
        safe = safe && (std::isalnum(static_cast<unsigned char>(c)) || std::strchr("@%+=:,./_-", c) != nullptr);
    if (safe) return word;
    std::string q = "'";
    for (char c : word) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

std::string inputCommandLine(const InputFlags& f) {
    std::string s;
    if (!f.in.empty()) s += " --in " + shellQuote(f.in);
    for (const FileFlag& ff : kFileFlags)
        if (!f.file[int(ff.buffer)].empty()) s += std::string(" ") + bufferFlag(ff.buffer) + " " + shellQuote(f.file[int(ff.buffer)]);
    for (const std::string& p : f.passes) s += " --pass " + shellQuote(p);
    if (!f.layer.empty()) s += " --layer " + shellQuote(f.layer);
    return s;
}

}  // namespace atrous::cli

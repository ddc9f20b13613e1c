// The viewer's "write image + command" (write_result.h).
#include "view/write_result.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "atrous/error.h"
#include "atrous/io/image_io.h"
#include "atrous/param_set.h"
#include "atrous/params.h"
#include "input_flags.h"
#include "still_output.h"

namespace atrous::view {

std::string denoiseCommand(const std::string& method, const DenoiseOptions& o, const std::string& input,
                           const std::string& device, const std::string& out, std::string* unset) {
    std::string cmd = "atrous denoise" + input + " --method " + cli::shellQuote(method) + " --device " + device;
    const ParamSet now(denoiseParams(), o), defaults(denoiseParams());
    unset->clear();
    for (size_t i = 0; i < now.rows().size(); ++i) {
        const ParamRow& row = now.rows()[i];
        const ParamRef v = now.at(i);
        const std::string text = paramText(v, row.choices);
        if (text == paramText(defaults.at(i), row.choices)) continue;
        // A Bool's flag sets it (or, negated, clears it): only the value the flag gives can be written.
        const bool* b = std::holds_alternative<bool*>(v) ? std::get<bool*>(v) : nullptr;
        if (row.flag.empty() || (b && *b == row.negated)) {
            *unset += (unset->empty() ? "" : ", ") + std::string(row.name) + " = " + text;
            continue;
        }
        cmd += " " + row.flag + (b ? "" : " " + cli::shellQuote(text));
    }
    return cmd + " --out " + cli::shellQuote(out);
}

namespace {

// The first view_NNNN under dir with none of its three files present.
std::string freeStem(const std::string& dir) {
    namespace fs = std::filesystem;
    for (int i = 1;; ++i) {
        char name[32];
        std::snprintf(name, sizeof(name), "view_%04d", i);
        const fs::path stem = fs::path(dir) / name;
        std::error_code ec;
        if (!fs::exists(stem.string() + ".exr", ec) && !fs::exists(stem.string() + ".png", ec) &&
            !fs::exists(stem.string() + ".txt", ec))
            return stem.string();
    }
}

// Why method m has no single-still command ("" when it has one).
std::string noCommand(const Method& m, const FileSource* files) {
    if (!files) return "a rendered scene has no files for `atrous denoise` to read (F12 / P saves its buffers)";
    if (m.kind == Method::Kind::None) return "method none shows the noisy input";
    if (m.kind == Method::Kind::Sequence)
        return std::string("method ") + methodName(m) + " is a sequence method: `atrous denoise --sequence` runs it over "
               "the whole sequence, not causally up to one frame as the viewer does";
    return "";
}

}  // namespace

WrittenResult writeResult(const ViewPipeline& pl, const PipelineSettings& ps, const FileSource* files,
                          const std::string& device, const std::string& outDir) {
    io::ensureWritableDirectory(outDir);
    const std::string stem = freeStem(outDir);
    WrittenResult w{stem + ".exr", stem + ".png", stem + ".txt", "", ""};
    const SlotResult& slot = pl.slot(0);
    const Image& result = slot.method == Method::none() ? pl.color() : pl.resultHost(0);
    if (result.empty()) throw RuntimeError("view: no result to write yet");
    // As `atrous denoise` writes its output: a still's alpha passed through, an LDR input clamped.
    const cli::StillExtras none;
    const cli::StillExtras& extras = files && files->extras() ? *files->extras() : none;
    bool dropped = false;
    atrous::writeImage(w.exr, cli::stillOutput(result.clone(), extras, false, w.exr, &dropped));
    atrous::writeImage(w.png, cli::stillOutput(result.clone(), extras, false, w.png, &dropped));
    w.note = noCommand(ps.methodA, files);
    if (w.note.empty() && !slot.error.empty()) w.note = "the filter refused its parameters: " + slot.error;
    std::string text;
    if (w.note.empty()) {
        std::string unset;
        w.command = denoiseCommand(methodName(ps.methodA), ps.denoise, files->denoiseInput(), device, w.exr, &unset);
        if (!unset.empty()) w.note = "no flag sets " + unset + " (the command runs with the default)";
        text = w.command + "\n";
    }
    if (!w.note.empty()) text += "# " + w.note + "\n";
    std::ofstream txt(w.txt);
    txt << text;
    if (!txt) throw RuntimeError(w.txt + ": cannot write");
    return w;
}

}  // namespace atrous::view

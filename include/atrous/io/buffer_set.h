// The buffers of one denoise call, read from what the user named (docs/inputs.md): a render
// directory as atrous writes it (color.exr, albedo.exr, ...), a layered EXR (Blender's multilayer
// file, Mitsuba's aov output), separate files per buffer, or a mix (explicit files win).
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "atrous/buffers.h"
#include "atrous/image.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/pass_map.h"
#include "atrous/io/sequence.h"

namespace atrous::io {

struct BufferFiles {
    std::string in;  // a render directory or a layered EXR file (may be empty)
    // Explicit files by buffer. The object_id slot takes atrous's ids.exr (R = mesh id, G =
    // material id); material_id has no file of its own.
    std::string file[kBufferCount];
    std::vector<PassRequest> passes;  // --pass BUFFER=NAME
    std::string viewLayer;            // --layer NAME
    // Which buffers to decode, given which are present (by buffer; material_id follows object_id,
    // colour is always decoded): empty = all. The others are listed in BufferSet::skipped.
    std::function<bool(Buffer, const bool present[kBufferCount])> wanted;
};

struct BufferSet {
    // By buffer, as the filters read them: 3 planes, but depth 1, motion 2 and the ids 2 (in the
    // object_id slot: R = object, G = material id). Empty when absent.
    Image image[kBufferCount];
    std::string from[kBufferCount];  // where each came from, for messages and `inspect`
    std::shared_ptr<ExrInfo> layered;  // the layered file given as `in`, if any
    std::vector<std::string> notes;    // conventions applied, passes not found, ...
    std::vector<Buffer> skipped;       // present but not decoded (BufferFiles::wanted)
    const Image* get(Buffer b) const { return image[int(b)].empty() ? nullptr : &image[int(b)]; }
    Frame inputs() const;  // refsOf(*this)
};

// One set of buffers, not owned: a Frame (atrous/buffers.h; ids in the object_id slot, as in
// BufferSet). Every entry point (render --denoise, denoise, denoise --sequence, the viewer,
// Python) puts what it holds here and hands it to the denoisers as it is, so a new buffer reaches
// all of them at once (a render's: RenderBuffers::frame(), atrous/render.h).
Frame refsOf(const BufferSet& set);
Frame refsOf(const SequenceFrame& f);  // all but the reference

// Every file loadBuffers(files) reads or could read: the explicit files, `in` when it is a file,
// and for a render directory each buffer's file name in it (color.exr, albedo.exr, ...: present
// or not, since a file written there would be read as that buffer next time). Outputs are checked
// against this list (io/paths.h) before anything runs.
std::vector<std::string> inputFiles(const BufferFiles& files);

// The file a render directory (`--in DIR`) or a sequence's frame folder gives for a buffer, by its
// name ("color", "variance", "albedo", "normal", "position", "depth", "ids", "emission", "motion",
// "reference"): atrous's own name (color.exr, ...) when it is there, else another renderer's name for
// that buffer, in dirBufferNames()'s order (LuxCore's film outputs as its documentation names them:
// RGB.exr, ALBEDO.exr, AVG_SHADING_NORMAL.exr or SHADING_NORMAL.exr, POSITION.exr, DEPTH.exr,
// EMISSION.exr). "" when the directory has none of them (docs/inputs.md, "Render directories").
std::string dirBufferFile(const std::string& dir, const std::string& buffer);
// The file names dirBufferFile tries for `buffer`, in order (empty for an unknown name).
std::vector<std::string> dirBufferNames(const std::string& buffer);

// A denoiser's message about a buffer ("variance buffer has a value of ...", "SVGF frame: the
// normal buffer is ...") with the file that buffer came from in front ("FILE: variance buffer has
// ..."). fileOf(name) gives that file for a library buffer name (color, variance, albedo, normal,
// position, depth, ids, emission, motion; "" when unknown); a message that names no buffer gets
// `fallback` in front (when not empty).
std::string withSourceFile(const std::string& msg, const std::function<std::string(const std::string&)>& fileOf,
                           const std::string& fallback);

// Reads every buffer that `files` names or that `files.in` holds. Throws InputError naming the
// file (and part) for a missing colour, an unreadable file, an ambiguous or empty pass mapping, or
// a buffer whose size differs from the colour's (naming both files); and naming the flag for a
// --pass whose buffer is not read from a layered EXR, a buffer given twice in --pass, or a --layer
// when no input is a layered EXR (flags that cannot apply are refused, never ignored).
BufferSet loadBuffers(const BufferFiles& files);

// Reads one buffer from a file given for it alone: a layered EXR gives the pass of that buffer
// (passForFile; `viewLayer` must be one of its view layers), any other image is read whole
// (readImage; the channel-count rule of pass_map.h applies). Conventions applied (conformBuffer).
// `layered`, when given, says whether a layered EXR's pass was read.
Image readBufferFile(const std::string& path, Buffer b, const std::vector<PassRequest>& passes,
                     const std::string& viewLayer, std::string* from = nullptr, bool* layered = nullptr);

}  // namespace atrous::io

// Reading and writing image files from C++ programs that use the installed library
// (docs/cpp.md). The same readers and writers as the CLI and the Python package use.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "atrous/image.h"

namespace atrous {

// Reads an EXR, PFM, PNG, JPEG, HDR, BMP or TGA file as a planar host Image in linear RGB (3
// channels unless asked for fewer). EXR needs R,G,B channels (A is not read here: readAlpha,
// atrous/io/alpha.h), or Y, or exactly one channel (grey, repeated into R,G,B); PFM may be colour or
// grey; 8- and 16-bit formats (PNG, JPEG, BMP, TGA) are converted from sRGB to linear with the sRGB
// curve (srgb.h: the inverse of the PNG writer's), so their values are in [0, 1]. Throws InputError naming the file and the problem for a missing, unreadable,
// truncated or oddly-shaped file (every EXR reader's size rule: src/io/exr_limits.h).
// `sourceChannels`, when given, receives how many distinct channels the file held: 1 for grey (one
// EXR channel, Y, a grey PFM or PNG), else 3. `channels` (1..3) keeps the first channels only (a
// depth file's R, an ids file's R and G): an EXR decodes no others.
Image readImage(const std::string& path, int* sourceChannels = nullptr, int channels = 3);

// Writes `img` (1, 3 or 4 channels; a 4th is alpha) by the file's extension: .exr (32-bit float
// R,G,B and A, ZIP compressed), .pfm (no alpha: a 4-channel image is an InputError), or .png (8-bit
// sRGB preview of clamp(v, 0, 1); alpha as 8-bit linear coverage). An image on the GPU is
// copied to the host first. The write is atomic: the file is written under a temporary name in
// the same directory and renamed, so a failure never leaves half a file under `path`.
// Throws InputError naming the file for an unknown extension, an unwritable directory or an
// unsupported channel count.
void writeImage(const std::string& path, const Image& img);

// One render's buffers as a renderer wrote them (docs/inputs.md), the way `atrous denoise --in
// PATH` reads them: `path` is a layered EXR (Blender's multilayer file, Mitsuba's AOV output) or a
// render folder (atrous's file names, LuxCore's); `passes` are "BUFFER=NAME" requests
// ("albedo=ViewLayer.Denoising Albedo") and `viewLayer` the view layer of a file with several, as
// the CLI's --pass and --layer. Every buffer found, by name (color, variance, albedo, normal,
// position, depth, ids, emission, motion), as host images in atrous's conventions: depth 1
// channel (view depth), ids 2 (R object, G material id; -1 background), motion 2 (previous -
// current, in pixels, y down), the others 3; `from` says which file (and pass) each came from and
// `notes` which conventions were applied. Throws InputError naming the file and the problem.
struct RenderFiles {
    std::vector<std::pair<std::string, Image>> buffers;
    std::vector<std::pair<std::string, std::string>> from;
    std::vector<std::string> notes;
    const Image* get(const std::string& name) const;  // null when absent
};
RenderFiles readRenderFiles(const std::string& path, const std::vector<std::string>& passes = {},
                            const std::string& viewLayer = {});

}  // namespace atrous

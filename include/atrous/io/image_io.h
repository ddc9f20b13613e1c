// Image files: OpenEXR (float RGB), PFM (the format Intel Open Image Denoise's tools use), and
// PNG/JPEG/HDR through stb. Every writer goes through writeFileAtomically, so a failure never
// leaves half a file under the final name.
#pragma once
#include <functional>
#include <string>

#include "atrous/image.h"

namespace atrous::io {

// Reads an image file as a planar host Image (linear RGB; 3 channels unless asked for fewer). EXR needs R,G,B channels
// (A is not read here: readAlpha, alpha.h), or Y, or exactly one channel (grey, repeated into R,G,B); PFM may be colour or
// grey; 8- and 16-bit formats (PNG, JPEG, BMP, TGA) are converted from sRGB to linear with the sRGB
// curve (srgb.h: the inverse of writePng), so their values are in [0, 1]. Throws InputError naming the file and the
// problem for a missing, unreadable, truncated or oddly-shaped file (exr_limits.h: the size rule
// every EXR reader shares). `sourceChannels`, when given, receives how many distinct channels the
// file held: 1 for grey (one EXR channel, Y, a grey PFM or PNG), else 3. `channels` (1..3) keeps
// the first channels only (a depth file's R, an ids file's R and G): an EXR decodes no others.
Image readImage(const std::string& path, int* sourceChannels = nullptr, int channels = 3);

// Writes `img` (1, 3 or 4 channels on the host; a 4th is alpha) by the file's extension: .exr
// (32-bit float R,G,B and A, ZIP compressed), .pfm (no alpha: a 4-channel image is an InputError), or
// .png (tonemapped preview: exposure, clamp, sRGB; alpha as 8-bit linear coverage). Atomic.
void writeImage(const std::string& path, const Image& img);
void writeExr(const std::string& path, const Image& img);
void writePfm(const std::string& path, const Image& img);
// 8-bit sRGB preview of linear HDR: out = srgb(clamp(exposure * v, 0, 1)).
void writePng(const std::string& path, const Image& img, float exposure = 1.0f);

// Calls writer(tmpPath) with a temporary name beside `path`, then renames it to `path`. If the
// writer throws, the temporary file is removed and the exception passes on. Throws InputError when
// the directory cannot be written.
void writeFileAtomically(const std::string& path, const std::function<void(const std::string&)>& writer);

// Throws InputError unless `dir` exists (or can be created) and a file can be created in it.
void ensureWritableDirectory(const std::string& dir);

// Whether `path` names an 8- or 16-bit display-referred format (PNG, JPEG, BMP, TGA: LDR, values
// in [0, 1] once read), by its extension; not EXR, PFM or Radiance .hdr.
bool isLdrFormat(const std::string& path);

// The alpha channel of a PNG, BMP or TGA with one (grey + alpha, RGBA), as a 1-channel host
// image of code / 255 (or / 65535); empty when the file has none (and for JPEG and .hdr, which
// have none). Throws InputError as readImage does. (alpha.h's readAlpha reads any format's.)
Image readStbAlpha(const std::string& path);

// Throws InputError "<what>: color buffer has no finite pixel ..." when no pixel of the host image
// `color` has three finite channels (an all-NaN render would otherwise come out black).
void requireFinitePixel(const Image& color, const std::string& what);

// Lower-case extension with the dot (".exr"), or "" when there is none.
std::string extensionOf(const std::string& path);

}  // namespace atrous::io

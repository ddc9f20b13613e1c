// Image files: OpenEXR (float RGB), PFM (the format Intel Open Image Denoise's tools use), and
// PNG/JPEG/HDR through stb. Every writer goes through writeFileAtomically, so a failure never
// leaves half a file under the final name.
#pragma once
#include <functional>
#include <string>

#include "atrous/image.h"
#include "atrous/io.h"

namespace atrous::io {

// Reading and writing an image file by its extension are atrous::readImage and atrous::writeImage
// (atrous/io.h), the one reader and writer of the library, the CLI, Python and installed users
// alike. The writers of one format (host images, 1 or 3 channels, EXR 4 too; atomic):
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
// have none: those files are not read). Throws InputError as readImage does. (alpha.h's readAlpha
// reads any format's.)
Image readStbAlpha(const std::string& path);

// Throws InputError "<what>: color buffer has no finite pixel ..." when no pixel of the host image
// `color` has three finite channels (an all-NaN render would otherwise come out black).
void requireFinitePixel(const Image& color, const std::string& what);

// Lower-case extension with the dot (".exr"), or "" when there is none.
std::string extensionOf(const std::string& path);

}  // namespace atrous::io

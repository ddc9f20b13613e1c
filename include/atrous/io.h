// Reading and writing image files from C++ programs that use the installed library
// (docs/cpp.md). The same readers and writers as the CLI and the Python package use.
#pragma once
#include <string>

#include "atrous/image.h"

namespace atrous {

// Reads an EXR, PFM, PNG, JPEG or HDR file as a 3-channel planar host Image in linear RGB.
// EXR needs R,G,B channels (A is ignored), or Y, or exactly one channel (grey, repeated into
// R,G,B); PFM may be colour or grey; 8-bit formats are converted from sRGB to linear.
// Throws InputError naming the file and the problem for a missing, unreadable, truncated or
// oddly-shaped file.
Image readImage(const std::string& path);

// Writes `img` (1 or 3 channels) by the file's extension: .exr (32-bit float R,G,B, ZIP
// compressed), .pfm, or .png (8-bit sRGB preview of clamp(v, 0, 1)). An image on the GPU is
// copied to the host first. The write is atomic: the file is written under a temporary name in
// the same directory and renamed, so a failure never leaves half a file under `path`.
// Throws InputError naming the file for an unknown extension, an unwritable directory or an
// unsupported channel count.
void writeImage(const std::string& path, const Image& img);

}  // namespace atrous

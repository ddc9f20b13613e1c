// What src/io checks in an 8-bit or Radiance file before stb_image decodes it (image_io.cpp's
// readStb; docs/inputs.md "What a file can claim"). stb_image 2.27 trusts its input: it reallocates
// to a PNG chunk's claimed length, reads a truncated BMP, TGA or .hdr as black without a word,
// loops for ever on some .hdr runs and sniffs the format whatever the file's name says. Each check
// throws InputError naming the file; none decodes pixels.
#pragma once
#include <string>
#include <vector>

namespace atrous::io {

// The file's first bytes are the format its extension names (.png, .jpg/.jpeg, .bmp, .hdr; a .tga,
// which has no magic, must not carry another format's).
void requireFormatOfExtension(const std::string& path, const std::vector<unsigned char>& bytes);

// A PNG's chunks: every length within the file, every CRC right, IEND at the end. Drops empty IDAT
// chunks (stb memcpy's from a null pointer on them) and data after IEND. Other formats pass as they are.
void checkPngChunks(const std::string& path, std::vector<unsigned char>& bytes);

// The w x h pixels the header claims (stb's info call; TurboJPEG's for a JPEG) fit the file: at most 16384 per side and a
// bound on pixels per byte for every format, then per format the pixel data itself: a .hdr's every
// scanline (flat or run-length), a BMP's rows, a TGA's pixels (raw, or its run-length packets
// walked to the last pixel).
void requireImagePixelsFit(const std::string& path, const std::vector<unsigned char>& bytes, int w, int h);

}  // namespace atrous::io

#include "io/stb_checks.h"

#include <libdeflate.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <initializer_list>

#include "atrous/error.h"
#include "atrous/image.h"
#include "atrous/io/image_io.h"

namespace atrous::io {

// stb sniffs a file's format from its bytes, whatever its name (a ".png" that starts "P6" goes to
// its PNM reader, whose header numbers overflow an int in 2.27: found by tests/fuzz/libfuzzer). A
// file is read only as the format its extension names: its magic must be that format's (TGA has
// none: it must not carry another format's).
void requireFormatOfExtension(const std::string& path, const std::vector<unsigned char>& b) {
    auto starts = [&](std::initializer_list<unsigned char> m) {
        return b.size() >= m.size() && std::equal(m.begin(), m.end(), b.begin());
    };
    // stb takes a file for a JPEG when it starts with 0xFF, any more 0xFF fill bytes, then 0xD8 (a
    // ".tga" starting FF FF D8 went to stb's JPEG header parser: found by tests/fuzz/libfuzzer).
    size_t fill = 0;
    while (fill < b.size() && b[fill] == 0xFF) ++fill;
    const bool jpeg = fill > 0 && fill < b.size() && b[fill] == 0xD8;
    const bool png = starts({0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'});
    const bool bmp = starts({'B', 'M'}), hdr = starts({'#', '?'});
    const bool other = starts({'G', 'I', 'F', '8'}) || starts({'8', 'B', 'P', 'S'}) || starts({0x53, 0x80, 0xF6, 0x34}) ||
                       (b.size() >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6');
    const std::string ext = extensionOf(path);
    const char* want = nullptr;
    if (ext == ".png" && !png) want = "PNG";
    if ((ext == ".jpg" || ext == ".jpeg") && !jpeg) want = "JPEG";
    if (ext == ".bmp" && !bmp) want = "BMP";
    if (ext == ".hdr" && !hdr) want = "Radiance HDR";
    if (ext == ".tga" && (png || jpeg || bmp || hdr || other)) want = "TGA";
    if (want) throw InputError(path + ": not a " + std::string(want) + " file (its first bytes are another format's, or none)");
}

// At most this many pixels per byte of a PNG/JPEG/HDR/BMP/TGA file (a 1-bit PNG at deflate's
// 1032:1 holds ~8256): a lying header is refused before stb allocates for it.
constexpr double kMaxPixelsPerByte = 8448.0;

static uint32_t bigEndian32(const unsigned char* p) { return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]; }

// A PNG's chunks, checked before stb sees them (stb skips CRCs, reallocates to an IDAT chunk's
// claimed length before reading it: 2 GB from a 326-byte file, and memcpy's from a null pointer on
// an empty IDAT; found by tests/fuzz/libfuzzer): every chunk's length fits in the file, its CRC is
// right, and the file ends with IEND (a file cut short inside or after its last data chunk was
// decoded without a word: tests/fuzz, seed 90210). Empty IDAT chunks (legal, and nothing to
// decode) are dropped. Data after IEND (some tools append it) is ignored. Non-PNG bytes pass as
// they are.
void checkPngChunks(const std::string& path, std::vector<unsigned char>& bytes) {
    static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (bytes.size() < 8 || std::memcmp(bytes.data(), kPng, 8) != 0) return;
    std::vector<unsigned char> out(bytes.begin(), bytes.begin() + 8);
    size_t at = 8;
    for (;;) {
        if (bytes.size() - at < 12) throw InputError(path + ": truncated PNG (no complete IEND chunk at its end)");
        const uint32_t len = bigEndian32(&bytes[at]);
        if (len > bytes.size() - at - 12)
            throw InputError(path + ": truncated or corrupt PNG (a chunk of " + std::to_string(len) + " bytes at offset " +
                             std::to_string(at) + " of a " + std::to_string(bytes.size()) + "-byte file)");
        const unsigned char* type = &bytes[at + 4];
        if (libdeflate_crc32(0, type, size_t(len) + 4) != bigEndian32(type + 4 + len))
            throw InputError(path + ": corrupt PNG (chunk '" + std::string(reinterpret_cast<const char*>(type), 4) +
                             "' at offset " + std::to_string(at) + " fails its CRC)");
        const bool iend = std::memcmp(type, "IEND", 4) == 0;
        if (!(len == 0 && std::memcmp(type, "IDAT", 4) == 0)) out.insert(out.end(), &bytes[at], &bytes[at] + len + 12);
        at += size_t(len) + 12;
        if (iend) break;
    }
    bytes.swap(out);
}

// Whether a .hdr header line ends the header as stb reads it: stb copies each line into a C
// string, so a line that is empty or starts with a NUL byte ends it (a "\0..." line did not end
// our walk: the scanlines were read 20 bytes after stb's and a 130-byte file stb looped on passed,
// found by tests/fuzz/libfuzzer; a "\r" line is not empty to stb, 07ee564).
static bool hdrHeaderEnds(const std::string& line) { return line.empty() || line[0] == '\0'; }

// A Radiance .hdr must hold every scanline: stb fills a truncated file's missing pixels with
// black without a word. Walks the scanlines (flat or new-style RLE) without decoding them.
static void requireHdrComplete(const std::string& path, uint64_t fileSize, int w, int h) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    // The header, up to the first empty line, exactly as stb reads it ('\n' ends a line; a "\r"
    // line is not empty to stb: taking it for the end put this walk 200 bytes before stb's, and a
    // file stb then looped on for minutes passed, found by tests/fuzz/libfuzzer).
    while (std::getline(in, line) && !hdrHeaderEnds(line)) {}
    if (!std::getline(in, line)) throw InputError(path + ": truncated HDR (no resolution line)");
    const std::streamoff headerBytes = in.tellg();
    auto truncated = [&](int y) {
        return InputError(path + ": truncated HDR (scanline " + std::to_string(y) + " of " + std::to_string(h) + " is incomplete)");
    };
    std::vector<unsigned char> buf;
    for (int y = 0; y < h; ++y) {
        unsigned char head[4];
        if (!in.read(reinterpret_cast<char*>(head), 4)) throw truncated(y);
        const bool rle = w >= 8 && w < 32768 && head[0] == 2 && head[1] == 2 && !(head[2] & 0x80);
        if (!rle && y == 0) {  // flat pixels: 4 bytes each after the header
            const uint64_t need = uint64_t(w) * uint64_t(h) * 4, have = fileSize - uint64_t(headerBytes);
            if (have < need)
                throw InputError(path + ": truncated HDR (expected " + std::to_string(need) + " bytes of pixels, found " +
                                 std::to_string(have) + ")");
            return;
        }
        // stb loops for ever on a zero-length run at the end of the data (EOF reads as 0): every
        // structural fault is refused here.
        auto corrupt = [&](const char* what) {
            return InputError(path + ": corrupt HDR (scanline " + std::to_string(y) + ": " + what + ")");
        };
        if (!rle) throw corrupt("not run-length encoded like the first");
        if (((head[2] << 8) | head[3]) != w) throw corrupt("its length is not the image width");
        for (int c = 0; c < 4; ++c)
            for (int x = 0; x < w;) {
                const int count = in.get();
                if (count == EOF) throw truncated(y);
                if (count > 128) {
                    if (in.get() == EOF) throw truncated(y);
                    if (count - 128 > w - x) throw corrupt("a run past the end of the line");
                    x += count - 128;
                } else {
                    if (count == 0) throw corrupt("a zero-length run");
                    if (count > w - x) throw corrupt("a run past the end of the line");
                    buf.resize(size_t(count));
                    if (!in.read(reinterpret_cast<char*>(buf.data()), count)) throw truncated(y);
                    x += count;
                }
            }
    }
}

static uint32_t le16(const std::vector<unsigned char>& b, size_t at) { return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8; }
static uint32_t le32(const std::vector<unsigned char>& b, size_t at) { return le16(b, at) | le16(b, at + 2) << 16; }

static InputError truncatedImage(const std::string& path, const char* format, uint64_t need, size_t have) {
    return InputError(path + ": truncated " + format + " (its pixels need " + std::to_string(need) + " bytes, the file has " +
                      std::to_string(have) + ")");
}

// A BMP's rows (stb 2.27 reads past the end as 0), from the pixel offset of its file header, rows
// padded to 4 bytes; stb refuses the run-length kinds itself, and an offset other than the header's
// end for a BMP without a palette. A palette is read as stb reads it: (offset - 14 - header) / 4
// entries, or (offset - 38) / 3 for an OS/2 header (stb's count, 4 short of the file's). With no
// entry stb reads none and starts the pixels past the offset; a pixel naming an entry stb did not
// read takes uninitialised memory: both are refused (found by a review of the checks).
static void requireBmpComplete(const std::string& path, const std::vector<unsigned char>& b, int w, int h) {
    const uint32_t hsz = b.size() >= 18 ? le32(b, 14) : 0;
    const size_t headerEnd = hsz == 12 ? 26 : 30;  // through the bits per pixel
    if (b.size() < headerEnd) throw InputError(path + ": truncated BMP (a header of " + std::to_string(b.size()) + " bytes)");
    const int64_t offset = le32(b, 10);
    const uint32_t bpp = hsz == 12 ? le16(b, 24) : le16(b, 28);
    const uint64_t stride = (uint64_t(w) * bpp + 31) / 32 * 4, last = (uint64_t(w) * bpp + 7) / 8;
    int64_t palette = 0;
    if (bpp < (hsz == 12 ? 24u : 16u)) {
        // C's integer division and shift, as stb computes it (offset is at most 2^32 - 1).
        palette = hsz == 12 ? (offset - 38) / 3 : (offset - 14 - int64_t(hsz)) >> 2;
        if (palette < 1)
            throw InputError(path + ": corrupt BMP (its pixels at offset " + std::to_string(offset) +
                             " leave no room for the palette stb_image reads)");
    }
    const uint64_t start = std::max<uint64_t>(uint64_t(offset), 14ull + hsz);
    const uint64_t need = start + stride * uint64_t(h - 1) + last;
    if (b.size() < need) throw truncatedImage(path, "BMP", need, b.size());
    if ((bpp != 1 && bpp != 4 && bpp != 8) || palette >= (int64_t(1) << bpp)) return;  // stb refuses other depths
    for (int y = 0; y < h; ++y)  // every index within the entries stb read
        for (int x = 0; x < w; ++x) {
            const uint64_t bit = uint64_t(x) * bpp;
            const unsigned byte = b[size_t(start + uint64_t(y) * stride + bit / 8)];
            const unsigned index = (byte >> (8 - bpp - unsigned(bit % 8))) & ((1u << bpp) - 1);
            if (int64_t(index) >= palette)
                throw InputError(path + ": corrupt BMP (a pixel of row " + std::to_string(y) + " names colour " + std::to_string(index) +
                                 " of a " + std::to_string(palette) + "-colour palette as stb_image reads it)");
        }
}

// A TGA's pixels (stb 2.27 reads past the end as 0): after the 18-byte header, the image id and,
// for a colour-mapped image, the palette as stb skips and reads it; raw pixels take (bits + 7) / 8
// bytes each, a run-length image is walked packet by packet to its last pixel.
static void requireTgaComplete(const std::string& path, const std::vector<unsigned char>& b, int w, int h) {
    if (b.size() < 18) throw InputError(path + ": truncated TGA (a header of " + std::to_string(b.size()) + " bytes)");
    const bool mapped = b[1] != 0, rle = b[2] > 8;
    const uint64_t pixelBytes = (uint64_t(b[16]) + 7) / 8, paletteBytes = (uint64_t(b[7]) + 7) / 8;
    uint64_t at = 18ull + b[0] + (mapped ? le16(b, 3) + le16(b, 5) * paletteBytes : 0);
    const uint64_t pixels = uint64_t(w) * uint64_t(h);
    if (!rle) {
        const uint64_t need = at + pixels * pixelBytes;
        if (b.size() < need) throw truncatedImage(path, "TGA", need, b.size());
        return;
    }
    for (uint64_t done = 0; done < pixels;) {
        if (at >= b.size())
            throw InputError(path + ": truncated TGA (its run-length data ends after " + std::to_string(done) + " of " +
                             std::to_string(pixels) + " pixels)");
        const unsigned packet = b[at++];
        const uint64_t count = std::min<uint64_t>((packet & 127u) + 1, pixels - done);
        at += (packet & 128u ? 1 : count) * pixelBytes;
        if (at > b.size())
            throw InputError(path + ": truncated TGA (a run-length packet at pixel " + std::to_string(done) + " of " +
                             std::to_string(pixels) + " ends past the file)");
        done += count;
    }
}

void requireImagePixelsFit(const std::string& path, const std::vector<unsigned char>& bytes, int w, int h) {
    if (w <= 0 || h <= 0 || w > kMaxImageDim || h > kMaxImageDim)
        throw InputError(path + ": unsupported image size " + std::to_string(w) + "x" + std::to_string(h) + " (at most " +
                         std::to_string(kMaxImageDim) + " per side)");
    if (double(w) * double(h) > double(bytes.size()) * kMaxPixelsPerByte + 65536.0)
        throw InputError(path + ": truncated or corrupt image (" + std::to_string(w) + "x" + std::to_string(h) +
                         " pixels cannot fit in " + std::to_string(bytes.size()) + " bytes)");
    const std::string ext = extensionOf(path);
    if (ext == ".bmp") return requireBmpComplete(path, bytes, w, h);
    if (ext == ".tga") return requireTgaComplete(path, bytes, w, h);
    if (ext != ".hdr") return;
    requireHdrComplete(path, bytes.size(), w, h);
}

}  // namespace atrous::io

#include "io/exr_limits.h"

#include <ImfChannelList.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "atrous/error.h"
#include "atrous/image.h"

namespace atrous::io {

namespace {

// The most bytes of decoded pixels one byte of an EXR file can hold, by compression (a lying
// header then costs memory in proportion to the file, not to its data window): deflate peaks near
// 1032:1 (ZIP, ZIPS, PXR24), PIZ's Huffman run codes and DWA's zipped DC near a few thousand,
// B44 stays below 16:1, RLE below 64:1.
double maxExpansion(Imf::Compression c) {
    switch (c) {
        case Imf::NO_COMPRESSION: return 1.0;
        case Imf::RLE_COMPRESSION: return 64.0;
        case Imf::B44_COMPRESSION:
        case Imf::B44A_COMPRESSION: return 16.0;
        case Imf::ZIPS_COMPRESSION:
        case Imf::ZIP_COMPRESSION:
        case Imf::PXR24_COMPRESSION: return 1100.0;
        default: return 8192.0;  // PIZ, DWAA, DWAB
    }
}

std::string sizeText(long w, long h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace

uint64_t exrFileBytes(const std::string& path) {
    std::error_code ec;
    const uintmax_t n = std::filesystem::file_size(path, ec);
    return ec ? 0 : uint64_t(n);
}

void requireExrHeadersFit(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char head[8];
    if (!in.read(reinterpret_cast<char*>(head), 8) || head[0] != 0x76 || head[1] != 0x2f || head[2] != 0x31 || head[3] != 0x01)
        return;
    const uint64_t bytes = exrFileBytes(path);
    const bool longNames = head[5] & 0x04, multipart = head[5] & 0x10;
    (void)longNames;  // names up to 255 bytes either way (OpenEXR checks the flag itself)
    const size_t maxName = 255;
    auto readName = [&](std::string& name) {
        name.clear();
        for (int ch; (ch = in.get()) != 0;) {
            if (ch == EOF) throw InputError(path + ": truncated EXR header");
            if (name.size() >= maxName) throw InputError(path + ": corrupt EXR header (a name longer than " +
                                                         std::to_string(maxName) + " bytes)");
            name += char(ch);
        }
    };
    // Headers (one, or a part's each up to an empty one), each a list of attributes up to an empty name.
    for (int part = 0;; ++part) {
        std::string name, type;
        readName(name);
        if (name.empty()) {
            if (part == 0 && !multipart) break;  // a single-part header ended (no attributes at all)
            break;                               // the empty header that ends a multipart file's headers
        }
        for (;;) {
            readName(type);
            unsigned char sz[4];
            if (!in.read(reinterpret_cast<char*>(sz), 4)) throw InputError(path + ": truncated EXR header");
            const int32_t size = int32_t(uint32_t(sz[0]) | uint32_t(sz[1]) << 8 | uint32_t(sz[2]) << 16 | uint32_t(sz[3]) << 24);
            const std::streamoff at = in.tellg();
            auto tooLarge = [&](const std::string& what, uint64_t claimed) {
                return InputError(path + ": truncated or corrupt EXR header (attribute '" + name + "' of type '" + type + "' claims " +
                                  std::to_string(claimed) + " bytes" + what + " at offset " + std::to_string(at) + " of a " +
                                  std::to_string(bytes) + "-byte file)");
            };
            if (size < 0 || at < 0 || uint64_t(at) + uint64_t(size) > bytes) throw tooLarge("", uint64_t(std::max(size, 0)));
            if (type == "chlist") {
                // OpenEXR reads a channel list by its entries (a name, then 16 bytes) up to an empty
                // name, whatever its size says, and goes on from there: so does this walk.
                // OpenEXR's Core reads it by its size: the two must agree.
                std::string channel;
                for (readName(channel); !channel.empty(); readName(channel)) {
                    in.seekg(16, std::ios::cur);
                    const std::streamoff now = in.tellg();
                    if (now < 0 || uint64_t(now) > bytes) throw tooLarge(" of channels", uint64_t(std::max<std::streamoff>(now - at, 0)));
                }
                if (in.tellg() != at + std::streamoff(size))
                    throw InputError(path + ": corrupt EXR header (the channel list's entries take " +
                                     std::to_string(in.tellg() - at) + " bytes, its attribute says " + std::to_string(size) + ")");
            } else if (type == "preview") {
                // A preview's width and height, then width * height * 4 bytes that OpenEXR allocates.
                unsigned char wh[8];
                if (size < 8 || !in.read(reinterpret_cast<char*>(wh), 8)) throw tooLarge(" (a preview without its size)", uint64_t(size));
                const uint64_t pw = uint32_t(wh[0]) | uint32_t(wh[1]) << 8 | uint32_t(wh[2]) << 16 | uint32_t(wh[3]) << 24;
                const uint64_t ph = uint32_t(wh[4]) | uint32_t(wh[5]) << 8 | uint32_t(wh[6]) << 16 | uint32_t(wh[7]) << 24;
                if (pw * ph * 4 + 8 > uint64_t(size)) throw tooLarge(" of preview pixels", pw * ph * 4);
                in.seekg(size - 8, std::ios::cur);
            } else {
                in.seekg(size, std::ios::cur);
            }
            readName(name);
            if (name.empty()) break;  // this header's end
        }
        if (!multipart) break;
    }
}

ExrWindow exrImageWindow(const std::string& path, const Imf::Header& first) {
    const Imath::Box2i dw = first.dataWindow(), disp = first.displayWindow();
    // Clipped to the display window (overscan is dropped), unless the display window is empty
    // or does not meet the data window at all: then the data window is the image.
    const long x0 = std::max(long(dw.min.x), long(disp.min.x)), y0 = std::max(long(dw.min.y), long(disp.min.y));
    const long x1 = std::min(long(dw.max.x), long(disp.max.x)), y1 = std::min(long(dw.max.y), long(disp.max.y));
    const bool meets = x1 >= x0 && y1 >= y0;
    ExrWindow win;
    const long ax = meets ? x0 : dw.min.x, ay = meets ? y0 : dw.min.y;
    const long w = (meets ? x1 : long(dw.max.x)) - ax + 1, h = (meets ? y1 : long(dw.max.y)) - ay + 1;
    if (w <= 0 || h <= 0 || w > kMaxImageDim || h > kMaxImageDim)
        throw InputError(path + ": unsupported image size " + sizeText(w, h) + " (at most " + std::to_string(kMaxImageDim) +
                         " per side)");
    win.x0 = int(ax);
    win.y0 = int(ay);
    win.width = int(w);
    win.height = int(h);
    return win;
}

void requireExrFits(const std::string& path, const std::vector<const Imf::Header*>& parts,
                    const std::vector<std::string>& labels) {
    const double bytes = double(exrFileBytes(path));
    double need = 0.0;  // file bytes the parts need at their compressions' largest ratios
    for (size_t p = 0; p < parts.size(); ++p) {
        const Imf::Header& header = *parts[p];
        const std::string where = labels[p].empty() ? std::string() : " " + labels[p];
        const Imath::Box2i dw = header.dataWindow();
        const long w = long(dw.max.x) - dw.min.x + 1, h = long(dw.max.y) - dw.min.y + 1;
        if (w <= 0 || h <= 0 || w > kMaxImageDim || h > kMaxImageDim)
            throw InputError(path + ":" + where + (where.empty() ? "" : ":") + " unsupported image size " + sizeText(w, h) +
                             " (at most " + std::to_string(kMaxImageDim) + " per side)");
        double bytesPerPixel = 0.0;
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
            const Imf::Channel& ch = it.channel();
            const double sampling = double(std::max(1, ch.xSampling)) * std::max(1, ch.ySampling);
            bytesPerPixel += (ch.type == Imf::HALF ? 2.0 : 4.0) / sampling;
        }
        const double decoded = double(w) * double(h) * bytesPerPixel;
        need += decoded / maxExpansion(header.compression());
        if (need > bytes + 65536.0)
            throw InputError(path + ": truncated or corrupt EXR (" + (where.empty() ? "the header's " : labels[p] + ": its ") +
                             sizeText(w, h) + " data window needs more pixel data than the file's " +
                             std::to_string(uint64_t(bytes)) + " bytes can hold)");
    }
}

bool exrNeedsProof(uint64_t planeBytes, uint64_t fileBytes) {
    return double(planeBytes) > 8.0 * double(fileBytes) + 64.0 * 1024.0 * 1024.0;
}

}  // namespace atrous::io

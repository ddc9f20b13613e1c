#include "io/exr_limits.h"

#include <ImfChannelList.h>

#include <algorithm>
#include <filesystem>

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

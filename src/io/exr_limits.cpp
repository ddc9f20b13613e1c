#include "io/exr_limits.h"

#include <ImfChannelList.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <vector>

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

namespace {

uint32_t le32(const unsigned char* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

// The size OpenEXR's classic API reads for a fixed-size attribute type (it reads that many bytes
// whatever the attribute declares; its Core reads the declared size), or -1 for types of variable size.
int fixedSize(const std::string& type) {
    static const std::pair<const char*, int> kSizes[] = {
        {"box2i", 16}, {"box2f", 16}, {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1},
        {"float", 4}, {"double", 8}, {"int", 4}, {"rational", 8}, {"timecode", 8}, {"keycode", 28}, {"tiledesc", 9},
        {"v2i", 8}, {"v2f", 8}, {"v2d", 16}, {"v3i", 12}, {"v3f", 12}, {"v3d", 24}, {"m33f", 36}, {"m33d", 72},
        {"m44f", 64}, {"m44d", 128}, {"chromaticities", 32}};
    for (const auto& [name, size] : kSizes)
        if (type == name) return size;
    return -1;
}

// What rules 1 and 2 need of a part's header.
struct PartHeader {
    bool hasWindow = false, deep = false;
    std::string name;
    uint32_t tileW = 0, tileH = 0;  // a tiled part's tile size (OpenEXR allocates tile buffers of it)
    int32_t window[4] = {0, 0, 0, 0};  // xmin, ymin, xmax, ymax
    int compression = 0;
    double bytesPerPixel = 0;  // of its channels, at their sampling
};

double maxExpansionOf(int compression) {
    switch (compression) {
        case 0: return 1.0;              // none
        case 1: return 64.0;             // RLE
        case 2: case 3: case 5: return 1100.0;  // ZIPS, ZIP, PXR24
        case 6: case 7: return 16.0;     // B44, B44A
        default: return 8192.0;          // PIZ, DWAA, DWAB
    }
}

}  // namespace

namespace {

// Reads an EXR's headers attribute by attribute (name, type, size, value), each value its declared
// size bounded by the file, and checks them as OpenEXR's classic API and its Core would read them:
// both must see the same attributes.
class ExrHeaderScan {
public:
    ExrHeaderScan(const std::string& path, std::ifstream& in, uint64_t bytes) : mPath(path), mIn(in), mBytes(bytes) {}

    InputError corrupt(const std::string& what) const {
        return InputError(mPath + ": truncated or corrupt EXR header (" + what + ")");
    }

    void readName(std::string& name) {
        name.clear();
        for (int ch; (ch = mIn.get()) != 0;) {
            if (ch == EOF) throw corrupt("it ends inside a name");
            if (name.size() >= 255) throw corrupt("a name longer than 255 bytes");
            name += char(ch);
        }
    }

    // One header, a list of attributes up to an empty name; `name` (read already) is its first.
    PartHeader readHeader(std::string name) {
        PartHeader part;
        std::vector<std::string> seen;  // an attribute twice: OpenEXR's classic API keeps the last, its Core the first
        for (; !name.empty(); readName(name)) {
            if (std::find(seen.begin(), seen.end(), name) != seen.end()) throw corrupt("attribute '" + name + "' appears twice");
            seen.push_back(name);
            readAttribute(name, part);
        }
        return part;
    }

private:
    // The type, size and value of attribute `name`.
    void readAttribute(const std::string& name, PartHeader& part) {
        std::string type;
        readName(type);
        unsigned char sz[4];
        if (!mIn.read(reinterpret_cast<char*>(sz), 4)) throw corrupt("it ends inside attribute '" + name + "'");
        const int64_t size = int32_t(le32(sz));
        const std::streamoff at = mIn.tellg();
        const std::string which = "attribute '" + name + "' of type '" + type + "'";
        if (size < 0 || at < 0 || uint64_t(at) + uint64_t(size) > mBytes)
            throw corrupt(which + " claims " + std::to_string(size) + " bytes at offset " + std::to_string(at) + " of a " +
                          std::to_string(mBytes) + "-byte file");
        mValue.resize(size_t(size));
        if (size > 0 && !mIn.read(reinterpret_cast<char*>(mValue.data()), std::streamsize(size)))
            throw corrupt("it ends inside attribute '" + name + "'");
        const int fixed = fixedSize(type);
        if (fixed >= 0 && size != fixed)
            throw corrupt(which + " has " + std::to_string(size) + " bytes; a " + type + " has " + std::to_string(fixed));
        checkValue(name, type, which, part);
    }

    // The value of a type whose parts OpenEXR sizes itself, or of an attribute rules 1 and 2 need.
    void checkValue(const std::string& name, const std::string& type, const std::string& which, PartHeader& part) {
        const std::vector<unsigned char>& value = mValue;
        if (type == "chlist") {
            readChannelList(which, part);
        } else if (type == "preview") {
            if (value.size() < 8 || uint64_t(le32(&value[0])) * le32(&value[4]) * 4 + 8 != uint64_t(value.size()))
                throw corrupt(which + "'s pixels do not fill its " + std::to_string(value.size()) + " bytes");
        } else if (type == "stringvector") {
            requireStrings(which);
        } else if (type == "box2i" && name == "dataWindow") {
            part.hasWindow = true;
            for (int i = 0; i < 4; ++i) part.window[i] = int32_t(le32(&value[size_t(4 * i)]));
        } else if (type == "compression" && name == "compression") {
            part.compression = value[0];
        } else if (type == "string" && name == "type") {
            part.deep = std::string(value.begin(), value.end()).rfind("deep", 0) == 0;
        } else if (type == "string" && name == "name") {
            part.name.assign(value.begin(), value.end());
        } else if (type == "tiledesc") {
            part.tileW = le32(&value[0]);
            part.tileH = le32(&value[4]);
        }
    }

    // Entries (a name, then type, pLinear, 3 reserved bytes, x and y sampling) up to an empty name,
    // which must end the attribute; their bytes per pixel add up in part.bytesPerPixel.
    void readChannelList(const std::string& which, PartHeader& part) const {
        const std::vector<unsigned char>& value = mValue;
        size_t p = 0;
        for (;;) {
            const size_t end = std::find(value.begin() + long(p), value.end(), 0) - value.begin();
            if (end >= value.size()) throw corrupt("the channel list of " + which + " is not terminated");
            if (end == p) {
                if (end + 1 != value.size()) throw corrupt("the channel list of " + which + " does not fill its size");
                break;
            }
            if (end - p > 255 || end + 17 > value.size()) throw corrupt("a channel of " + which + " is cut short");
            const uint32_t pixelType = le32(&value[end + 1]);
            const int32_t xs = int32_t(le32(&value[end + 9])), ys = int32_t(le32(&value[end + 13]));
            if (pixelType > 2 || xs < 1 || ys < 1) throw corrupt("a channel of " + which + " has a bad type or sampling");
            part.bytesPerPixel += (pixelType == 1 ? 2.0 : 4.0) / (double(xs) * double(ys));
            p = end + 17;
        }
    }

    // A stringvector's strings (a 4-byte length, then the bytes) fill the value exactly.
    void requireStrings(const std::string& which) const {
        const std::vector<unsigned char>& value = mValue;
        for (size_t p = 0; p < value.size();) {
            if (p + 4 > value.size()) throw corrupt("a string of " + which + " is cut short");
            const uint64_t len = le32(&value[p]);
            if (len > value.size() - p - 4) throw corrupt("a string of " + which + " claims " + std::to_string(len) + " bytes");
            p += 4 + size_t(len);
        }
    }

    const std::string& mPath;
    std::ifstream& mIn;
    uint64_t mBytes;
    std::vector<unsigned char> mValue;  // the attribute being read
};

// Rules 1 and 2 on the headers read, before OpenEXR sees the file (its classic API allocates line
// buffers for a data window's width when a file is opened).
void requirePartsFit(const std::string& path, const std::vector<PartHeader>& parts, uint64_t bytes) {
    double need = 0.0;
    for (size_t i = 0; i < parts.size(); ++i) {
        const PartHeader& h = parts[i];
        // OpenEXR fills in a missing data window (and then allocates for what the header's other
        // attributes say): a header without one is refused here.
        if (!h.hasWindow)
            throw InputError(path + ": " + (parts.size() > 1 ? "part " + std::to_string(i) + ": " : std::string()) +
                             "corrupt EXR header (no dataWindow attribute)");
        const int64_t w = int64_t(h.window[2]) - h.window[0] + 1, hh = int64_t(h.window[3]) - h.window[1] + 1;
        const std::string which =
            parts.size() > 1 ? "part " + std::to_string(i) + (h.name.empty() ? "" : " '" + h.name + "'") + ": " : "";
        if (w <= 0 || hh <= 0 || w > kMaxImageDim || hh > kMaxImageDim)
            throw InputError(path + ": " + which + "unsupported image size " + sizeText(long(w), long(hh)) + " (at most " +
                             std::to_string(kMaxImageDim) + " per side)");
        // A tile side is at most the data window's, or 1024 (a small image's usual 64 x 64 tiles):
        // OpenEXR's classic API allocates buffers of a tile's size when it opens a tiled file
        // (4 x 28835840 tiles: 7.4 GB, found by tests/fuzz/libfuzzer).
        if (h.tileW > uint64_t(std::max<int64_t>(w, 1024)) || h.tileH > uint64_t(std::max<int64_t>(hh, 1024)))
            throw InputError(path + ": " + which + "corrupt EXR (tiles of " + std::to_string(h.tileW) + "x" + std::to_string(h.tileH) +
                             " for a " + sizeText(long(w), long(hh)) + " data window)");
        if (h.deep) continue;
        need += double(w) * double(hh) * h.bytesPerPixel / maxExpansionOf(h.compression);
        if (need > double(bytes) + 65536.0)
            throw InputError(path + ": truncated or corrupt EXR (" + (which.empty() ? "the header's " : which + "its ") +
                             sizeText(long(w), long(hh)) + " data window needs more pixel data than the file's " +
                             std::to_string(bytes) + " bytes can hold)");
    }
}

}  // namespace

void requireExrHeadersFit(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char head[8];
    if (!in.read(reinterpret_cast<char*>(head), 8) || le32(head) != 20000630u) return;  // not an EXR: the caller says so
    const uint64_t bytes = exrFileBytes(path);
    const bool multipart = head[5] & 0x10;
    ExrHeaderScan scan(path, in, bytes);
    // Headers: one, or a part's each up to an empty one.
    std::vector<PartHeader> parts;
    for (;;) {
        std::string name;
        scan.readName(name);
        if (name.empty()) break;  // no (more) headers
        parts.push_back(scan.readHeader(name));
        if (!multipart) break;
    }
    requirePartsFit(path, parts, bytes);
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

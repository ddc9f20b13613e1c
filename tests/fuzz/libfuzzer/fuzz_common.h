// Shared by the libFuzzer targets (tests/fuzz/libfuzzer/*.cpp, docs/reliability.md): the contract
// every target checks, a per-process scratch directory for readers that need a path, and the
// checks of what a reader promises about what it returns.
//
// The contract: a reader returns or throws atrous::InputError. Any other exception, a crash, a
// sanitizer report, a leak, or a returned value that breaks the reader's promise (a NaN where the
// conventions say none, an image larger than its file can hold, a scene value outside its rule) is
// a finding: the target prints one line "==atrous-fuzz== FINDING in <target>: ..." and aborts, and
// libFuzzer keeps the input as crash-<sha1>.
//
// Known problems (Debian 12's stb_image 2.27; two in src/io's EXR header checks, reported to the
// lead): a target names them once as "==atrous-fuzz== KNOWN <id>" and skips the input, so that a
// long run can go on; with ATROUS_FUZZ_STRICT=1 they are not skipped (and then end the run as
// findings).
#pragma once
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <set>
#include <string>
#include <typeinfo>
#include <vector>

#include "atrous/error.h"
#include "atrous/image.h"
#include "io/exr_layers.h"
#include "io/pass_map.h"
#include "render/scene_data.h"
#include "render/scene_limits.h"

namespace atrous_fuzz {

using atrous::Image;

// The target's name, for messages (set once in LLVMFuzzerInitialize or at first use).
inline const char*& targetName() {
    static const char* name = "atrous";
    return name;
}

// `s` with control and non-ASCII bytes as '?' (file names and attribute names from the input
// stay on one printable line of the log).
inline std::string printable(std::string s) {
    for (char& c : s)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
    return s;
}

[[noreturn]] inline void finding(const std::string& what) {
    std::fprintf(stderr, "\n==atrous-fuzz== FINDING in %s: %s\n", targetName(), printable(what).c_str());
    std::fflush(stderr);
    std::abort();
}

inline bool strict() {
    static const bool s = [] {
        const char* e = std::getenv("ATROUS_FUZZ_STRICT");
        return e && *e && std::string(e) != "0";
    }();
    return s;
}

// True (skip the input) for a known problem, unless ATROUS_FUZZ_STRICT is set. Named once per id.
inline bool knownIssue(const char* id, const std::string& detail) {
    if (strict()) return false;
    static std::set<std::string>* seen = new std::set<std::string>();
    if (seen->insert(id).second) {
        std::fprintf(stderr, "==atrous-fuzz== KNOWN %s (skipped; ATROUS_FUZZ_STRICT=1 makes it a finding): %s\n", id,
                     printable(detail).c_str());
        std::fflush(stderr);
    }
    return true;
}

// ------------------------------------------------------------------------------- scratch files

// A directory of this process's own: $ATROUS_FUZZ_TMP (scripts/libfuzz.sh gives each target one
// under /dev/shm), else /dev/shm or $TMPDIR; removed at a normal exit.
inline const std::string& scratchDir() {
    static const std::string* dir = [] {
        std::string base;
        if (const char* t = std::getenv("ATROUS_FUZZ_TMP"); t && *t)
            base = t;
        else if (access("/dev/shm", W_OK) == 0)
            base = "/dev/shm";
        else if (const char* t2 = std::getenv("TMPDIR"); t2 && *t2)
            base = t2;
        else
            base = "/tmp";
        auto* d = new std::string(base + "/atrous-fuzz-" + std::to_string(getpid()));
        std::error_code ec;
        std::filesystem::create_directories(*d, ec);
        if (ec) {
            std::fprintf(stderr, "cannot create %s: %s\n", d->c_str(), ec.message().c_str());
            std::exit(2);
        }
        std::atexit([] {
            std::error_code e2;
            std::filesystem::remove_all(scratchDir(), e2);
        });
        return d;
    }();
    return *dir;
}

// Writes `size` bytes to scratchDir()/name (replacing it) and returns the path.
inline std::string writeScratch(const std::string& name, const void* data, size_t size) {
    const std::string path = scratchDir() + "/" + name;
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f || (size && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
        std::fprintf(stderr, "cannot write %s\n", path.c_str());
        std::exit(2);
    }
    return path;
}
inline std::string writeScratch(const std::string& name, const std::string& text) {
    return writeScratch(name, text.data(), text.size());
}

// The input cut at each `sep` into at most `maxParts` parts (the last keeps the rest): how the
// targets with several files (a scene JSON and an image; an OBJ, its MTL and a texture) take them
// from one input.
inline std::vector<std::string> splitSections(const uint8_t* data, size_t size, const std::string& sep, size_t maxParts) {
    std::vector<std::string> parts;
    const std::string all(reinterpret_cast<const char*>(data), size);
    size_t at = 0;
    while (parts.size() + 1 < maxParts) {
        const size_t next = all.find(sep, at);
        if (next == std::string::npos) break;
        parts.push_back(all.substr(at, next - at));
        at = next + sep.size();
    }
    parts.push_back(all.substr(at));
    while (parts.size() < maxParts) parts.emplace_back();
    return parts;
}

// ------------------------------------------------------------------------------ known problems

// Known (src/io at f6cab04, found by the 10-minute exr runs with ATROUS_FUZZ_STRICT=1): OpenEXR 3.1's
// Header::readFrom allocates an attribute's claimed size (a string's, opaque data, a preview's
// pixels) before reading it. src/io/exr_limits.cpp's requireExrHeadersFit walks the header
// first, but steps over every attribute by its declared size, while OpenEXR reads the fixed-size
// types by their size whatever they declare: a 'compression' declaring 321 bytes (OpenEXR reads
// 1) hides the string of 1918989835 bytes that OpenEXR then meets (reproducer
// tests/fuzz/libfuzzer/findings/exr-header-declared-size-desync-1.9gb.exr). True, with what, when
// an attribute claims more bytes than follow it, the header walked the way OpenEXR reads it: a
// channel list up to its terminating null name and the fixed-size types by their size; the others
// by their declared size. `parts` receives each header's channel pixel types (0 uint, 1 half, 2
// float), `windows` each header's data window (x0, y0, x1, y1), `tiles` each tile size (x, y), as
// far as the walk got.
inline bool exrAttributeOverrun(const uint8_t* d, size_t n, std::string* what,
                                std::vector<std::vector<int>>* parts = nullptr,
                                std::vector<std::array<int64_t, 4>>* windows = nullptr,
                                std::vector<std::array<int64_t, 2>>* tiles = nullptr) {
    if (parts) parts->assign(1, {});
    if (windows) windows->clear();
    if (tiles) tiles->clear();
    if (n < 8 || d[0] != 0x76 || d[1] != 0x2f || d[2] != 0x31 || d[3] != 0x01) return false;
    const bool multipart = (d[5] & 0x10) != 0;  // version flag 0x1000
    auto cstr = [&](size_t& i, std::string& out) {
        const size_t start = i;
        while (i < n && d[i] != 0 && i - start < 256) ++i;
        if (i >= n || d[i] != 0) return false;
        out.assign(reinterpret_cast<const char*>(d + start), i - start);
        ++i;
        return true;
    };
    auto i32 = [&](size_t i) {
        return int64_t(int32_t(uint32_t(d[i]) | uint32_t(d[i + 1]) << 8 | uint32_t(d[i + 2]) << 16 | uint32_t(d[i + 3]) << 24));
    };
    auto fixedSize = [](const std::string& t) -> size_t {
        static const std::pair<const char*, size_t> kFixed[] = {
            {"box2i", 16}, {"box2f", 16}, {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1},
            {"int", 4}, {"float", 4}, {"double", 8}, {"v2i", 8}, {"v2f", 8}, {"v2d", 16}, {"v3i", 12}, {"v3f", 12},
            {"v3d", 24}, {"m33f", 36}, {"m33d", 72}, {"m44f", 64}, {"m44d", 128}, {"tiledesc", 9}, {"keycode", 28},
            {"timecode", 8}, {"rational", 8}, {"chromaticities", 32}};
        for (const auto& [name, bytes] : kFixed)
            if (t == name) return bytes;
        return 0;
    };
    auto overrun = [&](const std::string& name, const std::string& type, int64_t claim, size_t left) {
        if (what) *what = "attribute '" + name + "' (" + type + ") claims " + std::to_string(claim) + " bytes, " + std::to_string(left) + " follow";
        return true;
    };
    size_t at = 8;
    while (at < n) {
        if (d[at] == 0) {  // end of a header; in a multipart file an empty header ends the list
            ++at;
            if (!multipart || at >= n || d[at] == 0) return false;
            if (parts) parts->emplace_back();
            continue;
        }
        std::string name, type;
        if (!cstr(at, name) || !cstr(at, type) || at + 4 > n) return false;
        const int64_t size = i32(at);
        at += 4;
        if (size < 0) return false;  // OpenEXR refuses it
        const size_t left = n - at;
        if (type == "chlist") {
            for (std::string channel;;) {
                if (!cstr(at, channel)) return false;
                if (channel.empty()) break;
                if (at + 16 > n) return false;
                if (parts) parts->back().push_back(int(i32(at)));
                at += 16;
            }
        } else if (const size_t fixed = fixedSize(type)) {
            if (fixed > left) return false;
            if (windows && name == "dataWindow" && type == "box2i")
                windows->push_back({i32(at), i32(at + 4), i32(at + 8), i32(at + 12)});
            if (tiles && type == "tiledesc") tiles->push_back({int64_t(uint32_t(i32(at))), int64_t(uint32_t(i32(at + 4)))});
            at += fixed;
        } else if (type == "preview") {
            if (left < 8 || i32(at) < 0 || i32(at + 4) < 0) return false;
            const uint64_t pixels = uint64_t(i32(at)) * uint64_t(i32(at + 4));  // 4 bytes each
            if (pixels > (left - 8) / 4) return overrun(name, type, int64_t(pixels * 4), left - 8);
            at += 8 + size_t(pixels * 4);
        } else if (type == "stringvector") {
            for (int64_t read = 0; read < size;) {
                if (at + 4 > n || i32(at) < 0) return false;
                const int64_t len = i32(at);
                at += 4;
                if (uint64_t(len) > n - at) return overrun(name, type + " string", len, n - at);
                at += size_t(len);
                read += 4 + len;
            }
        } else {
            if (uint64_t(size) > left) return overrun(name, type, size, left);
            at += size_t(size);
        }
    }
    return false;
}

// Known (Debian 12's stb_image 2.27; the JPEG decoder's bugs below are fixed in 2.28): its JPEG
// decoder, which stb sniffs in any file (readImage on .png, .jpg, ...), met by the png target:
// a DHT table of more than 256 codes writes past the Huffman table's size[257] and values[256]
// arrays (UBSan "index 257 out of bounds", stbi__build_huffman; findings/png-stb-jpeg-dht-overflow.jpg),
// a shift by 32 in stbi__grow_buffer_unsafe (findings/png-stb-jpeg-shift-exponent.jpg), and once
// an STBI_ASSERT in stbi__jpeg_huff_decode, an abort in Debian's libstb.so too, not reproduced from
// the file alone (findings/png-stb-jpeg-huff-assert-unreproduced.jpg). True for what stb takes for
// a JPEG: 0xFF bytes, then the SOI marker 0xD8.
inline bool stbJpeg(const uint8_t* d, size_t n) {
    size_t i = 0;
    while (i < n && d[i] == 0xFF) ++i;
    return i > 0 && i < n && d[i] == 0xD8;
}

// Known (stb_image 2.27): the PNG reader grows its IDAT buffer to a chunk's claimed length before
// reading it, so a 200-byte PNG whose IDAT claims 2^31 bytes makes it realloc 2 GB (found by png,
// reproducer tests/fuzz/libfuzzer/findings/png-stb-idat-length-2gb.png). True when an IDAT chunk
// claims more bytes than follow its header.
inline bool pngIdatOverrun(const uint8_t* d, size_t n) {
    static const uint8_t kSig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (n < 8 || std::memcmp(d, kSig, 8) != 0) return false;
    for (size_t at = 8; at + 8 <= n;) {
        const uint64_t len = uint64_t(d[at]) << 24 | uint64_t(d[at + 1]) << 16 | uint64_t(d[at + 2]) << 8 | d[at + 3];
        if (std::memcmp(d + at + 4, "IDAT", 4) == 0 && len > n - (at + 8)) return true;
        at += 12 + size_t(len);
    }
    return false;
}

// The known-problem skips of every target that hands bytes to an image reader (the OpenEXR Core
// reader's 4-channel SEGV and readBufferFile on an EXR without channels, known before, are fixed
// in src/io: 7244261, 37f271e).
// Known (src/io at f6cab04, found by the 10-minute exr_single run with ATROUS_FUZZ_STRICT=1):
// readImage opens an Imf::InputFile before it checks the data window, and OpenEXR's constructor
// allocates its line buffers for the window's width: a 565-byte file with a data window from
// x = -234881024 to 1792 costs 1.9 GB (reproducer findings/exr-huge-data-window-1.9gb.exr).
// True when a header's data window is wider or taller than atrous accepts (kMaxImageDim).
// Known (stb_image 2.27, fixed in 2.28): the PNM reader (P5/P6, which stb sniffs in any file)
// reads the header's numbers into an int without an overflow check (UBSan: "666666666 * 10
// cannot be represented in type 'int'", stbi__pnm_getinteger; found by the 10-minute png run;
// reproducer findings/png-stb-pnm-integer-overflow.pnm). True for a P5/P6 file with a run of 10
// or more digits in its first 1 KB.
inline bool pnmLongNumber(const uint8_t* d, size_t n) {
    if (n < 2 || d[0] != 'P' || (d[1] != '5' && d[1] != '6')) return false;
    for (size_t i = 2, run = 0; i < std::min<size_t>(n, 1024); ++i)
        if ((run = d[i] >= '0' && d[i] <= '9' ? run + 1 : 0) >= 10) return true;
    return false;
}

inline bool exrWindowBeyondLimit(const std::vector<std::array<int64_t, 4>>& windows) {
    for (const auto& w : windows)
        if (w[2] - w[0] + 1 > atrous::kMaxImageDim || w[3] - w[1] + 1 > atrous::kMaxImageDim) return true;
    return false;
}

// Known (src/io at b493c61, found by the 10-minute exr_single run): the same for a tiled file's
// tile size: TiledInputFile's constructor allocates tile buffers for it (tiles of 4 x 28835840
// pixels: a 7.4 GB malloc; findings/exr-huge-tile-size-7.4gb.exr). True for a tile side beyond
// kMaxImageDim.
inline bool exrTileBeyondLimit(const std::vector<std::array<int64_t, 2>>& tiles) {
    for (const auto& t : tiles)
        if (t[0] > atrous::kMaxImageDim || t[1] > atrous::kMaxImageDim) return true;
    return false;
}

inline bool skipKnownImage(const uint8_t* d, size_t n) {
    std::string what;
    std::vector<std::array<int64_t, 4>> windows;
    std::vector<std::array<int64_t, 2>> tiles;
    if (exrAttributeOverrun(d, n, &what, nullptr, &windows, &tiles) &&
        knownIssue("exr-header-size-desync", "an EXR attribute claims more than the file holds, walked as OpenEXR reads it: " + what))
        return true;
    if (exrWindowBeyondLimit(windows) &&
        knownIssue("exr-window-line-buffers", "an EXR data window beyond 16384 per side: OpenEXR allocates its line buffers first"))
        return true;
    if (exrTileBeyondLimit(tiles) &&
        knownIssue("exr-tile-buffers", "an EXR tile side beyond 16384: OpenEXR allocates its tile buffers first"))
        return true;
    if (pnmLongNumber(d, n) && knownIssue("stb-pnm-integer-overflow", "stb_image 2.27 overflows an int reading a PNM header's number"))
        return true;
    if (pngIdatOverrun(d, n) &&
        knownIssue("stb-png-idat-length", "stb_image 2.27 allocates an IDAT chunk's claimed length before reading it"))
        return true;
    return stbJpeg(d, n) && knownIssue("stb-jpeg-decoder", "stb_image 2.27's JPEG decoder (out-of-bounds writes, a shift by 32, an assert)");
}

// --------------------------------------------------------------------------------- the contract

// Runs f(). True when it returned, false when it threw InputError (with a message); anything else
// is a finding.
template <class F>
bool returnsOrInputError(const std::string& what, F&& f) {
    try {
        f();
        return true;
    } catch (const atrous::InputError& e) {
        if (std::string(e.what()).empty()) finding(what + ": InputError with an empty message");
        return false;
    } catch (const std::exception& e) {
        finding(what + ": threw " + typeid(e).name() + " instead of atrous::InputError: " + e.what());
    } catch (...) {
        finding(what + ": threw something that is not a std::exception");
    }
}

// A returned image: a host image of `minPlanes` to 3 channels and of a size the readers accept.
inline void checkShape(const std::string& what, const Image& img, int minPlanes = 3) {
    if (img.empty()) finding(what + ": returned an empty image");
    if (img.channels() < minPlanes || img.channels() > 3 || img.width() <= 0 || img.height() <= 0 || img.width() > atrous::kMaxImageDim ||
        img.height() > atrous::kMaxImageDim)
        finding(what + ": returned a " + std::to_string(img.width()) + "x" + std::to_string(img.height()) + "x" +
                std::to_string(img.channels()) + " image");
}

inline std::string at(const Image& img, size_t i) {
    const size_t plane = img.plane(), c = i / plane, p = i % plane;
    return " at (" + std::to_string(p % size_t(img.width())) + ", " + std::to_string(p / size_t(img.width())) +
           ") channel " + std::to_string(c);
}

// What conformBuffer (io/pass_map.h) promises for buffer b: normals finite and at most unit
// length, depth in (0, 1e9) or the background 1e30, albedo in [0, 1], positions, ids and motion
// finite. Colour, variance and emission are left as they are (the filters repair them).
inline void checkConformed(atrous::io::Buffer b, const Image& img, const std::string& what) {
    using atrous::io::Buffer;
    const float* p = img.data();
    const size_t n = img.plane(), all = img.size();
    switch (b) {
        case Buffer::Normal:
            for (size_t i = 0; i < n; ++i) {
                const float x = p[i], y = p[i + n], z = p[i + 2 * n];
                if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || double(x) * x + double(y) * y + double(z) * z > 1.001)
                    finding(what + ": normal (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) +
                            ") is not finite or longer than 1" + at(img, i));
            }
            break;
        case Buffer::Depth:
            for (size_t i = 0; i < all; ++i)
                if (!((p[i] > 0.0f && p[i] < 1e9f) || p[i] == 1e30f))
                    finding(what + ": depth " + std::to_string(p[i]) + " is neither in (0, 1e9) nor 1e30" + at(img, i));
            break;
        case Buffer::Albedo:
            for (size_t i = 0; i < all; ++i)
                if (!(p[i] >= 0.0f && p[i] <= 1.0f)) finding(what + ": albedo " + std::to_string(p[i]) + " outside [0, 1]" + at(img, i));
            break;
        case Buffer::Position:
        case Buffer::ObjectId:
        case Buffer::MaterialId:
        case Buffer::Motion:
            for (size_t i = 0; i < all; ++i)
                if (!std::isfinite(p[i])) finding(what + ": a non-finite value" + at(img, i));
            break;
        default: break;
    }
}

// ------------------------------------------------------------------------------ layered EXR

// What inspectExr promises about the ExrInfo it returns (io/exr_layers.h): parts of accepted sizes,
// an image window of an accepted size inside the first part's data window, every channel in one
// part and in exactly one layer, each layer's components the last name components of its channels.
inline void checkExrInfo(const atrous::io::ExrInfo& info, const std::string& what) {
    auto bad = [&](const std::string& m) { finding(what + ": " + m); };
    if (info.parts.empty()) bad("no parts");
    for (const auto& p : info.parts)
        if (p.width <= 0 || p.height <= 0 || p.width > atrous::kMaxImageDim || p.height > atrous::kMaxImageDim)
            bad("a part of size " + std::to_string(p.width) + "x" + std::to_string(p.height));
    if (info.width <= 0 || info.height <= 0 || info.width > info.parts[0].width || info.height > info.parts[0].height)
        bad("an image of " + std::to_string(info.width) + "x" + std::to_string(info.height) + " for a first part of " +
            std::to_string(info.parts[0].width) + "x" + std::to_string(info.parts[0].height));
    std::vector<int> seen(info.channels.size(), 0);
    for (const auto& ch : info.channels)
        if (ch.part < 0 || size_t(ch.part) >= info.parts.size()) bad("a channel in a missing part");
    for (const auto& l : info.layers) {
        if (l.channels.size() != l.components.size() || l.channels.empty()) bad("a layer with mismatched components");
        for (size_t i = 0; i < l.channels.size(); ++i) {
            const int c = l.channels[i];
            if (c < 0 || size_t(c) >= info.channels.size()) bad("a layer with a missing channel");
            ++seen[size_t(c)];
            const std::string& full = info.channels[size_t(c)].fullName;
            const size_t dot = full.rfind('.');
            if ((dot == std::string::npos ? full : full.substr(dot + 1)) != l.components[i] ||
                (dot == std::string::npos ? std::string() : full.substr(0, dot)) != l.name)
                bad("channel '" + full + "' in layer '" + l.name + "' as component '" + l.components[i] + "'");
        }
    }
    for (int n : seen)
        if (n != 1) bad("a channel in " + std::to_string(n) + " layers");
}

inline bool isAlphaName(const std::string& c) { return c == "A" || c == "a" || c == "alpha" || c == "Alpha"; }

// What mapPasses / passForFile promise about a choice (io/pass_map.h): 1 or the buffer's count of
// distinct, existing channels, inside the chosen layer; never an alpha channel unless named by
// --pass as a full channel name (the only way to get a choice without a layer).
inline void checkPassChoice(const atrous::io::ExrInfo& info, atrous::io::Buffer b, const atrous::io::PassChoice& c,
                            const std::string& what) {
    using namespace atrous::io;
    auto bad = [&](const std::string& m) { finding(what + " (" + bufferName(b) + "): " + m); };
    if (c.layer < -1 || c.layer >= int(info.layers.size())) bad("layer index " + std::to_string(c.layer));
    if (!c.found()) return;
    if (c.rule.empty()) bad("a choice without a rule");
    const size_t n = c.channels.size();
    if (n != 1 && int(n) != bufferChannels(b)) bad(std::to_string(n) + " channels");
    for (size_t i = 0; i < n; ++i) {
        const int ch = c.channels[i];
        if (ch < 0 || size_t(ch) >= info.channels.size()) bad("channel index " + std::to_string(ch));
        for (size_t j = 0; j < i; ++j)
            if (c.channels[j] == ch) bad("a channel taken twice");
        if (c.layer < 0) continue;
        const ExrLayer& l = info.layers[size_t(c.layer)];
        size_t k = 0;
        while (k < l.channels.size() && l.channels[k] != ch) ++k;
        if (k == l.channels.size()) bad("a channel outside its layer '" + l.name + "'");
        if (isAlphaName(l.components[k])) bad("the alpha channel of '" + l.name + "'");
    }
    if (c.layer < 0 && n != 1) bad("several channels without a layer");
}

// ------------------------------------------------------------------------------- scene values

inline bool inRule(const atrous::pt::ValueRule& r, float v) { return atrous::pt::allowed(r, v); }
inline bool inRule(const atrous::pt::ValueRule& r, atrous::Vec3 v) {
    return inRule(r, v.x) && inRule(r, v.y) && inRule(r, v.z);
}
inline bool finite3(atrous::Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Every value of a parsed scene within its rule (src/render/scene_limits.h, docs/reliability.md),
// every index in range, every derived table (light CDF, environment distribution) finite.
inline void checkScene(const atrous::pt::SceneData& d, const std::string& what) {
    using namespace atrous::pt;
    auto bad = [&](const std::string& m) { finding(what + ": parsed scene has " + m); };
    const size_t nTri = d.triMaterial.size();
    if (d.indices.size() != 3 * nTri || d.triMesh.size() != nTri || d.triLight.size() != nTri) bad("inconsistent triangle arrays");
    if (d.normals.size() != d.positions.size() || d.uvs.size() != d.positions.size()) bad("inconsistent vertex arrays");
    for (size_t i = 0; i < d.positions.size(); ++i) {
        if (!inRule(kCoordinateRule, d.positions[i])) bad("vertex " + std::to_string(i) + " outside +-1e9 or not finite");
        if (!finite3(d.normals[i])) bad("a non-finite vertex normal");
        if (!inRule(kTexcoordRule, d.uvs[i].x) || !inRule(kTexcoordRule, d.uvs[i].y)) bad("a texcoord outside +-1e6");
    }
    for (uint32_t ix : d.indices)
        if (ix >= d.positions.size()) bad("a triangle index past the last vertex");
    const size_t nMat = d.materials.size(), nMesh = d.meshNames.size(), nLight = d.lights.size();
    for (size_t t = 0; t < nTri; ++t) {
        if (d.triMaterial[t] < 0 || size_t(d.triMaterial[t]) >= nMat) bad("a triangle with a bad material id");
        if (d.triMesh[t] < 0 || size_t(d.triMesh[t]) >= nMesh) bad("a triangle with a bad mesh id");
        if (d.triLight[t] < -1 || d.triLight[t] >= int(nLight)) bad("a triangle with a bad light id");
    }
    for (const Sphere& s : d.spheres) {
        if (!inRule(kCoordinateRule, s.center) || !(s.radius > 0.0f) || !inRule(kCoordinateRule, s.radius)) bad("a sphere out of range");
        if (s.material < 0 || size_t(s.material) >= nMat || s.mesh < 0 || size_t(s.mesh) >= nMesh) bad("a sphere with a bad id");
    }
    for (const Material& m : d.materials) {
        if (!inRule(kReflectanceRule, m.albedo) || !inRule(kReflectanceRule, m.albedo2)) bad("an albedo outside [0, 1]");
        if (!inRule(kRadianceRule, m.emission)) bad("an emission outside [0, 1e8]");
        if (!inRule(kRoughnessRule, m.roughness) || !inRule(kIorRule, m.ior)) bad("a roughness or ior out of range");
        if (!(m.checkerScale > 0.0f) || !inRule(kCheckerScaleRule, m.checkerScale)) bad("a checker scale out of range");
        if (m.texture < -1 || m.texture >= int(d.textures.size())) bad("a material with a bad texture id");
    }
    for (const Texture& t : d.textures)
        if (t.width <= 0 || t.height <= 0 || t.offset < 0 ||
            size_t(t.offset) + 3 * size_t(t.width) * size_t(t.height) > d.texels.size())
            bad("a texture outside the texel array");
    for (float v : d.texels)
        if (!(v >= 0.0f) || !std::isfinite(v)) bad("a texel that is negative or not finite");
    for (const Light& l : d.lights) {
        if (l.type == LightType::Point && (!inRule(kCoordinateRule, l.position) || !inRule(kRadianceRule, l.intensity)))
            bad("a point light out of range");
        if (l.type == LightType::Triangle && (l.triangle < 0 || size_t(l.triangle) >= nTri)) bad("a light on a missing triangle");
    }
    if (d.lightCdf.size() != nLight + 1) bad("a light CDF of the wrong size");
    for (size_t i = 0; i < d.lightCdf.size(); ++i)
        if (!(d.lightCdf[i] >= 0.0f && d.lightCdf[i] <= 1.0f) || (i && d.lightCdf[i] < d.lightCdf[i - 1]))
            bad("a light CDF that is not finite and non-decreasing in [0, 1]");
    for (float v : d.envDist)
        if (!std::isfinite(v)) bad("a non-finite environment sampling distribution");
    if (!finite3(d.env.color) || !inRule(kRadianceRule, d.env.color)) bad("an environment colour/scale outside [0, 1e8]");
    if (d.env.type == EnvType::Map) {
        if (d.env.texture < 0 || size_t(d.env.texture) >= d.textures.size()) bad("an environment map with a bad texture id");
        const Texture& t = d.textures[size_t(d.env.texture)];
        for (size_t i = 0; i < 3 * size_t(t.width) * size_t(t.height); ++i)
            if (double(d.texels[size_t(t.offset) + i]) * d.env.color.x > 1.0001e8) bad("an environment texel times its scale above 1e8");
        if (!std::isfinite(d.env.margInt)) bad("a non-finite environment integral");
    }
    const Camera& c = d.camera;
    if (!inRule(kCoordinateRule, c.position) || !finite3(c.forward) || !finite3(c.right) || !finite3(c.up) ||
        !(c.tanHalfFov > 0.0f) || !std::isfinite(c.tanHalfFov))
        bad("a camera out of range");
    if (!(d.sceneRadius > 0.0f) || !std::isfinite(d.sceneRadius)) bad("a scene radius that is not finite");
    for (size_t k = 0; k < d.cameraKeys.size(); ++k) {
        const CameraKey& key = d.cameraKeys[k];
        if (!inRule(kCoordinateRule, key.position) || !inRule(kCoordinateRule, key.target) || !inRule(kCoordinateRule, key.up) ||
            !(key.fovDeg > 0.5f && key.fovDeg < 179.0f) || !inRule(kCoordinateRule, key.t) ||
            (k && !(key.t > d.cameraKeys[k - 1].t)))
            bad("a camera keyframe out of range or out of order");
    }
    if (d.meshMotion.size() > nMesh) bad("motion for a missing mesh");
    for (const MeshMotion& m : d.meshMotion)
        if (!inRule(kCoordinateRule, m.translate) || !inRule(kAngleRule, m.rotateYDeg) || !finite3(m.pivot))
            bad("a motion out of range");
}

}  // namespace atrous_fuzz

// EXR pixels straight into the planes the filters use, and out of them, through OpenEXR's Core API
// (openexr.h). Reading:
// the chunks of a scanline part are located and checked against the file first (rule 3 of
// exr_limits.h, without decoding anything), then decoded in parallel on TBB's threads, each into
// its rows of the caller's planes. ZIP and ZIPS chunks are inflated by libdeflate (faster than
// zlib: docs/decisions.md, "Speed"); every other compression by OpenEXR's own
// routines. Tiled parts are left to OpenEXR's classic API (the caller's fallback). Writing
// (writeExrCore): the chunks of a ZIP scanline file packed and deflated by libdeflate in parallel,
// then written in order by OpenEXR Core.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/exr_limits.h"

namespace atrous::io {

// One channel of a part into one plane of win.width x win.height floats (row-major).
struct ExrPlaneRequest {
    std::string channel;  // the channel's name inside its part
    float* plane = nullptr;
};

class ExrCoreFile {
public:
    // Opens `path` for reading (its headers). Throws InputError naming the file when OpenEXR's
    // Core cannot read it.
    explicit ExrCoreFile(const std::string& path);
    ~ExrCoreFile();
    ExrCoreFile(const ExrCoreFile&) = delete;
    ExrCoreFile& operator=(const ExrCoreFile&) = delete;

    // True for a (flat) scanline part of a compression whose Core decoder agrees with the classic
    // one bit for bit (none, RLE, ZIPS, ZIP, PIZ, PXR24: tests/exr_core_test.cpp), which decode()
    // reads; false for tiled or deep parts and for B44/B44A/DWAA/DWAB, where OpenEXR 3.1's Core
    // decodes float channels differently from (or not at all like) its classic API.
    bool decodes(int part) const;

    // Locates every chunk of a scanline part that holds rows of `win`, and checks each against the
    // file: its offset and size inside the file, its leader, and an unpacked size its packed bytes
    // can hold at the compression's largest ratio. Throws InputError naming the file, the part and
    // the chunk. Nothing of the pixels is decoded or allocated.
    void locate(int part, const ExrWindow& win, const std::string& what);

    // Decodes the requested channels of a located part into the planes (placed by the part's data
    // window, which covers `win`): chunks in parallel, straight into the planes where a chunk's
    // rows and columns are the image's, through a chunk-sized scratch otherwise. Half and uint
    // channels are converted to float. Throws InputError naming the file for data that does not
    // decode.
    void decode(int part, const std::vector<ExrPlaneRequest>& requests, const ExrWindow& win, const std::string& what);

    struct Impl;

private:
    std::unique_ptr<Impl> mImpl;
};

// Writes a single-part scanline EXR of float channels at `path` (not atomic: the caller writes a
// temporary name, io::writeFileAtomically), ZIP-compressed with the given libdeflate level (1..12).
// planes[i] is channel names[i], width x height floats, row-major. Throws RuntimeError naming the
// file when OpenEXR Core cannot write it.
void writeExrCore(const std::string& path, int width, int height, const std::vector<std::string>& names,
                  const std::vector<const float*>& planes, int level = 4);

}  // namespace atrous::io

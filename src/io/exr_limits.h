// The one size rule of every EXR reader (single image, layered file, sequence frame; docs/inputs.md,
// "What a file can claim"): before anything is allocated for a file's pixels,
//
// 1. every part's data window is at most kMaxImageDim per side;
// 2. the pixel data all parts claim fits in what the file's bytes can hold at its compression's
//    largest ratio (1 uncompressed, 64 RLE, 16 B44, 1100 ZIP/ZIPS/PXR24, 8192 PIZ/DWA);
// 3. when what atrous would allocate for the planes it reads is large against the file
//    (kProveAbove), the chunks are first decoded into one row per channel: a header that claims
//    more than its chunks hold fails there, at a row's cost, not after gigabytes of planes.
//
// And one placement rule: the image is the first part's data window clipped to its display window;
// every pass is placed by its own data window, must cover that image (else it is refused), and
// its pixels outside it are dropped.
#pragma once
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace atrous::io {

// The file region atrous reads as the image (see above), in the file's pixel coordinates.
struct ExrWindow {
    int x0 = 0, y0 = 0, width = 0, height = 0;
};

// Rule 0, before OpenEXR reads a header (its 3.1 parser allocates an attribute's claimed size: 2 GB
// from a 901-byte file, found by tests/fuzz/libfuzzer): walks every header's attributes (name,
// type, size, value) and refuses one whose claimed size runs past the end of the file. Throws
// InputError naming the file and the attribute; a file that is not an EXR passes (the caller's
// magic-number check refuses it).
void requireExrHeadersFit(const std::string& path);

// The first part's data window clipped to its display window. Throws InputError naming the file
// when that is empty or larger than kMaxImageDim per side.
ExrWindow exrImageWindow(const std::string& path, const Imf::Header& first);

// Rules 1 and 2 over the given parts' headers. `label(i)` names part i in messages ("" for a
// single-part file). Throws InputError naming the file (and the part).
void requireExrFits(const std::string& path, const std::vector<const Imf::Header*>& parts,
                    const std::vector<std::string>& labels);

// What `bytes` of float planes may be allocated for a file of `fileBytes` bytes without proving its
// chunks first: 8 bytes of planes per file byte plus 64 MiB (a noisy render compresses 1.5-3x, so
// a real file stays far below it; a 1 MB file never costs more than ~72 MB before its chunks are
// known to hold pixels).
bool exrNeedsProof(uint64_t planeBytes, uint64_t fileBytes);

// The file's size in bytes (0 when it cannot be read).
uint64_t exrFileBytes(const std::string& path);

// Rule 3: decodes rows y0..y1 of `channels` of a part (an Imf::InputFile or Imf::InputPart) into one
// row per channel. Throws what OpenEXR throws for data that is not there.
template <class Part>
void proveExrRows(Part& part, const std::vector<std::string>& channels, int y0, int y1) {
    const Imath::Box2i dw = part.header().dataWindow();
    const long w = long(dw.max.x) - dw.min.x + 1;
    std::vector<float> rows(size_t(w) * channels.size());
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < channels.size(); ++c) {
        const Imf::Channel* ch = part.header().channels().findChannel(channels[c].c_str());
        const int xs = ch ? std::max(1, ch->xSampling) : 1, ys = ch ? std::max(1, ch->ySampling) : 1;
        // yStride 0: every scanline lands on the same row.
        char* base = reinterpret_cast<char*>(rows.data() + c * size_t(w)) - long(dw.min.x / xs) * long(sizeof(float));
        fb.insert(channels[c].c_str(), Imf::Slice(Imf::FLOAT, base, sizeof(float), 0, xs, ys, 0.0));
    }
    part.setFrameBuffer(fb);
    part.readPixels(y0, y1);
}

// True when the data window `dw` covers the image window.
inline bool exrCovers(const Imath::Box2i& dw, const ExrWindow& win) {
    return dw.min.x <= win.x0 && dw.min.y <= win.y0 && long(dw.max.x) >= long(win.x0) + win.width - 1 &&
           long(dw.max.y) >= long(win.y0) + win.height - 1;
}

// Decodes channels names[k] of a part (every one unsubsampled) into planes[k] (win.width x
// win.height floats, row-major), placed by the part's data window, which must cover `win`
// (exrCovers). Straight into the planes when the data window's columns are the image's; else
// through a band of 64 rows at a time, its columns outside the image dropped.
template <class Part>
void readExrPlanes(Part& part, const std::vector<std::string>& names, const std::vector<float*>& planes, const ExrWindow& win) {
    const Imath::Box2i dw = part.header().dataWindow();
    const long rowBytes = long(win.width) * long(sizeof(float));
    const int yEnd = win.y0 + win.height - 1;
    Imf::FrameBuffer fb;
    if (dw.min.x == win.x0 && long(dw.max.x) == long(win.x0) + win.width - 1) {
        for (size_t k = 0; k < names.size(); ++k) {
            char* base = reinterpret_cast<char*>(planes[k]) - long(win.x0) * long(sizeof(float)) - long(win.y0) * rowBytes;
            fb.insert(names[k].c_str(), Imf::Slice(Imf::FLOAT, base, sizeof(float), size_t(rowBytes), 1, 1, 0.0));
        }
        part.setFrameBuffer(fb);
        part.readPixels(win.y0, yEnd);
        return;
    }
    const long dwWidth = long(dw.max.x) - dw.min.x + 1;
    const int band = 64;
    std::vector<float> rows(size_t(dwWidth) * band * names.size());
    for (int y = win.y0; y <= yEnd; y += band) {
        const int last = std::min(yEnd, y + band - 1);
        Imf::FrameBuffer bandFb;
        for (size_t k = 0; k < names.size(); ++k) {
            char* base = reinterpret_cast<char*>(rows.data() + k * size_t(dwWidth) * band) -
                         long(dw.min.x) * long(sizeof(float)) - long(y) * dwWidth * long(sizeof(float));
            bandFb.insert(names[k].c_str(),
                          Imf::Slice(Imf::FLOAT, base, sizeof(float), size_t(dwWidth) * sizeof(float), 1, 1, 0.0));
        }
        part.setFrameBuffer(bandFb);
        part.readPixels(y, last);
        for (size_t k = 0; k < names.size(); ++k)
            for (int r = y; r <= last; ++r) {
                const float* src = rows.data() + k * size_t(dwWidth) * band + size_t(r - y) * size_t(dwWidth) + size_t(win.x0 - dw.min.x);
                std::copy(src, src + win.width, planes[k] + size_t(r - win.y0) * size_t(win.width));
            }
    }
}

}  // namespace atrous::io

#include "atrous/io/image_io.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfRgbaFile.h>
#include <ImfArray.h>
#include <stb_image.h>
#include <turbojpeg.h>
#include <tbb/parallel_for.h>
#include <stb_image_write.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "atrous/error.h"
#include "atrous/srgb.h"
#include "atrous/io/exr_layers.h"
#include "io/exr_core.h"
#include "io/exr_limits.h"
#include "atrous/io/pass_map.h"
#include "io/stb_checks.h"

namespace fs = std::filesystem;

namespace atrous::io {

std::string extensionOf(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

// A path with a NUL byte (possible from Python) would name another file at the C layer ("a\0b.exr"
// opens "a"): refused.
static void requireNoNul(const std::string& path) {
    const size_t nul = path.find('\0');
    if (nul != std::string::npos) throw InputError(path.substr(0, nul) + "...: the path contains a NUL byte");
}

static void requireFile(const std::string& path) {
    requireNoNul(path);
    std::error_code ec;
    if (!fs::exists(path, ec)) throw InputError(path + ": file not found");
    if (fs::is_directory(path, ec)) throw InputError(path + ": is a directory, not an image file");
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw InputError(path + ": cannot open for reading (" + std::strerror(errno) + ")");
}

// ---------------------------------------------------------------------------------------- EXR

static uintmax_t fileSize(const std::string& path) {
    std::error_code ec;
    const uintmax_t n = fs::file_size(path, ec);
    return ec ? 0 : n;
}

// The first n channels of img (all of them when it has no more).
static Image firstChannels(Image img, int n) {
    if (n >= img.channels()) return img;
    Image out = Image::uninitialized(img.width(), img.height(), n);
    std::copy(img.data(), img.data() + out.size(), out.data());
    return out;
}

// Out of memory while reading a file names the file (the allocator's message names none).
template <class F>
static auto namingFile(const std::string& path, F&& f) -> decltype(f()) {
    try {
        return f();
    } catch (const RuntimeError& e) {
        if (std::string(e.what()).rfind(path + ":", 0) == 0) throw;
        throw RuntimeError(path + ": " + e.what());
    } catch (const std::bad_alloc&) {
        throw RuntimeError(path + ": out of host memory");
    }
}

// One EXR part's R,G,B (or Y, or its only channel) as a 3-channel image (exr_limits.h: the size rule
// before anything is allocated, placed by the data window clipped to the display window).
static Image readExr(const std::string& path, int* sourceChannels, int outChannels) {
    try {
        requireExrHeadersFit(path);
        Imf::InputFile file(path.c_str());
        const Imf::Header& header = file.header();
        requireExrFits(path, {&header}, {""});
        const ExrWindow win = exrImageWindow(path, header);
        const Imath::Box2i dw = header.dataWindow();
        const long w = win.width, h = win.height;
        const Imf::ChannelList& channels = header.channels();
        std::vector<std::string> names;
        for (auto it = channels.begin(); it != channels.end(); ++it) names.push_back(it.name());
        auto has = [&](const char* n) { return channels.findChannel(n) != nullptr; };
        std::string src[3];
        if (has("R") && has("G") && has("B")) {
            src[0] = "R", src[1] = "G", src[2] = "B";
        } else if (has("Y") && (has("RY") || has("BY"))) {
            // Luminance/chroma (Y, RY, BY): OpenEXR's RGBA interface converts it to RGB.
            const long dwW = long(dw.max.x) - dw.min.x + 1, dwH = long(dw.max.y) - dw.min.y + 1;
            if (exrNeedsProof(uint64_t(dwW) * uint64_t(dwH) * 20, fileSize(path)))
                proveExrRows(file, {"Y", has("RY") ? "RY" : "BY"}, dw.min.y, dw.max.y);
            Imf::RgbaInputFile rgba(path.c_str());
            Imf::Array2D<Imf::Rgba> px(dwH, dwW);
            rgba.setFrameBuffer(&px[0][0] - dw.min.x - dw.min.y * dwW, 1, size_t(dwW));
            rgba.readPixels(dw.min.y, dw.max.y);
            Image img(int(w), int(h), 3);
            for (long y = 0; y < h; ++y)
                for (long x = 0; x < w; ++x) {
                    const Imf::Rgba& p = px[y + win.y0 - dw.min.y][x + win.x0 - dw.min.x];
                    img(int(x), int(y), 0) = float(p.r);
                    img(int(x), int(y), 1) = float(p.g);
                    img(int(x), int(y), 2) = float(p.b);
                }
            if (sourceChannels) *sourceChannels = 3;
            return firstChannels(std::move(img), outChannels);
        } else if (has("Y")) {
            src[0] = src[1] = src[2] = "Y";
        } else if (names.size() == 1) {
            src[0] = src[1] = src[2] = names[0];
        } else if (names.size() > 1) {
            // A layered file (Blender's multilayer, Mitsuba's aov): its colour pass (pass_map.h).
            const ExrInfo info = inspectExr(path);
            const PassMap m = mapPasses(info, {}, "");
            if (m[Buffer::Color].found()) {
                if (sourceChannels) *sourceChannels = int(m[Buffer::Color].channels.size());
                return firstChannels(readPass(info, m[Buffer::Color], Buffer::Color), outChannels);
            }
            std::string list;
            for (auto& n : names) list += (list.empty() ? "" : ",") + n;
            throw InputError(path + ": expected R,G,B (or Y, or a single) channels or a colour pass, found " + list);
        } else {
            throw InputError(path + ": expected R,G,B (or Y, or a single) channels, found none");
        }
        const bool grey = src[1] == src[0];
        // Only the channels asked for are decoded (a depth file's R alone, an ids file's R and G).
        std::vector<std::string> read(src, src + (grey ? 1 : outChannels));
        for (const std::string& n : read) {
            const Imf::Channel& ch = *channels.findChannel(n.c_str());
            if (ch.xSampling != 1 || ch.ySampling != 1)
                throw InputError(path + ": channel '" + n + "' is subsampled (" + std::to_string(ch.xSampling) + "x" +
                                 std::to_string(ch.ySampling) + "), which atrous cannot read");
        }
        Image img;
        std::vector<float*> planes;
        ExrCoreFile core(path);
        if (core.decodes(0)) {
            // OpenEXR Core, chunks located and checked first, then decoded in parallel (exr_core.h).
            core.locate(0, win, "the image");
            img = Image::uninitialized(int(w), int(h), outChannels);
            std::vector<ExrPlaneRequest> req;
            for (size_t c = 0; c < read.size(); ++c) req.push_back({read[c], img.view().channel(int(c))});
            core.decode(0, req, win, "the image");
        } else {
            if (exrNeedsProof(uint64_t(w) * uint64_t(h) * 12, fileSize(path))) proveExrRows(file, read, dw.min.y, dw.max.y);
            img = Image::uninitialized(int(w), int(h), outChannels);
            for (size_t c = 0; c < read.size(); ++c) planes.push_back(img.view().channel(int(c)));
            readExrPlanes(file, read, planes, win);
        }
        for (int c = 1; grey && c < outChannels; ++c) std::copy(img.data(), img.data() + img.plane(), img.data() + c * img.plane());
        if (sourceChannels) *sourceChannels = grey ? 1 : 3;
        return img;
    } catch (const InputError&) {
        throw;
    } catch (const RuntimeError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot read EXR (" + e.what() + ")");
    }
}

void writeExr(const std::string& path, const Image& img) {
    if (img.device() != Device::Cpu) throw InputError(path + ": writeExr needs a host image");
    if (img.channels() != 1 && img.channels() != 3 && img.channels() != 4)
        throw InputError(path + ": can only write 1-, 3- or 4-channel (RGBA) images, got " + std::to_string(img.channels()));
    writeFileAtomically(path, [&](const std::string& tmp) {
        // 32-bit float R,G,B (and A), ZIP: chunks packed and deflated in parallel (exr_core.h).
        std::vector<const float*> planes;
        for (int c = 0; c < 3; ++c) planes.push_back(img.view().channel(img.channels() >= 3 ? c : 0));
        std::vector<std::string> names = {"R", "G", "B"};
        if (img.channels() == 4) names.push_back("A"), planes.push_back(img.view().channel(3));
        writeExrCore(tmp, img.width(), img.height(), names, planes);
    });
}

// ---------------------------------------------------------------------------------------- PFM

static Image readPfm(const std::string& path, int* sourceChannels) {
    std::ifstream in(path, std::ios::binary);
    std::string magic;
    long w = 0, h = 0;
    double scale = 0;
    in >> magic >> w >> h >> scale;
    if (!in || (magic != "PF" && magic != "Pf"))
        throw InputError(path + ": not a PFM file (bad header)");
    if (w <= 0 || h <= 0 || w > kMaxImageDim || h > kMaxImageDim)
        throw InputError(path + ": unsupported PFM size " + std::to_string(w) + "x" + std::to_string(h));
    if (scale == 0 || !std::isfinite(scale)) throw InputError(path + ": PFM scale must be a non-zero number");
    in.get();  // the single whitespace byte after the scale
    const int nc = magic == "PF" ? 3 : 1;
    if (sourceChannels) *sourceChannels = nc;
    // Before allocating: a 20-byte file may declare 16384x16384 (3 GB).
    const uintmax_t need = uintmax_t(w) * uintmax_t(h) * uintmax_t(nc) * sizeof(float);
    const std::streamoff at = in.tellg();
    const uintmax_t have = fileSize(path);
    if (at < 0 || have < uintmax_t(at) || have - uintmax_t(at) < need)
        throw InputError(path + ": truncated PFM (expected " + std::to_string(need) + " bytes of pixels, found " +
                         std::to_string(at < 0 || have < uintmax_t(at) ? 0 : have - uintmax_t(at)) + ")");
    std::vector<float> raw(size_t(w) * size_t(h) * nc);
    in.read(reinterpret_cast<char*>(raw.data()), std::streamsize(raw.size() * sizeof(float)));
    if (size_t(in.gcount()) != raw.size() * sizeof(float))
        throw InputError(path + ": truncated PFM (expected " + std::to_string(raw.size() * sizeof(float)) +
                         " bytes of pixels, found " + std::to_string(in.gcount()) + ")");
    const bool fileLittle = scale < 0;
    const uint16_t probe = 1;
    const bool swap = fileLittle != (*reinterpret_cast<const uint8_t*>(&probe) == 1);
    // Rows in parallel, each written once (no zero fill): de-interleaved, flipped (PFM rows run
    // bottom to top), byte-swapped when the file's order is not the host's.
    Image img = Image::uninitialized(int(w), int(h), 3);
    const ImageView v = img.view();
    tbb::parallel_for(0L, h, [&](long y) {
        const float* src = raw.data() + size_t(h - 1 - y) * size_t(w) * size_t(nc);
        float* dst[3] = {&v(0, int(y), 0), &v(0, int(y), 1), &v(0, int(y), 2)};
        for (long x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                float f = src[size_t(x) * size_t(nc) + size_t(nc == 3 ? c : 0)];
                if (swap) {
                    uint32_t u;
                    std::memcpy(&u, &f, 4);
                    u = __builtin_bswap32(u);
                    std::memcpy(&f, &u, 4);
                }
                dst[c][x] = f;
            }
    });
    return img;
}

void writePfm(const std::string& path, const Image& img) {
    if (img.device() != Device::Cpu) throw InputError(path + ": writePfm needs a host image");
    if (img.channels() == 4) throw InputError(path + ": PFM has no alpha channel (write .exr or .png to keep it)");
    writeFileAtomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) throw RuntimeError(tmp + ": cannot open for writing");
        const int w = img.width(), h = img.height();
        out << "PF\n" << w << " " << h << "\n-1.0\n";
        // Interleaved and flipped in parallel, then written in one call.
        std::vector<float> px(size_t(w) * size_t(h) * 3);
        const ImageView v = img.view();
        const int ch = img.channels();
        tbb::parallel_for(0, h, [&](int y) {
            float* row = px.data() + size_t(h - 1 - y) * size_t(w) * 3;
            for (int c = 0; c < 3; ++c) {
                const float* src = &v(0, y, ch == 3 ? c : 0);
                for (int x = 0; x < w; ++x) row[size_t(x) * 3 + size_t(c)] = src[x];
            }
        });
        out.write(reinterpret_cast<const char*>(px.data()), std::streamsize(px.size() * sizeof(float)));
        if (!out) throw RuntimeError(path + ": write failed");
    });
}

// ---------------------------------------------------------------------------------- PNG & co.

void writePng(const std::string& path, const Image& img, float exposure) {
    if (img.device() != Device::Cpu) throw InputError(path + ": writePng needs a host image");
    const int w = img.width(), h = img.height();
    // A 4th channel is alpha: written as RGBA, linearly (PNG's rule: code = alpha x 255), no exposure.
    const int n = img.channels() == 4 ? 4 : 3;
    std::vector<unsigned char> px(size_t(w) * h * size_t(n));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) {
                float v = img(x, y, img.channels() >= 3 ? c : 0) * exposure;
                if (!std::isfinite(v)) v = 0.0f;
                px[(size_t(y) * w + x) * n + c] = displayByte(srgbEncode(v));
            }
            if (n == 4) {
                const float a = img(x, y, 3);
                px[(size_t(y) * w + x) * n + 3] = displayByte(a);
            }
        }
    writeFileAtomically(path, [&](const std::string& tmp) {
        if (!stbi_write_png(tmp.c_str(), w, h, n, px.data(), w * n)) throw RuntimeError(path + ": cannot write PNG");
    });
}

// The linear value of every 8-bit code: the sRGB curve (srgb.h), the exact inverse of writePng's
// encode, so a PNG atrous writes reads back as the values it was written from (to a code's
// rounding). (Until 2026-12-07 the 8-bit formats were read with stb's x^2.2, which put code 13 at
// 0.0012 instead of 0.0040: docs/decisions.md, "LDR input".)
static const float* srgbCodes() {
    static const std::vector<float> lut = [] {
        std::vector<float> t(256);
        for (int i = 0; i < 256; ++i) t[size_t(i)] = srgbDecode(float(i) / 255.0f);
        return t;
    }();
    return lut.data();
}

// A JPEG through libjpeg-turbo (TurboJPEG), not stb: stb_image 2.27's JPEG decoder overruns its
// Huffman tables, shifts by 32 and asserts on crafted files (found by tests/fuzz/libfuzzer). Warnings
// (a damaged stream) are errors. 8-bit sRGB to linear as for the other 8-bit formats (srgbCodes),
// so a JPEG and a PNG of the same pixels read alike.
static Image readJpeg(const std::string& path, const std::vector<unsigned char>& bytes, int* sourceChannels) {
    struct Handle {
        tjhandle h = tjInitDecompress();
        ~Handle() {
            if (h) tjDestroy(h);
        }
    } tj;
    if (!tj.h) throw RuntimeError(path + ": cannot start the JPEG decoder");
    int w = 0, h = 0, subsamp = 0, colorspace = 0;
    if (tjDecompressHeader3(tj.h, bytes.data(), static_cast<unsigned long>(bytes.size()), &w, &h, &subsamp, &colorspace) != 0)
        throw InputError(path + ": not a readable JPEG (" + tjGetErrorStr2(tj.h) + ")");
    requireImagePixelsFit(path, bytes, w, h);
    std::vector<unsigned char> rgb(size_t(w) * size_t(h) * 3);
    if (tjDecompress2(tj.h, bytes.data(), static_cast<unsigned long>(bytes.size()), rgb.data(), w, 0, h, TJPF_RGB,
                      TJFLAG_STOPONWARNING) != 0)
        throw InputError(path + ": corrupt JPEG (" + tjGetErrorStr2(tj.h) + ")");
    if (sourceChannels) *sourceChannels = subsamp == TJSAMP_GRAY ? 1 : 3;
    const float* lut = srgbCodes();
    Image img = Image::uninitialized(w, h, 3);
    const ImageView v = img.view();
    tbb::parallel_for(0, h, [&](int y) {
        for (int c = 0; c < 3; ++c) {
            float* dst = &v(0, y, c);
            const unsigned char* src = rgb.data() + size_t(y) * size_t(w) * 3 + size_t(c);
            for (int x = 0; x < w; ++x) dst[x] = lut[src[size_t(x) * 3]];
        }
    });
    return img;
}

// An stb-read file (PNG, BMP, TGA, HDR), in memory and checked: its bytes and the header as stb's
// info call reads it (w, h, n channels in the file).
struct StbFile {
    std::vector<unsigned char> bytes;
    int len = 0, w = 0, h = 0, n = 0;
};

static StbFile openStb(const std::string& path) {
    StbFile f;
    // The whole file in memory (its size is what it holds), checked, then decoded from there.
    f.bytes.resize(static_cast<size_t>(fileSize(path)));
    {
        std::ifstream in(path, std::ios::binary);
        if (!in.read(reinterpret_cast<char*>(f.bytes.data()), std::streamsize(f.bytes.size())))
            throw InputError(path + ": cannot read the file");
    }
    requireFormatOfExtension(path, f.bytes);
    return f;
}

// The header checks of an stb format (not JPEG), then f.w, f.h, f.n as stb reads them.
static void checkStb(const std::string& path, StbFile& f) {
    checkPngChunks(path, f.bytes);
    f.len = f.bytes.size() > size_t(INT32_MAX) ? INT32_MAX : int(f.bytes.size());
    // Every check below needs the header as stb reads it: a file whose header stb's info call
    // cannot read is refused, not handed to its loader (whose header parse differs: a 203-byte .hdr
    // with two FORMAT lines passed to the loader looped for minutes, found by tests/fuzz/libfuzzer).
    if (!stbi_info_from_memory(f.bytes.data(), f.len, &f.w, &f.h, &f.n))
        throw InputError(path + ": cannot read image (" + stbi_failure_reason() + ")");
    // stb's BMP info gives a top-down file's height negative; its loader reads it as |h|.
    if (extensionOf(path) == ".bmp" && f.h < 0 && f.h > -65536) f.h = -f.h;
    requireImagePixelsFit(path, f.bytes, f.w, f.h);
}

// stb's pixels (`channels` interleaved, 8-bit, 16-bit or float) as planes of `img`, each value
// through conv. The planes are img's first `planes`, from the interleaved channels `from`.
template <class T, class Conv>
static void deinterleave(const T* data, int channels, Image& img, int planes, int from, Conv conv) {
    const ImageView v = img.view();
    const int w = img.width();
    tbb::parallel_for(0, img.height(), [&](int y) {
        for (int c = 0; c < planes; ++c) {
            float* dst = &v(0, y, c);
            const T* src = data + size_t(y) * size_t(w) * size_t(channels) + size_t(from + c);
            for (int x = 0; x < w; ++x) dst[x] = conv(src[size_t(x) * size_t(channels)]);
        }
    });
}

// Decodes f as stb does, `want` channels interleaved (0: as many as the file has), and hands the
// pixels to use(data, bits) (8, 16 or 32 for float: Radiance .hdr) before freeing them.
template <class Use>
static void decodeStb(const std::string& path, const StbFile& f, int want, Use use) {
    int w = 0, h = 0, n = 0;
    void* data = nullptr;
    int bits = 8;
    if (extensionOf(path) == ".hdr") {
        data = stbi_loadf_from_memory(f.bytes.data(), f.len, &w, &h, &n, want), bits = 32;
    } else if (stbi_is_16_bit_from_memory(f.bytes.data(), f.len)) {
        data = stbi_load_16_from_memory(f.bytes.data(), f.len, &w, &h, &n, want), bits = 16;
    } else {
        data = stbi_load_from_memory(f.bytes.data(), f.len, &w, &h, &n, want);
    }
    if (!data) throw InputError(path + ": cannot read image (" + stbi_failure_reason() + ")");
    try {
        use(data, bits);
    } catch (...) {
        stbi_image_free(data);
        throw;
    }
    stbi_image_free(data);
}

static Image readStb(const std::string& path, int* sourceChannels) {
    StbFile f = openStb(path);
    const std::string ext = extensionOf(path);
    if (ext == ".jpg" || ext == ".jpeg") return readJpeg(path, f.bytes, sourceChannels);
    checkStb(path, f);
    if (sourceChannels) *sourceChannels = f.n <= 2 ? 1 : 3;  // grey (+ alpha) or colour (+ alpha)
    // Radiance .hdr as is; 8- and 16-bit codes through the sRGB curve (srgbCodes).
    Image img;
    decodeStb(path, f, 3, [&](const void* data, int bits) {
        img = Image::uninitialized(f.w, f.h, 3);
        if (bits == 32) deinterleave(static_cast<const float*>(data), 3, img, 3, 0, [](float v) { return v; });
        if (bits == 16)
            deinterleave(static_cast<const uint16_t*>(data), 3, img, 3, 0,
                         [](uint16_t v) { return srgbDecode(float(v) / 65535.0f); });
        if (bits == 8) {
            const float* lut = srgbCodes();
            deinterleave(static_cast<const unsigned char*>(data), 3, img, 3, 0, [lut](unsigned char v) { return lut[v]; });
        }
    });
    return img;
}

Image readStbAlpha(const std::string& path) {
    requireFile(path);
    const std::string ext = extensionOf(path);
    if (ext == ".jpg" || ext == ".jpeg" || ext == ".hdr") return {};  // no alpha in these formats: not read again
    StbFile f = openStb(path);
    checkStb(path, f);
    if (f.n != 2 && f.n != 4) return {};
    Image a;
    // Alpha is a coverage, stored linearly (PNG's rule): code / max.
    decodeStb(path, f, 0, [&](const void* data, int bits) {
        a = Image::uninitialized(f.w, f.h, 1);
        if (bits == 16)
            deinterleave(static_cast<const uint16_t*>(data), f.n, a, 1, f.n - 1, [](uint16_t v) { return float(v) / 65535.0f; });
        else
            deinterleave(static_cast<const unsigned char*>(data), f.n, a, 1, f.n - 1,
                         [](unsigned char v) { return float(v) / 255.0f; });
    });
    return a;
}

bool isLdrFormat(const std::string& path) {
    const std::string ext = extensionOf(path);
    return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tga";
}

// ------------------------------------------------------------------------------------ helpers

void requireFinitePixel(const Image& color, const std::string& what) {
    if (color.empty() || color.device() != Device::Cpu) return;
    const size_t n = color.plane();
    const int ch = std::min(color.channels(), 3);
    for (size_t i = 0; i < n; ++i) {
        bool finite = true;
        for (int c = 0; c < ch && finite; ++c) finite = std::isfinite(color.data()[size_t(c) * n + i]);
        if (finite) return;
    }
    throw InputError((what.empty() ? std::string() : what + ": ") +
                     "color buffer has no finite pixel (every pixel has a NaN or an infinite value): nothing to denoise");
}

void ensureWritableDirectory(const std::string& dir) {
    std::error_code ec;
    if (fs::exists(dir, ec)) {
        if (!fs::is_directory(dir, ec)) throw InputError(dir + ": exists and is not a directory");
    } else if (!fs::create_directories(dir, ec) || ec) {
        throw InputError(dir + ": cannot create output directory (" + ec.message() + ")");
    }
    if (access(dir.c_str(), W_OK | X_OK) != 0) throw InputError(dir + ": output directory is not writable");
}

void writeFileAtomically(const std::string& path, const std::function<void(const std::string&)>& writer) {
    fs::path target(path);
    fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        if (fs::exists(dir, ec))
            throw InputError(path + ": " + dir.string() + " is not a directory");
        throw InputError(path + ": output directory " + dir.string() + " does not exist");
    }
    if (access(dir.c_str(), W_OK | X_OK) != 0) throw InputError(path + ": output directory is not writable");
    // Keep the extension last so libraries that look at it (stb, OpenEXR) still see it.
    std::string tmp = (dir / ("." + target.stem().string() + ".tmp" + std::to_string(getpid()) + target.extension().string())).string();
    try {
        writer(tmp);
    } catch (...) {
        fs::remove(tmp, ec);
        throw;
    }
    fs::rename(tmp, target, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw RuntimeError(path + ": cannot rename temporary file into place (" + ec.message() + ")");
    }
}

}  // namespace atrous::io

namespace atrous {

// The one image reader and writer (atrous/io.h), by the file's extension.
Image readImage(const std::string& path, int* sourceChannels, int channels) {
    using namespace io;
    requireFile(path);
    if (channels < 1 || channels > 3) throw InputError(path + ": readImage takes 1 to 3 channels");
    const std::string ext = extensionOf(path);
    if (ext == ".exr") return namingFile(path, [&] { return readExr(path, sourceChannels, channels); });
    if (ext == ".pfm") return namingFile(path, [&] { return firstChannels(readPfm(path, sourceChannels), channels); });
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".hdr" || ext == ".bmp" || ext == ".tga")
        return namingFile(path, [&] { return firstChannels(readStb(path, sourceChannels), channels); });
    throw InputError(path + ": unsupported image format '" + ext + "' (expected .exr, .pfm, .png, .jpg or .hdr)");
}

// The one image writer (atrous/io.h), by the file's extension.
void writeImage(const std::string& path, const Image& img) {
    using namespace io;
    // The writers read host memory; a denoise() result may live on the GPU.
    if (img.device() != Device::Cpu) return writeImage(path, img.to(Device::Cpu));
    requireNoNul(path);
    const std::string ext = extensionOf(path);
    if (ext == ".exr") return writeExr(path, img);
    if (ext == ".pfm") return writePfm(path, img);
    if (ext == ".png") return writePng(path, img);
    throw InputError(path + ": unsupported output format '" + ext + "' (expected .exr, .pfm or .png)");
}

}  // namespace atrous

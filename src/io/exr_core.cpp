#include "io/exr_core.h"

#include <libdeflate.h>
#include <openexr.h>
#include <tbb/parallel_for.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <atomic>
#include <cstring>
#include <mutex>

#include "atrous/error.h"

namespace atrous::io {

namespace {

// OpenEXR Core reports an error through this callback on the thread that met it (its default
// prints to stderr): the message is kept for the InputError that follows.
thread_local std::string tLastError;
void keepError(exr_const_context_t, exr_result_t code, const char* msg) {
    tLastError = msg && *msg ? msg : exr_get_default_error_message(code);
}

std::string errorText(exr_result_t rv) {
    std::string m = tLastError.empty() ? exr_get_default_error_message(rv) : tLastError;
    tLastError.clear();
    return m;
}

// The most unpacked bytes one packed byte can hold, by compression (exr_limits.cpp's ratios).
double maxExpansion(exr_compression_t c) {
    switch (c) {
        case EXR_COMPRESSION_NONE: return 1.0;
        case EXR_COMPRESSION_RLE: return 64.0;
        case EXR_COMPRESSION_B44:
        case EXR_COMPRESSION_B44A: return 16.0;
        case EXR_COMPRESSION_ZIPS:
        case EXR_COMPRESSION_ZIP:
        case EXR_COMPRESSION_PXR24: return 1100.0;
        default: return 8192.0;
    }
}

// EXR's ZIP: a zlib stream of the pixel bytes split into even and odd halves, each byte stored as
// its difference from the one before (+128). libdeflate inflates; the two cheap steps after it
// undo the predictor and the split, as OpenEXR's internal_zip.c does.
struct Inflater {
    libdeflate_decompressor* d = libdeflate_alloc_decompressor();
    std::vector<uint8_t> scratch;
    ~Inflater() { libdeflate_free_decompressor(d); }
};
thread_local Inflater tInflater;

// t[i] = t[i - 1] + t[i] - 128 for i >= 1 (a running byte sum). SSE2: 16 bytes at a time, the sum
// inside a vector in four shifted adds, carried from the last byte of the one before.
void undoPredictor(uint8_t* t, uint64_t n) {
    if (n == 0) return;
    uint64_t i = 0;
#if defined(__SSE2__)
    t[0] = uint8_t(t[0] + 128);  // the first byte has no offset: pre-add what the loop takes away
    const __m128i bias = _mm_set1_epi8(char(-128));
    uint8_t prev = 0;
    for (; i + 16 <= n; i += 16) {
        __m128i d = _mm_add_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(t + i)), bias);
        d = _mm_add_epi8(d, _mm_slli_si128(d, 1));
        d = _mm_add_epi8(d, _mm_slli_si128(d, 2));
        d = _mm_add_epi8(d, _mm_slli_si128(d, 4));
        d = _mm_add_epi8(d, _mm_slli_si128(d, 8));
        d = _mm_add_epi8(d, _mm_set1_epi8(char(prev)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(t + i), d);
        prev = uint8_t(_mm_extract_epi16(d, 7) >> 8);
    }
    if (i == 0) t[0] = uint8_t(t[0] - 128);
#endif
    for (i = std::max<uint64_t>(i, 1); i < n; ++i) t[i] = uint8_t(int(t[i - 1]) + int(t[i]) - 128);
}

// out = the even half and the odd half of t, byte by byte: out[2k] = t[k], out[2k+1] = t[(n+1)/2 + k].
void interleave(uint8_t* out, const uint8_t* t, uint64_t n) {
    const uint8_t* even = t;
    const uint8_t* odd = t + (n + 1) / 2;
    const uint64_t pairs = n / 2;
    uint64_t k = 0;
#if defined(__SSE2__)
    for (; k + 16 <= pairs; k += 16) {
        const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(even + k));
        const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(odd + k));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * k), _mm_unpacklo_epi8(a, b));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * k + 16), _mm_unpackhi_epi8(a, b));
    }
#endif
    for (; k < pairs; ++k) {
        out[2 * k] = even[k];
        out[2 * k + 1] = odd[k];
    }
    if (n & 1) out[n - 1] = even[pairs];
}

exr_result_t undoZip(exr_decode_pipeline_t* decode) {
    const uint64_t packed = decode->chunk.packed_size, unpacked = decode->chunk.unpacked_size;
    if (packed == 0) return EXR_ERR_SUCCESS;
    if (packed == unpacked) {  // stored as it is (the pipeline points both buffers at the same bytes)
        if (decode->unpacked_buffer != decode->packed_buffer) std::memcpy(decode->unpacked_buffer, decode->packed_buffer, unpacked);
        return EXR_ERR_SUCCESS;
    }
    Inflater& inf = tInflater;
    if (!inf.d) return EXR_ERR_OUT_OF_MEMORY;
    inf.scratch.resize(unpacked);
    size_t got = 0;
    if (libdeflate_zlib_decompress(inf.d, decode->packed_buffer, packed, inf.scratch.data(), unpacked, &got) !=
            LIBDEFLATE_SUCCESS ||
        got != unpacked) {
        tLastError = "a ZIP chunk does not inflate to its " + std::to_string(unpacked) + " bytes";
        return EXR_ERR_CORRUPT_CHUNK;
    }
    undoPredictor(inf.scratch.data(), unpacked);
    interleave(static_cast<uint8_t*>(decode->unpacked_buffer), inf.scratch.data(), unpacked);
    return EXR_ERR_SUCCESS;
}

// The same steps forwards: split, predictor, deflate (OpenEXR's internal_zip.c, compress side).
struct Deflater {
    libdeflate_compressor* c = nullptr;
    int level = -1;
    std::vector<uint8_t> scratch;
    ~Deflater() {
        if (c) libdeflate_free_compressor(c);
    }
};
thread_local Deflater tDeflater;

// Packs and compresses one chunk; returns its bytes (the raw packed bytes when deflate does not
// make them smaller, as OpenEXR does).
std::vector<uint8_t> zipChunk(const std::vector<uint8_t>& packed, int level) {
    Deflater& d = tDeflater;
    if (d.level != level) {
        if (d.c) libdeflate_free_compressor(d.c);
        d.c = libdeflate_alloc_compressor(level);
        d.level = level;
    }
    if (!d.c) throw std::bad_alloc();
    const size_t n = packed.size();
    d.scratch.resize(2 * n);
    uint8_t* split = d.scratch.data();  // the even bytes, then the odd ones
    uint8_t* t = split + n;             // each byte's difference from the one before, + 128
    const size_t half = (n + 1) / 2;
    for (size_t k = 0; k < n / 2; ++k) {
        split[k] = packed[2 * k];
        split[half + k] = packed[2 * k + 1];
    }
    if (n & 1) split[n / 2] = packed[n - 1];
    if (n) t[0] = split[0];
    for (size_t i = 1; i < n; ++i) t[i] = uint8_t(int(split[i]) - int(split[i - 1]) + 128);
    std::vector<uint8_t> out(libdeflate_zlib_compress_bound(d.c, n));
    const size_t got = libdeflate_zlib_compress(d.c, t, n, out.data(), out.size());
    if (got == 0 || got >= n) return packed;
    out.resize(got);
    return out;
}

}  // namespace

void writeExrCore(const std::string& path, int width, int height, const std::vector<std::string>& names,
                  const std::vector<const float*>& planes, int level) {
    exr_context_t ctx = nullptr;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = keepError;
    auto check = [&](exr_result_t rv, const char* step) {
        if (rv == EXR_ERR_SUCCESS) return;
        const std::string msg = errorText(rv);
        if (ctx) exr_finish(&ctx);
        throw RuntimeError(path + ": cannot write EXR (" + step + ": " + msg + ")");
    };
    check(exr_start_write(&ctx, path.c_str(), EXR_WRITE_FILE_DIRECTLY, &init), "open");
    int part = 0;
    check(exr_add_part(ctx, "", EXR_STORAGE_SCANLINE, &part), "part");
    check(exr_initialize_required_attr_simple(ctx, part, width, height, EXR_COMPRESSION_ZIP), "header");
    for (const std::string& n : names)
        check(exr_add_channel(ctx, part, n.c_str(), EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1), "channel");
    check(exr_write_header(ctx), "header");
    // A chunk holds its lines one after the other, each line its channels in the file's (sorted) order.
    const exr_attr_chlist_t* list = nullptr;
    check(exr_get_channels(ctx, part, &list), "channels");
    std::vector<const float*> ordered;
    for (int i = 0; i < list->num_channels; ++i)
        for (size_t k = 0; k < names.size(); ++k)
            if (names[k] == list->entries[i].name.str) ordered.push_back(planes[k]);
    int32_t lpc = 16;
    check(exr_get_scanlines_per_chunk(ctx, part, &lpc), "chunks");
    const int chunks = (height + lpc - 1) / lpc;
    std::vector<std::vector<uint8_t>> data(static_cast<size_t>(chunks));
    const size_t row = size_t(width);
    tbb::parallel_for(0, chunks, [&](int ci) {
        const int y0 = ci * lpc, y1 = std::min(height, y0 + lpc);
        std::vector<uint8_t> packed(size_t(y1 - y0) * ordered.size() * row * sizeof(float));
        uint8_t* p = packed.data();
        for (int y = y0; y < y1; ++y)
            for (const float* plane : ordered) {
                std::memcpy(p, plane + size_t(y) * row, row * sizeof(float));  // little-endian, as EXR stores it
                p += row * sizeof(float);
            }
        data[size_t(ci)] = zipChunk(packed, level);
    });
    for (int ci = 0; ci < chunks; ++ci)
        check(exr_write_scanline_chunk(ctx, part, ci * lpc, data[size_t(ci)].data(), data[size_t(ci)].size()), "pixels");
    check(exr_finish(&ctx), "close");
}

struct ExrCoreFile::Impl {
    std::string path;
    exr_context_t ctx = nullptr;
    uint64_t fileBytes = 0;
    std::vector<std::vector<exr_chunk_info_t>> chunks;  // by part: the located chunks

    [[noreturn]] void fail(const std::string& where, exr_result_t rv) const {
        throw InputError(path + ": " + where + " (" + errorText(rv) + ")");
    }
};

ExrCoreFile::ExrCoreFile(const std::string& path) : mImpl(std::make_unique<Impl>()) {
    mImpl->path = path;
    mImpl->fileBytes = exrFileBytes(path);
    requireExrHeadersFit(path);
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = keepError;
    const exr_result_t rv = exr_start_read(&mImpl->ctx, path.c_str(), &init);
    if (rv != EXR_ERR_SUCCESS) {
        mImpl->ctx = nullptr;
        mImpl->fail("cannot read EXR", rv);
    }
    int parts = 0;
    exr_get_count(mImpl->ctx, &parts);
    mImpl->chunks.resize(size_t(std::max(parts, 0)));
}

ExrCoreFile::~ExrCoreFile() {
    if (mImpl && mImpl->ctx) exr_finish(&mImpl->ctx);
}

bool ExrCoreFile::decodes(int part) const {
    exr_storage_t s;
    exr_compression_t c;
    if (exr_get_storage(mImpl->ctx, part, &s) != EXR_ERR_SUCCESS || s != EXR_STORAGE_SCANLINE) return false;
    if (exr_get_compression(mImpl->ctx, part, &c) != EXR_ERR_SUCCESS) return false;
    return c == EXR_COMPRESSION_NONE || c == EXR_COMPRESSION_RLE || c == EXR_COMPRESSION_ZIPS || c == EXR_COMPRESSION_ZIP ||
           c == EXR_COMPRESSION_PIZ || c == EXR_COMPRESSION_PXR24;
}

void ExrCoreFile::locate(int part, const ExrWindow& win, const std::string& what) {
    Impl& m = *mImpl;
    exr_attr_box2i_t dw;
    int32_t lpc = 1;
    exr_compression_t comp = EXR_COMPRESSION_NONE;
    if (exr_get_data_window(m.ctx, part, &dw) != EXR_ERR_SUCCESS || exr_get_scanlines_per_chunk(m.ctx, part, &lpc) != EXR_ERR_SUCCESS ||
        exr_get_compression(m.ctx, part, &comp) != EXR_ERR_SUCCESS || lpc <= 0)
        m.fail("cannot read the header of the part holding " + what, EXR_ERR_INVALID_ARGUMENT);
    std::vector<exr_chunk_info_t>& found = m.chunks.at(size_t(part));
    found.clear();
    const int yEnd = win.y0 + win.height - 1;
    // The first chunk holding row win.y0, then one per lpc rows (the Core rounds to chunk starts).
    const int first = dw.min.y + ((win.y0 - dw.min.y) / lpc) * lpc;
    for (long y = first; y <= yEnd; y += lpc) {
        exr_chunk_info_t c;
        const exr_result_t rv = exr_read_scanline_chunk_info(m.ctx, part, int(y), &c);
        if (rv != EXR_ERR_SUCCESS) m.fail("truncated or corrupt EXR: the chunk of row " + std::to_string(y) + " (" + what + ")", rv);
        const double room = double(c.packed_size) * maxExpansion(comp) + 65536.0;
        if (c.packed_size == 0 || c.data_offset + c.packed_size > m.fileBytes || double(c.unpacked_size) > room)
            throw InputError(m.path + ": truncated or corrupt EXR (the chunk of row " + std::to_string(y) + " of " + what +
                             " claims " + std::to_string(c.unpacked_size) + " bytes of pixels in " +
                             std::to_string(c.packed_size) + " bytes at offset " + std::to_string(c.data_offset) +
                             " of a " + std::to_string(m.fileBytes) + "-byte file)");
        found.push_back(c);
    }
}

void ExrCoreFile::decode(int part, const std::vector<ExrPlaneRequest>& requests, const ExrWindow& win,
                         const std::string& what) {
    Impl& m = *mImpl;
    const std::vector<exr_chunk_info_t>& chunks = m.chunks.at(size_t(part));
    std::mutex failMutex;
    std::string failure;
    std::atomic<bool> failed{false};
    const size_t rowFloats = size_t(win.width);
    tbb::parallel_for(size_t(0), chunks.size(), [&](size_t i) {
        if (failed.load(std::memory_order_relaxed)) return;
        const exr_chunk_info_t& c = chunks[i];
        exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
        auto stop = [&](exr_result_t rv, const char* step) {
            std::lock_guard<std::mutex> lock(failMutex);
            if (!failed.exchange(true))
                failure = std::string("cannot ") + step + " the chunk of row " + std::to_string(c.start_y) + " of " + what + " (" +
                          errorText(rv) + ")";
            exr_decoding_destroy(m.ctx, &dec);
        };
        exr_result_t rv = exr_decoding_initialize(m.ctx, part, &c, &dec);
        if (rv != EXR_ERR_SUCCESS) return stop(rv, "read");
        // Rows of this chunk inside the image, and whether its columns are the image's. The chunk
        // must span the image's columns (the caller checked the data window it read from the
        // header against the image; this is the data window OpenEXR's Core decodes).
        if (c.start_x > win.x0 || int64_t(c.start_x) + c.width < int64_t(win.x0) + win.width)
            return stop(EXR_ERR_INVALID_ARGUMENT, "place");
        const int y0 = std::max(c.start_y, win.y0), y1 = std::min(c.start_y + c.height - 1, win.y0 + win.height - 1);
        const bool direct = c.start_x == win.x0 && c.width == win.width && y0 == c.start_y && y1 == c.start_y + c.height - 1;
        std::vector<float> scratch;
        if (!direct) scratch.resize(size_t(c.width) * size_t(c.height) * requests.size());
        size_t matched = 0;
        for (int k = 0; k < dec.channel_count; ++k) {
            exr_coding_channel_info_t& ch = dec.channels[k];
            ch.decode_to_ptr = nullptr;  // not requested: skipped
            for (size_t r = 0; r < requests.size(); ++r) {
                if (requests[r].channel != ch.channel_name) continue;
                ++matched;
                ch.user_data_type = EXR_PIXEL_FLOAT;
                ch.user_bytes_per_element = 4;
                ch.user_pixel_stride = 4;
                if (direct) {
                    ch.user_line_stride = int32_t(rowFloats * 4);
                    ch.decode_to_ptr = reinterpret_cast<uint8_t*>(requests[r].plane + size_t(c.start_y - win.y0) * rowFloats);
                } else {
                    ch.user_line_stride = c.width * 4;
                    ch.decode_to_ptr = reinterpret_cast<uint8_t*>(scratch.data() + r * size_t(c.width) * size_t(c.height));
                }
            }
        }
        if (matched != requests.size()) return stop(EXR_ERR_NO_ATTR_BY_NAME, "find every channel in");
        // OpenEXR 3.1 Core picks its 3- and 4-channel half-to-float routines without looking at which
        // channels have a destination, and writes through the null pointer of one that has none
        // (a Blender part's A: found by tests/fuzz, a segfault). Those channels get a sink.
        std::vector<float> sink;
        if (matched < size_t(dec.channel_count) && dec.channel_count <= 4) {
            sink.resize(size_t(c.width) * size_t(c.height));
            for (int k = 0; k < dec.channel_count; ++k) {
                exr_coding_channel_info_t& ch = dec.channels[k];
                if (ch.decode_to_ptr) continue;
                ch.user_data_type = EXR_PIXEL_FLOAT;
                ch.user_bytes_per_element = 4;
                ch.user_pixel_stride = 4;
                ch.user_line_stride = c.width * 4;
                ch.decode_to_ptr = reinterpret_cast<uint8_t*>(sink.data());
            }
        }
        rv = exr_decoding_choose_default_routines(m.ctx, part, &dec);
        if (rv != EXR_ERR_SUCCESS) return stop(rv, "decode");
        if (c.compression == EXR_COMPRESSION_ZIP || c.compression == EXR_COMPRESSION_ZIPS) dec.decompress_fn = undoZip;
        rv = exr_decoding_run(m.ctx, part, &dec);
        if (rv != EXR_ERR_SUCCESS) return stop(rv, "decode");
        if (!direct)
            for (size_t r = 0; r < requests.size(); ++r)
                for (int y = y0; y <= y1; ++y) {
                    const float* src = scratch.data() + r * size_t(c.width) * size_t(c.height) + size_t(y - c.start_y) * size_t(c.width) +
                                       size_t(win.x0 - c.start_x);
                    std::copy(src, src + rowFloats, requests[r].plane + size_t(y - win.y0) * rowFloats);
                }
        exr_decoding_destroy(m.ctx, &dec);
    });
    if (failed) throw InputError(m.path + ": " + failure);
}

}  // namespace atrous::io

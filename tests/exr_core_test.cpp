// The EXR path through OpenEXR Core (src/io/exr_core.h): every compression, pixel type and part
// layout decodes to exactly what OpenEXR's classic API decodes from the same file (ZIP through
// libdeflate, the others through OpenEXR's own routines), the writer's files read back bit for bit
// with the classic API, and damaged files are one InputError naming the file.
#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <half.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "exr_fixture.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "atrous/io/pass_map.h"

using namespace atrous;
using namespace atrous::test;
namespace fs = std::filesystem;

namespace {

// Noise with structure: values over many exponents, some negative, as a render's buffers hold.
float pixelValue(int x, int y, int c) {
    uint32_t h = uint32_t(x) * 2654435761u ^ uint32_t(y) * 40503u ^ uint32_t(c + 1) * 97u;
    h ^= h >> 15;
    const float u = float(h & 0xffff) / 65535.0f;
    return (u - 0.1f) * std::exp2(float(int(h >> 16) % 12 - 6)) + 0.01f * float(x);
}

// A single-part RGB file written by the classic API with the given compression and type.
void writeClassic(const std::string& path, int w, int h, Imf::Compression comp, Imf::PixelType type,
                  Imath::Box2i dw = Imath::Box2i()) {
    if (dw.isEmpty()) dw = box(0, 0, w - 1, h - 1);
    Imf::Header hd(box(0, 0, w - 1, h - 1), dw);
    hd.compression() = comp;
    const int dwW = dw.max.x - dw.min.x + 1, dwH = dw.max.y - dw.min.y + 1;
    std::vector<float> f[3];
    std::vector<half> hf[3];
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        hd.channels().insert(names[c], Imf::Channel(type));
        f[c].resize(size_t(dwW) * size_t(dwH));
        hf[c].resize(f[c].size());
        for (int y = 0; y < dwH; ++y)
            for (int x = 0; x < dwW; ++x) {
                f[c][size_t(y) * size_t(dwW) + size_t(x)] = pixelValue(x + dw.min.x, y + dw.min.y, c);
                hf[c][size_t(y) * size_t(dwW) + size_t(x)] = half(pixelValue(x + dw.min.x, y + dw.min.y, c));
            }
        char* base = type == Imf::HALF ? reinterpret_cast<char*>(hf[c].data()) : reinterpret_cast<char*>(f[c].data());
        const size_t bytes = type == Imf::HALF ? 2 : 4;
        base -= (long(dw.min.x) + long(dw.min.y) * dwW) * long(bytes);
        fb.insert(names[c], Imf::Slice(type, base, bytes, bytes * size_t(dwW)));
    }
    Imf::OutputFile out(path.c_str(), hd);
    out.setFrameBuffer(fb);
    out.writePixels(dwH);
}

// What the classic API decodes: the display window's pixels as float planes.
Image readClassic(const std::string& path) {
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow(), disp = in.header().displayWindow();
    const int dwW = dw.max.x - dw.min.x + 1, dwH = dw.max.y - dw.min.y + 1;
    std::vector<float> f[3];
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        f[c].resize(size_t(dwW) * size_t(dwH));
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(f[c].data()) - (long(dw.min.x) + long(dw.min.y) * dwW) * 4,
                                       4, 4 * size_t(dwW)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    const int w = disp.max.x - disp.min.x + 1, h = disp.max.y - disp.min.y + 1;
    Image img(w, h, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                img(x, y, c) = f[c][size_t(y + disp.min.y - dw.min.y) * size_t(dwW) + size_t(x + disp.min.x - dw.min.x)];
    return img;
}

bool bitEqual(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() && a.channels() == b.channels() &&
           std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace

TEST(ExrCore, EveryCompressionAndTypeDecodesAsTheClassicApiDoes) {
    TempDir dir;
    const Imf::Compression comps[] = {Imf::NO_COMPRESSION, Imf::RLE_COMPRESSION, Imf::ZIPS_COMPRESSION, Imf::ZIP_COMPRESSION,
                                      Imf::PIZ_COMPRESSION, Imf::PXR24_COMPRESSION, Imf::B44_COMPRESSION, Imf::DWAA_COMPRESSION};
    for (Imf::Compression comp : comps)
        for (Imf::PixelType type : {Imf::FLOAT, Imf::HALF}) {
            // 77 x 53: chunks of 1, 16 and 32 lines end part-way, rows are not a multiple of 4.
            const std::string f = dir / ("c" + std::to_string(int(comp)) + "_" + std::to_string(int(type)) + ".exr");
            writeClassic(f, 77, 53, comp, type);
            EXPECT_TRUE(bitEqual(atrous::readImage(f), readClassic(f))) << "compression " << int(comp) << " type " << int(type);
        }
}

TEST(ExrCore, DataWindowsAroundTheImageDecodeAsTheClassicApiDoes) {
    TempDir dir;
    // Overscan on every side (the crop path, through a chunk-sized scratch), and a data window
    // that starts inside a ZIP chunk's 16 lines.
    writeClassic(dir / "over.exr", 40, 30, Imf::ZIP_COMPRESSION, Imf::FLOAT, box(-3, -7, 45, 36));
    EXPECT_TRUE(bitEqual(atrous::readImage(dir / "over.exr"), readClassic(dir / "over.exr")));
    writeClassic(dir / "half_over.exr", 40, 30, Imf::PIZ_COMPRESSION, Imf::HALF, box(-1, -20, 40, 29));
    EXPECT_TRUE(bitEqual(atrous::readImage(dir / "half_over.exr"), readClassic(dir / "half_over.exr")));
}

TEST(ExrCore, TiledFilesAreReadThroughTheClassicApi) {
    TempDir dir;
    const int w = 37, h = 29;
    Imf::Header hd(w, h);
    hd.setTileDescription(Imf::TileDescription(8, 8, Imf::ONE_LEVEL));
    hd.compression() = Imf::ZIP_COMPRESSION;
    std::vector<float> f[3];
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        hd.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
        f[c].resize(size_t(w) * size_t(h));
        for (int i = 0; i < w * h; ++i) f[c][size_t(i)] = pixelValue(i % w, i / w, c);
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(f[c].data()), 4, 4 * size_t(w)));
    }
    {
        Imf::TiledOutputFile out((dir / "tiled.exr").c_str(), hd);
        out.setFrameBuffer(fb);
        out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
    }
    const Image img = atrous::readImage(dir / "tiled.exr");
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < w * h; ++i) ASSERT_EQ(img(i % w, i / w, c), f[c][size_t(i)]);
}

TEST(ExrCore, WrittenFilesReadBackBitForBitWithTheClassicApi) {
    TempDir dir;
    for (const auto& [w, h] : {std::pair<int, int>{1, 1}, {77, 53}, {640, 17}}) {
        Image img(w, h, 3);
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) img(x, y, c) = pixelValue(x, y, c);
        img(0, 0, 1) = -0.0f;
        const std::string f = dir / ("w" + std::to_string(w) + ".exr");
        io::writeExr(f, img);
        EXPECT_TRUE(bitEqual(readClassic(f), img)) << w << "x" << h;
        EXPECT_TRUE(bitEqual(atrous::readImage(f), img)) << w << "x" << h;
    }
    // A constant image deflates to almost nothing; a 1-channel image is written as grey R,G,B.
    Image grey(300, 40, 1);
    grey.fill(0.25f);
    io::writeExr(dir / "grey.exr", grey);
    EXPECT_LT(fs::file_size(dir / "grey.exr"), 4096u);
    const Image back = readClassic(dir / "grey.exr");
    for (int c = 0; c < 3; ++c) EXPECT_EQ(back(299, 39, c), 0.25f);
}

TEST(ExrCore, DamagedFilesAreOneErrorNamingTheFile) {
    TempDir dir;
    writeClassic(dir / "ok.exr", 64, 64, Imf::ZIP_COMPRESSION, Imf::FLOAT);
    const std::string bytes = fileBytes(dir / "ok.exr");
    // Cut at several places, and a run of bytes of the pixel data flipped (the chunk table and
    // the chunks' leaders intact): each is an InputError naming the file, never a crash.
    for (const size_t cut : {bytes.size() / 2, bytes.size() - 100, bytes.size() - 1}) {
        std::ofstream(dir / "cut.exr", std::ios::binary) << bytes.substr(0, cut);
        try {
            atrous::readImage(dir / "cut.exr");
            ADD_FAILURE() << "a file cut at " << cut << " of " << bytes.size() << " bytes was read";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("cut.exr"), std::string::npos) << e.what();
        }
    }
    std::string flipped = bytes;
    for (size_t i = bytes.size() / 2; i < bytes.size() / 2 + 64; ++i) flipped[i] = char(~flipped[i]);
    std::ofstream(dir / "flipped.exr", std::ios::binary) << flipped;
    try {
        atrous::readImage(dir / "flipped.exr");
        ADD_FAILURE() << "a file with damaged pixel data was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("flipped.exr"), std::string::npos) << e.what();
    }
}

// A part with channels that are not read (Blender's Combined has an A) in half floats: OpenEXR 3.1
// Core's 4-channel half-to-float routine wrote through the missing destination (found by
// tests/fuzz: a segfault on a Blender-5 multipart file of half channels).
TEST(ExrCore, HalfPartsWithChannelsNotReadDecode) {
    TempDir dir;
    Image rgba(19, 11, 4), alb(19, 11, 3);
    for (int c = 0; c < 4; ++c)
        for (int y = 0; y < 11; ++y)
            for (int x = 0; x < 19; ++x) {
                rgba(x, y, c) = float(half(pixelValue(x, y, c)));
                if (c < 3) alb(x, y, c) = float(half(0.5f + 0.01f * float(x + y + c)));
            }
    for (const bool multipart : {true, false}) {
        const std::string f = dir / (multipart ? "multi.exr" : "single.exr");
        io::writeLayeredExr(f, {{"ViewLayer.Combined", &rgba, {"R", "G", "B", "A"}}, {"ViewLayer.Denoising Albedo", &alb}},
                            multipart, /*halfFloat=*/true);
        const io::ExrInfo info = io::inspectExr(f);
        const io::PassMap m = io::mapPasses(info, {}, "");
        const Image c = io::readPass(info, m[io::Buffer::Color], io::Buffer::Color);
        const Image a = io::readPass(info, m[io::Buffer::Albedo], io::Buffer::Albedo);
        for (int y = 0; y < 11; ++y)
            for (int x = 0; x < 19; ++x)
                for (int ch = 0; ch < 3; ++ch) {
                    ASSERT_EQ(c(x, y, ch), rgba(x, y, ch)) << (multipart ? "multipart" : "single part");
                    ASSERT_EQ(a(x, y, ch), std::min(alb(x, y, ch), 1.0f)) << (multipart ? "multipart" : "single part");
                }
    }
}

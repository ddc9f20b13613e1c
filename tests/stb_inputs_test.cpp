// PNG and the other formats stb_image reads, checked before stb sees them, and JPEG, read by
// libjpeg-turbo instead (src/io/image_io.cpp, docs/inputs.md): the libFuzzer targets' reproducers of stb_image 2.27's faults (kept in
// tests/data/stb_regressions) are refused in one InputError naming the file, and valid files with
// the unusual-but-legal parts those checks touch (an empty IDAT chunk, data after IEND) still read.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "exr_fixture.h"
#include "atrous/io/image_io.h"

using namespace atrous;
using namespace atrous::test;
namespace fs = std::filesystem;

namespace {

std::string errorOf(const std::string& path) {
    try {
        atrous::readImage(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

uint32_t crc32(const std::string& s) {
    uint32_t c = 0xffffffffu;
    for (unsigned char ch : s) {
        c ^= ch;
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return ~c;
}

std::string chunk(const std::string& type, const std::string& data) {
    auto be = [](uint32_t v) { return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; };
    return be(uint32_t(data.size())) + type + data + be(crc32(type + data));
}

}  // namespace

TEST(StbInputs, FuzzReproducersAreRefusedNamingTheFile) {
    const std::string data = std::string(ATROUS_SOURCE_DIR) + "/tests/data/stb_regressions/";
    // A 326-byte PNG whose IDAT claims 2 GB (stb reallocs to it), a JPEG DHT of more than 256 codes
    // (stb overruns its table), a JPEG stb shifts by 32 on, a PNM header named .png (stb sniffs it; its numbers overflow an
    // int), a PNG whose first IDAT is empty and whose CRCs are wrong, a .hdr whose "\r" header line
    // our scanline walk took for the header's end (stb does not) and stb then looped on for minutes,
    // a .tga starting FF FF D8 (a JPEG to stb, whose header parser overran its Huffman table), a
    // .hdr whose header line starting with a NUL byte ends the header for stb (a C string) but not
    // for our walk, which then passed a file stb looped on.
    for (const char* name : {"idat_length_2gb.png", "jpeg_dht_overflow.jpg", "jpeg_shift_exponent.jpg", "pnm_integer_overflow.png",
                             "zero_length_idat.png", "hdr_cr_header_loop.hdr", "jpeg_fill_bytes.tga", "hdr_nul_header_line.hdr"}) {
        const std::string msg = errorOf(data + name);
        EXPECT_NE(msg.find(name), std::string::npos) << name << ": " << msg;
        const CliRun r = runCliMeasured("compare --ref " + data + name + " " + data + name);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_TRUE(oneLine(r.output)) << r.output;
        EXPECT_LT(r.peakMb, 100) << name;
    }
}

TEST(StbInputs, LegalPngPartsStillRead) {
    TempDir dir;
    Image img(9, 5, 3);
    for (int c = 0; c < 3; ++c)
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 9; ++x) img(x, y, c) = 0.1f * float((x + y + c) % 10);
    io::writePng(dir / "a.png", img);
    const Image want = atrous::readImage(dir / "a.png");
    // Split the file into its chunks, then add an empty IDAT before the first one and bytes after IEND.
    const std::string bytes = fileBytes(dir / "a.png");
    const size_t firstIdat = bytes.find("IDAT") - 4;
    const std::string edited = bytes.substr(0, firstIdat) + chunk("IDAT", "") + bytes.substr(firstIdat) + "trailing bytes";
    std::ofstream(dir / "b.png", std::ios::binary) << edited;
    const Image got = atrous::readImage(dir / "b.png");
    ASSERT_EQ(got.size(), want.size());
    EXPECT_TRUE(std::equal(want.data(), want.data() + want.size(), got.data()));
    // A flipped byte inside the pixel data fails its CRC (stb would decode it without a word).
    std::string flipped = bytes;
    flipped[firstIdat + 10] = char(flipped[firstIdat + 10] ^ 0x55);
    std::ofstream(dir / "c.png", std::ios::binary) << flipped;
    EXPECT_NE(errorOf(dir / "c.png").find("fails its CRC"), std::string::npos) << errorOf(dir / "c.png");
}

TEST(StbInputs, AFileIsReadOnlyAsTheFormatItsNameSays) {
    TempDir dir;
    Image img(4, 3, 3);
    img.fill(0.5f);
    io::writePng(dir / "a.png", img);
    fs::copy_file(dir / "a.png", dir / "a.jpg");
    fs::copy_file(dir / "a.png", dir / "a.tga");
    std::ofstream(dir / "p.png", std::ios::binary) << "P6\n4 3\n255\n" << std::string(36, '\x80');
    EXPECT_NE(errorOf(dir / "a.jpg").find("a.jpg: not a JPEG file"), std::string::npos) << errorOf(dir / "a.jpg");
    EXPECT_NE(errorOf(dir / "a.tga").find("a.tga: not a TGA file"), std::string::npos) << errorOf(dir / "a.tga");
    EXPECT_NE(errorOf(dir / "p.png").find("p.png: not a PNG file"), std::string::npos) << errorOf(dir / "p.png");
}

// JPEG goes to libjpeg-turbo (stb 2.27's JPEG decoder overruns its tables, shifts by 32 and asserts
// on crafted files): two small files made with ffmpeg (tests/data/images) read as 8-bit sRGB-ish
// values to the power 2.2, as stb read them; a damaged one is an error naming it.
TEST(StbInputs, JpegIsReadByLibjpegTurbo) {
    const std::string data = std::string(ATROUS_SOURCE_DIR) + "/tests/data/images/";
    int channels = 0;
    const Image grey = atrous::readImage(data + "grey_16x8.jpg", &channels);  // (YCbCr: ffmpeg writes no grey JPEG)
    ASSERT_EQ(grey.width(), 16);
    ASSERT_EQ(grey.height(), 8);
    const float g = std::pow(128.0f / 255.0f, 2.2f);  // 0x80, give or take one code value of the codec
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(grey(5, 3, c), g, 0.01f) << c;
    const Image colour = atrous::readImage(data + "colour_16x8.jpg", &channels);
    EXPECT_EQ(channels, 3);
    EXPECT_NEAR(colour(8, 4, 0), 1.0f, 0.03f);                                 // 0xff
    EXPECT_NEAR(colour(8, 4, 1), std::pow(64.0f / 255.0f, 2.2f), 0.02f);       // 0x40
    EXPECT_NEAR(colour(8, 4, 2), std::pow(32.0f / 255.0f, 2.2f), 0.02f);       // 0x20
    TempDir dir;
    std::string bytes = fileBytes(data + "colour_16x8.jpg");
    std::ofstream(dir / "cut.jpg", std::ios::binary) << bytes.substr(0, bytes.size() - 40);
    EXPECT_NE(errorOf(dir / "cut.jpg").find("cut.jpg"), std::string::npos) << errorOf(dir / "cut.jpg");
}

namespace {

std::string le(uint32_t v, int bytes) {
    std::string s;
    for (int i = 0; i < bytes; ++i) s += char((v >> (8 * i)) & 0xff);
    return s;
}

// Pixel (x, y) of the 7x5 test pattern: white where (x + 2y) % 3 == 0, else black with red 255 on
// even rows. As stb reads 8-bit files: 0 and 255 are 0 and 1 exactly.
void patternAt(int x, int y, unsigned char rgb[3]) {
    const bool white = (x + 2 * y) % 3 == 0;
    rgb[0] = white || y % 2 == 0 ? 255 : 0;
    rgb[1] = rgb[2] = white ? 255 : 0;
}

void expectPattern(const Image& img, const std::string& what) {
    ASSERT_EQ(img.width(), 7) << what;
    ASSERT_EQ(img.height(), 5) << what;
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 7; ++x) {
            unsigned char rgb[3];
            patternAt(x, y, rgb);
            for (int c = 0; c < 3; ++c) ASSERT_EQ(img(x, y, c), rgb[c] / 255.0f) << what << " at " << x << "," << y << "," << c;
        }
}

std::string tga(bool rle) {
    std::string s = std::string(1, 0) + char(0) + char(rle ? 10 : 2) + std::string(9, 0) + le(7, 2) + le(5, 2) + char(24) + char(0x20);
    std::string px;  // BGR, top row first (descriptor 0x20)
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 7; ++x) {
            unsigned char rgb[3];
            patternAt(x, y, rgb);
            px += std::string{char(rgb[2]), char(rgb[1]), char(rgb[0])};
        }
    if (!rle) return s + px;
    // Raw packets of 4 pixels, except a run packet for pixels 32..34 when they are equal.
    for (int i = 0; i < 35;) {
        if (i == 32 && px.substr(96, 3) == px.substr(99, 3) && px.substr(99, 3) == px.substr(102, 3)) {
            s += char(0x80 | 2) + px.substr(96, 3);
            i += 3;
            continue;
        }
        const int n = std::min(4, 35 - i);
        s += char(n - 1) + px.substr(size_t(i) * 3, size_t(n) * 3);
        i += n;
    }
    return s;
}

std::string bmp() {
    const int stride = 24;  // 7 * 3 bytes padded to 4
    std::string s = "BM" + le(54 + stride * 5, 4) + le(0, 4) + le(54, 4) + le(40, 4) + le(7, 4) + le(5, 4) + le(1, 2) + le(24, 2) +
                    le(0, 4) + le(stride * 5, 4) + le(2835, 4) + le(2835, 4) + le(0, 4) + le(0, 4);
    for (int y = 4; y >= 0; --y) {  // bottom row first
        std::string row;
        for (int x = 0; x < 7; ++x) {
            unsigned char rgb[3];
            patternAt(x, y, rgb);
            row += std::string{char(rgb[2]), char(rgb[1]), char(rgb[0])};
        }
        s += row + std::string(stride - row.size(), 0);
    }
    return s;
}

}  // namespace

// stb_image 2.27 reads a BMP or TGA cut short as black where the bytes are missing, without a word
// (found by the png libFuzzer target once it wrote TGA files): the rows or the run-length packets
// must reach the last pixel. Whole files read exactly; every cut before the last pixel's byte is
// refused naming the file.
TEST(StbInputs, BmpAndTgaCutShortAreRefused) {
    TempDir dir;
    struct Case {
        const char* name;
        std::string bytes;
        size_t pixelStart;
    };
    const Case cases[] = {{"raw.tga", tga(false), 18}, {"rle.tga", tga(true), 18}, {"rows.bmp", bmp(), 54}};
    for (const Case& c : cases) {
        const std::string path = dir / c.name;
        std::ofstream(path, std::ios::binary) << c.bytes;
        expectPattern(atrous::readImage(path), c.name);
        // The BMP's last row has 3 bytes of padding nobody reads: cutting those is harmless.
        const size_t lastUsed = std::string(c.name) == "rows.bmp" ? c.bytes.size() - 3 : c.bytes.size();
        for (size_t keep : {c.pixelStart + 1, (c.pixelStart + lastUsed) / 2, lastUsed - 1}) {
            std::ofstream(path, std::ios::binary | std::ios::trunc) << c.bytes.substr(0, keep);
            const std::string msg = errorOf(path);
            EXPECT_NE(msg.find(path), std::string::npos) << c.name << " cut to " << keep << ": " << msg;
            EXPECT_NE(msg.find("truncated"), std::string::npos) << c.name << " cut to " << keep << ": " << msg;
        }
    }
}

// Found by a review of the checks against stb_image 2.27's loaders: a top-down BMP (negative
// height, which stb's info call reports as is) was refused though stb reads it; a paletted BMP
// whose pixel offset leaves no room for the palette stb reads (an OS/2 header, where stb counts 4
// entries fewer than the file has, or an offset of 0), or whose pixels name entries stb did not
// read, decoded from uninitialised memory; a flat .hdr whose first pixel starts 02 02 8x was
// taken for run-length data by the size check and read past the end.
TEST(StbInputs, BmpPalettesAndTopDownRowsAndFlatHdrAsStbReadsThem) {
    TempDir dir;
    auto write = [&](const std::string& name, const std::string& bytes) {
        std::ofstream(dir / name, std::ios::binary) << bytes;
        return dir / name;
    };
    auto header = [](int hsz, int w, int h, int bpp, uint32_t offset, uint32_t fileSize) {
        std::string s = "BM" + le(fileSize, 4) + le(0, 4) + le(offset, 4) + le(uint32_t(hsz), 4);
        if (hsz == 12) return s + le(uint32_t(w), 2) + le(uint32_t(h), 2) + le(1, 2) + le(uint32_t(bpp), 2);
        return s + le(uint32_t(w), 4) + le(uint32_t(h), 4) + le(1, 2) + le(uint32_t(bpp), 2) + le(0, 4) + le(0, 4) + le(2835, 4) +
               le(2835, 4) + le(0, 4) + le(0, 4);
    };
    // Top-down 2x2, 24 bits: rows red/green, then blue/white, first row on top.
    const std::string rows = std::string("\x00\x00\xff\x00\xff\x00", 6) + std::string(2, '\0') +
                             std::string("\xff\x00\x00\xff\xff\xff", 6) + std::string(2, '\0');
    const Image td = atrous::readImage(write("topdown.bmp", header(40, 2, -2, 24, 54, 70) + rows));
    ASSERT_EQ(td.height(), 2);
    EXPECT_EQ(td(0, 0, 0), 1.0f);  // red on top
    EXPECT_EQ(td(1, 0, 1), 1.0f);  // green
    EXPECT_EQ(td(0, 1, 2), 1.0f);  // blue below
    EXPECT_EQ(td(1, 1, 0), 1.0f);  // white
    // 8 bits, a 2-entry palette (black, white): indices 0 and 1 read; an index of 5 is refused.
    const std::string pal = std::string(4, '\0') + std::string("\xff\xff\xff\x00", 4);
    const Image ok = atrous::readImage(write("pal2.bmp", header(40, 4, 1, 8, 62, 66) + pal + std::string("\x00\x01\x01\x00", 4)));
    EXPECT_EQ(ok(1, 0, 0), 1.0f);
    EXPECT_EQ(ok(0, 0, 0), 0.0f);
    const std::string bad = write("pal2_index5.bmp", header(40, 4, 1, 8, 62, 66) + pal + std::string("\x00\x05\x01\x00", 4));
    EXPECT_NE(errorOf(bad).find("names colour 5 of a 2-colour palette"), std::string::npos) << errorOf(bad);
    // An offset of 0: no palette as stb counts it.
    const std::string zero = write("offset0.bmp", header(40, 4, 1, 8, 0, 58) + std::string("\x01\x01\x01\x01", 4));
    EXPECT_NE(errorOf(zero).find("leave no room for the palette"), std::string::npos) << errorOf(zero);
    // OS/2 1-bit with its 2-entry palette at offset 32: stb counts (32 - 38) / 3 entries.
    const std::string os2 = write("os2.bmp", header(12, 8, 2, 1, 32, 40) + std::string("\x00\x00\xff\xff\xff\xff", 6) +
                                                 std::string("\xf0\x00\x00\x00\x0f\x00\x00\x00", 8));
    EXPECT_NE(errorOf(os2).find("leave no room for the palette"), std::string::npos) << errorOf(os2);
    // A flat .hdr (8x2) cut after its first two pixels, the first starting 02 02 80.
    const std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 8\n";
    const std::string cut = write("flat_cut.hdr", hdr + std::string("\x02\x02\x80\x80\x80\x40\x20\x81", 8));
    EXPECT_NE(errorOf(cut).find("truncated HDR"), std::string::npos) << errorOf(cut);
}

#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <cmath>
#include <fstream>
#include <vector>

#include "atrous/error.h"
#include "atrous/io/image_io.h"
#include "test_util.h"

using namespace atrous;
using atrous::test::TempDir;

static Image ramp(int w, int h) { return test::rampImage(w, h, 0.1f, 10.0f, 100.0f); }

static void expectSame(const Image& a, const Image& b) {
    ASSERT_EQ(a.width(), b.width());
    ASSERT_EQ(a.height(), b.height());
    ASSERT_EQ(a.channels(), b.channels());
    for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.data()[i], b.data()[i]) << "at " << i;
}

TEST(ImageIo, ExrRoundTripIsExact) {
    TempDir dir;
    Image img = ramp(13, 7);
    atrous::writeImage(dir / "a.exr", img);
    expectSame(img, atrous::readImage(dir / "a.exr"));
}

TEST(ImageIo, PfmRoundTripIsExactAndRowOrderIsTopDown) {
    TempDir dir;
    Image img = ramp(9, 4);
    atrous::writeImage(dir / "a.pfm", img);
    expectSame(img, atrous::readImage(dir / "a.pfm"));
    // The first pixel row stored in the file is the bottom row of the image.
    std::ifstream in(dir / "a.pfm", std::ios::binary);
    std::string magic;
    int w, h;
    float scale;
    in >> magic >> w >> h >> scale;
    in.get();
    float first;
    in.read(reinterpret_cast<char*>(&first), 4);
    EXPECT_EQ(first, img(0, 3, 0));
}

TEST(ImageIo, PngPreviewIsWritten) {
    TempDir dir;
    atrous::writeImage(dir / "a.png", ramp(8, 8));
    Image back = atrous::readImage(dir / "a.png");
    EXPECT_EQ(back.width(), 8);
    EXPECT_EQ(atrous::test::countEntries(dir.str()), 1);  // no temporary left behind
}

TEST(ImageIo, BadFilesGiveInputErrorsNamingTheFile) {
    TempDir dir;
    EXPECT_THROW(atrous::readImage(dir / "missing.exr"), InputError);
    {
        std::ofstream(dir / "garbage.exr") << "this is not an exr file";
    }
    try {
        atrous::readImage(dir / "garbage.exr");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("garbage.exr"), std::string::npos);
    }
    // A truncated EXR: the first half of a valid file.
    atrous::writeImage(dir / "full.exr", ramp(64, 64));
    std::ifstream in(dir / "full.exr", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(dir / "trunc.exr", std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() / 2));
    EXPECT_THROW(atrous::readImage(dir / "trunc.exr"), InputError);
    // A truncated PFM.
    std::ofstream(dir / "trunc.pfm", std::ios::binary) << "PF\n4 4\n-1.0\n" << std::string(10, 'x');
    EXPECT_THROW(atrous::readImage(dir / "trunc.pfm"), InputError);
    EXPECT_THROW(atrous::readImage(dir / "a.xyz"), InputError);
}

TEST(ImageIo, FailedWriteLeavesNothing) {
    TempDir dir;
    EXPECT_THROW(atrous::writeImage(dir / "nodir/a.exr", ramp(4, 4)), InputError);
    EXPECT_THROW(atrous::writeImage(dir / "a.bmp", ramp(4, 4)), InputError);
    EXPECT_EQ(atrous::test::countEntries(dir.str()), 0);
    // A parent that is a regular file is named as such, not as missing.
    { std::ofstream(dir / "afile") << "x"; }
    try {
        atrous::writeImage(dir / "afile/a.exr", ramp(4, 4));
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("is not a directory"), std::string::npos) << e.what();
    }
}

// An EXR whose channels are neither R,G,B nor Y nor a single one: rejected, naming the file and
// the channels it has; through the CLI, exit code 2 and no output.
TEST(ImageIo, ExrWithTheWrongChannelsIsRejected) {
    TempDir dir;
    const std::string path = dir / "uv.exr";
    {
        const int w = 4, h = 3;
        std::vector<float> u(w * h, 0.5f), v(w * h, 0.25f);
        Imf::Header header(w, h);
        header.channels().insert("U", Imf::Channel(Imf::FLOAT));
        header.channels().insert("V", Imf::Channel(Imf::FLOAT));
        Imf::OutputFile file(path.c_str(), header);
        Imf::FrameBuffer fb;
        fb.insert("U", Imf::Slice(Imf::FLOAT, (char*)u.data(), sizeof(float), sizeof(float) * w));
        fb.insert("V", Imf::Slice(Imf::FLOAT, (char*)v.data(), sizeof(float), sizeof(float) * w));
        file.setFrameBuffer(fb);
        file.writePixels(h);
    }
    try {
        atrous::readImage(path);
        FAIL() << "a U,V file was accepted";
    } catch (const InputError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("uv.exr"), std::string::npos) << msg;
        EXPECT_NE(msg.find("U,V"), std::string::npos) << msg;
    }
    const std::string out = dir / "out.exr";
    auto r = atrous::test::runCli("denoise --color " + path + " --method eaw --out " + out);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("uv.exr"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
}

// libFuzzer target: a layered EXR (Blender's multilayer file, Mitsuba's aov output, any multipart
// file) through the readers of `atrous denoise --in FILE.exr` and `--albedo FILE.exr`:
// io::inspectExr, io::mapPasses + io::readPasses, io::loadBuffers (BufferFiles.in = the file) and
// io::readBufferFile for one buffer (chosen by the input's size). The input is the file's bytes.
//
// Contract (fuzz_common.h): each call returns or throws InputError. inspectExr's ExrInfo is
// consistent (checkExrInfo); each pass choice is one mapPasses promises (checkPassChoice); every
// image read has 3 planes (or as few as the buffer allows), the image window's size, atrous's conventions
// (conformBuffer: checkConformed); loadBuffers' buffers all have the colour's size.
//
// Found and fixed in src/io: the image window unchecked against the file's size (423a377), an
// EXR without channels given for one buffer (37f271e: SIGSEGV), 4-channel half parts in the
// OpenEXR Core reader (7244261: SIGSEGV). Their inputs are seeds (corpus/*/finding_*.exr).
#include "fuzz_common.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "atrous/io/pass_map.h"

using namespace atrous_fuzz;
using namespace atrous::io;

namespace {

// The fewest planes a buffer may come as (3 until the rewrite of src/io under way, which reads
// depth and a material index as 1 plane, motion as 2, the ids as 2 and an object index as 1).
int planesOf(Buffer b) {
    switch (b) {
        case Buffer::Depth:
        case Buffer::MaterialId:
        case Buffer::ObjectId: return 1;
        case Buffer::Motion: return 2;
        default: return 3;
    }
}

void checkImage(Buffer b, const Image& img, const ExrInfo& info, const std::string& what) {
    checkShape(what, img, planesOf(b));
    if (img.width() != info.width || img.height() != info.height)
        finding(what + ": " + std::to_string(img.width()) + "x" + std::to_string(img.height()) + ", the file's image is " +
                std::to_string(info.width) + "x" + std::to_string(info.height));
    checkConformed(b, img, what);
}

}  // namespace

ATROUS_FUZZ_FILE_TARGET("exr_layered", "in.exr") {
    ExrInfo info;
    if (!returnsOrInputError("inspectExr", [&] { info = inspectExr(path); })) return 0;
    checkExrInfo(info, "inspectExr");
    for (const ExrLayer& l : info.layers) (void)describeLayer(info, l);

    PassMap m;
    if (returnsOrInputError("mapPasses", [&] { m = mapPasses(info, {}, ""); })) {
        std::vector<std::pair<Buffer, const PassChoice*>> wanted;
        for (int b = 0; b < kBufferCount; ++b) {
            checkPassChoice(info, Buffer(b), m.pass[size_t(b)], "mapPasses");
            if (m.pass[size_t(b)].found()) wanted.emplace_back(Buffer(b), &m.pass[size_t(b)]);
        }
        std::vector<Image> images;
        if (returnsOrInputError("readPasses", [&] { images = readPasses(info, wanted); })) {
            if (images.size() != wanted.size()) finding("readPasses: " + std::to_string(images.size()) + " images for " +
                                                        std::to_string(wanted.size()) + " passes");
            for (size_t k = 0; k < images.size(); ++k)
                checkImage(wanted[k].first, images[k], info, std::string("readPasses: ") + bufferName(wanted[k].first));
        }
    }

    BufferFiles files;
    files.in = path;
    BufferSet set;
    if (returnsOrInputError("loadBuffers", [&] { set = loadBuffers(files); })) {
        const Image& color = set.image[int(Buffer::Color)];
        if (color.empty()) finding("loadBuffers returned no colour");
        for (int b = 0; b < kBufferCount; ++b)
            if (!set.image[b].empty()) checkImage(Buffer(b), set.image[b], info, std::string("loadBuffers: ") + bufferName(Buffer(b)));
    }

    const Buffer one = Buffer(size % kBufferCount);
    Image img;
    if (returnsOrInputError("readBufferFile", [&] { img = readBufferFile(path, one, {}, ""); }))
        checkImage(one, img, info, std::string("readBufferFile: ") + bufferName(one));
    return 0;
}

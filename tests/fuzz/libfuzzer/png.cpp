// libFuzzer target: 8-bit images through atrous::readImage (PNG textures; JPEG through
// libjpeg-turbo since b765052; BMP and TGA through stb_image). A file is read only as the format its
// extension names (image_io.cpp), so the input's bytes are written under the extension its first
// bytes suggest: in.hdr for "#?", in.jpg for FF D8, in.bmp for "BM", in.png for the PNG signature,
// and otherwise in.png or in.tga by the input's size (so that the refusal of a mismatch and stb's
// TGA reader, which has no signature, are reached too).
//
// Contract (fuzz_common.h): readImage returns a 3-channel image or throws InputError. The image
// fits the file (at most 8448 pixels per byte plus 65536, docs/reliability.md); an 8-bit image's
// values are finite and in [0, 1] (sRGB decoded to linear); a Radiance image's are finite.
#include <cmath>
#include <cstring>

#include "fuzz_common.h"
#include "atrous/io/image_io.h"

using namespace atrous_fuzz;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    targetName() = "png";
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const auto starts = [&](const char* magic, size_t n) { return size >= n && std::memcmp(data, magic, n) == 0; };
    const bool hdr = starts("#?", 2);
    const char* ext = hdr                         ? ".hdr"
                      : starts("\xff\xd8", 2)      ? ".jpg"
                      : starts("BM", 2)             ? ".bmp"
                      : starts("\x89PNG", 4)        ? ".png"
                      : size % 2 == 0               ? ".png"
                                                    : ".tga";
    const std::string path = writeScratch(std::string("in") + ext, data, size);
    const std::string what = std::string("readImage(") + ext + ")";
    Image img;
    if (!returnsOrInputError(what, [&] { img = atrous::readImage(path); })) return 0;
    checkShape(what, img);
    if (double(img.width()) * img.height() > double(size) * 8448.0 + 65536.0)
        finding(what + " returned a " + std::to_string(img.width()) + "x" + std::to_string(img.height()) +
                " image from a file of " + std::to_string(size) + " bytes");
    const float* p = img.data();
    for (size_t i = 0; i < img.size(); ++i)
        if (!std::isfinite(p[i]) || (!hdr && !(p[i] >= 0.0f && p[i] <= 1.0f)))
            finding(what + ": value " + std::to_string(p[i]) + at(img, i) + (hdr ? " is not finite" : " outside [0, 1]"));
    return 0;
}

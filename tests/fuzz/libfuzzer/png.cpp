// libFuzzer target: 8-bit images through atrous::io::readImage (PNG textures; JPEG through
// libjpeg-turbo since b765052; stb_image reads BMP, TGA, GIF, PSD, PNM whatever the name says). The input is the file's bytes, written as
// in.png, or as in.hdr when it starts like a Radiance file (so that the .hdr checks run too).
//
// Contract (fuzz_common.h): readImage returns a 3-channel image or throws InputError. The image
// fits the file (at most 8448 pixels per byte plus 65536, docs/reliability.md); an 8-bit image's
// values are finite and in [0, 1] (sRGB decoded to linear); a Radiance image's are finite.
#include <cmath>
#include <cstring>

#include "fuzz_common.h"
#include "io/image_io.h"

using namespace atrous_fuzz;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    targetName() = "png";
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (skipKnownHdr(data, size)) return 0;
    const bool hdr = size >= 2 && std::memcmp(data, "#?", 2) == 0;
    const std::string path = writeScratch(hdr ? "in.hdr" : "in.png", data, size);
    const std::string what = hdr ? "readImage(.hdr)" : "readImage(.png)";
    Image img;
    if (!returnsOrInputError(what, [&] { img = atrous::io::readImage(path); })) return 0;
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

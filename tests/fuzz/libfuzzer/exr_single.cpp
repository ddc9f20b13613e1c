// libFuzzer target: a single EXR file through atrous::readImage (the reader of --color FILE.exr,
// textures and environment maps). The input is the file's bytes.
//
// Contract (fuzz_common.h): readImage returns a 3-channel image or throws InputError. Its size is
// one the file can hold: at most 8192 bytes of decoded pixels per file byte (PIZ/DWA's ratio, the
// most the reader allows, docs/reliability.md) plus 64 KiB, at 2 bytes (one half channel) per
// pixel. NaN/Inf pixels are allowed (colour: the filters repair them).
#include "fuzz_common.h"
#include "atrous/io/image_io.h"

using namespace atrous_fuzz;

ATROUS_FUZZ_FILE_TARGET("exr_single", "in.exr") {
    Image img;
    if (!returnsOrInputError("readImage(.exr)", [&] { img = atrous::readImage(path); })) return 0;
    checkShape("readImage(.exr)", img);
    if (double(img.width()) * img.height() * 2.0 > double(size) * 8192.0 + 65536.0)
        finding("readImage(.exr) returned a " + std::to_string(img.width()) + "x" + std::to_string(img.height()) +
                " image from a file of " + std::to_string(size) + " bytes");
    return 0;
}

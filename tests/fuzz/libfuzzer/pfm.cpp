// libFuzzer target: a PFM file through atrous::readImage (oidnDenoise's format: --hdr, --alb,
// --nrm). The input is the file's bytes.
//
// Contract (fuzz_common.h): readImage returns a 3-channel image or throws InputError, and the image
// is one the file holds: width x height x (3 for "PF", 1 for "Pf") floats after the header. NaN/Inf
// pixels are allowed (the format can store them).
#include <cstring>

#include "fuzz_common.h"
#include "atrous/io/image_io.h"

using namespace atrous_fuzz;

ATROUS_FUZZ_FILE_TARGET("pfm", "in.pfm") {
    Image img;
    if (!returnsOrInputError("readImage(.pfm)", [&] { img = atrous::readImage(path); })) return 0;
    checkShape("readImage(.pfm)", img);
    size_t m = 0;  // the magic after any leading whitespace (the reader reads it with >>)
    while (m < size && std::strchr(" \t\n\v\f\r", data[m]) && data[m]) ++m;
    const bool grey = size >= m + 2 && std::memcmp(data + m, "Pf", 2) == 0;
    const double need = double(img.width()) * img.height() * (grey ? 1 : 3) * 4.0;
    if (size < m + 2 || (std::memcmp(data + m, "PF", 2) != 0 && !grey) || need > double(size - m))
        finding("readImage(.pfm) returned a " + std::to_string(img.width()) + "x" + std::to_string(img.height()) +
                " image from a file of " + std::to_string(size) + " bytes");
    return 0;
}

// What `atrous denoise` does around the filter for a still beyond its buffers (issue 49): an LDR
// colour (an 8-bit PNG/JPEG, or oidnDenoise's --ldr) is denoised as LDR, the colour's alpha is passed
// through to the output unchanged, and a colour with no finite pixel is refused.
#pragma once
#include <string>

#include "atrous/image.h"
#include "atrous/io/buffer_set.h"

namespace atrous::cli {

struct StillExtras {
    std::string colorFile;  // where the colour came from (the file, a folder's colour file, the layered file)
    bool ldrFile = false;   // an 8- or 16-bit format (io::isLdrFormat): read through the sRGB curve into [0, 1]
    bool ldr = false;       // denoised as LDR: ldrFile, or --ldr
    Image alpha;            // the colour's alpha (io::readAlpha); empty when it has none
};

// Reads what goes with the colour of `set` (loaded from `files`) and checks it, before anything is
// denoised or written: InputError naming the colour's file for a colour with no finite pixel, and
// for an LDR colour given with a variance buffer (a variance of display-encoded values is not the
// variance of the pixel mean the filters take).
StillExtras readStillExtras(const io::BufferFiles& files, const io::BufferSet& set, bool ldrFlag);

// The output as it is written: an LDR input's output clamped to [0, 1]; with --srgb (LDR), encoded
// by the sRGB curve unless the file is a PNG (writePng encodes); the alpha added as a 4th channel
// (not for PFM, which has none: *dropped says so).
Image stillOutput(Image out, const StillExtras& e, bool srgb, const std::string& outPath, bool* dropped);

// The lines `denoise` prints about them ("" when there is nothing to say), each ending in '\n'.
std::string stillExtrasLines(const StillExtras& e, const std::string& outPath, bool alphaDropped);

}  // namespace atrous::cli

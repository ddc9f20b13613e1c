// LDR input, alpha and an all-non-finite colour for `atrous denoise` on a still (still_output.h;
// docs/inputs.md "LDR input" and "Alpha", docs/decisions.md "LDR input").
#include "still_output.h"

#include <algorithm>
#include <utility>

#include "atrous/error.h"
#include "atrous/io/alpha.h"
#include "atrous/io/image_io.h"
#include "atrous/srgb.h"

namespace atrous::cli {

StillExtras readStillExtras(const io::BufferFiles& files, const io::BufferSet& set, bool ldrFlag) {
    StillExtras e;
    const Image& color = set.image[int(io::Buffer::Color)];
    e.alpha = io::readAlpha(files, color.width(), color.height(), &e.colorFile);
    const std::string& colorArg = files.file[int(io::Buffer::Color)];
    e.ldrFile = !colorArg.empty() && io::isLdrFormat(colorArg);
    e.ldr = e.ldrFile || ldrFlag;
    io::requireFinitePixel(color, e.colorFile);
    if (e.ldr && set.get(io::Buffer::Variance))
        throw InputError(e.colorFile + ": an LDR colour (" + (e.ldrFile ? "an 8-bit, display-encoded image" : "--ldr") +
                         ") with a variance buffer (" + set.from[int(io::Buffer::Variance)] +
                         "): the variance of display-encoded values is not the variance of the pixel mean atrous "
                         "filters with; give the HDR colour (EXR, PFM) with it, or drop the variance");
    return e;
}

Image stillOutput(Image out, const StillExtras& e, bool srgb, const std::string& outPath, bool* dropped) {
    const size_t n = out.plane() * size_t(out.channels());
    if (e.ldr)
        for (size_t i = 0; i < n; ++i) out.data()[i] = std::min(std::max(out.data()[i], 0.0f), 1.0f);
    if (srgb && io::extensionOf(outPath) != ".png")
        for (size_t i = 0; i < n; ++i) out.data()[i] = srgbEncode(out.data()[i]);
    *dropped = !e.alpha.empty() && io::extensionOf(outPath) == ".pfm";
    if (e.alpha.empty() || *dropped) return out;
    return io::withAlpha(std::move(out), e.alpha);
}

std::string stillExtrasLines(const StillExtras& e, const std::string& outPath, bool alphaDropped) {
    std::string s;
    if (e.ldrFile)
        s += "denoise: LDR input: " + e.colorFile + " is an 8-bit, display-encoded image: denoised as LDR (sRGB-decoded to "
             "[0, 1], output clamped to [0, 1]" + (io::extensionOf(outPath) == ".png" ? ", written sRGB-encoded" : ", written linear") + ")\n";
    else if (e.ldr)
        s += "denoise: LDR input (--ldr): output clamped to [0, 1]\n";
    if (alphaDropped)
        s += "denoise: note: " + e.colorFile + " has an alpha channel and PFM has none: the alpha is not written (write .exr or .png to keep it)\n";
    else if (!e.alpha.empty())
        s += "denoise: alpha of " + e.colorFile + " passed through unchanged\n";
    return s;
}

}  // namespace atrous::cli

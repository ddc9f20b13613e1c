// How the frames of `atrous denoise --sequence IN --out OUT` are named (docs/inputs.md,
// "Sequences"): OUT a folder, each output keeping its input's name (render0001.exr ->
// OUT/render0001.exr; a frame folder frame_0001/ or LuxCore's 0001/ -> OUT/frame_0001.exr,
// OUT/0001.exr; color_0001.exr -> OUT/color_0001.exr), or OUT a pattern DIR/NAME####.exr (the
// frame number zero-padded to the count of #'s) or DIR/NAME%04d.exr. The PNG previews take the
// same names with .png.
#pragma once
#include <string>

namespace atrous::io {

struct SequenceOutputNames {
    std::string dir;              // the output folder (the pattern's folder, "." without one)
    bool pattern = false;         // named by the pattern below, else by the inputs
    std::string prefix, suffix;   // the pattern's name around its number ("render", ".exr")
    int width = 0;                // the number's zero-padded width (0: as is, %d)

    // The output's name without its extension for a frame (its file or folder, its number):
    // "render0001".
    std::string stem(const std::string& frame, int index) const;
};

// Parses --out: a pattern when its last component has a '#' or a '%', else a folder. InputError
// naming `flag` and the problem (one line) for a bad pattern: two groups of #'s, a '%' that is not
// %d / %0Nd, both kinds, an extension other than .exr, or an image file name with neither (a
// sequence's --out is a folder or a pattern).
SequenceOutputNames parseSequenceOutput(const std::string& flag, const std::string& out);

// The name an output keeps from its input frame: a file's name without .exr, a folder's name.
std::string sequenceInputStem(const std::string& frame);

}  // namespace atrous::io

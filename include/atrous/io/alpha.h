// Alpha passed through (docs/inputs.md, "Alpha"): a colour's alpha channel is not denoised; it is read
// from where the colour came from and written beside the denoised colour unchanged (the same float
// values: an EXR's A comes back bit for bit, a PNG's codes too). The still path (`atrous denoise`),
// Python and the sequence session read it with these functions and write it as the 4th channel of
// writeImage (image_io.h).
#pragma once
#include <string>
#include <vector>

#include "atrous/image.h"
#include "atrous/io/pass_map.h"

namespace atrous::io {

struct BufferFiles;
struct SequenceFrame;
struct SequenceOptions;

// The alpha channel that goes with the colour of `path`, as a 1-channel host image; empty when it has
// none:
// - an EXR: the A channel of the layer the colour is read from (a plain file's root R,G,B,A; a
//   layered file's colour pass as mapPasses picks it with `passes` and `viewLayer`: Blender's
//   "ViewLayer.Combined.A", Mitsuba's root A);
// - a PNG, BMP or TGA: its alpha (grey + alpha, RGBA), code / 255;
// - PFM, JPEG and Radiance .hdr have none.
// Throws InputError naming the file when the alpha channel is not the colour's size (a subsampled A;
// width, height: the colour's, -1 = not checked) or cannot be read.
Image readAlpha(const std::string& path, const std::vector<PassRequest>& passes = {}, const std::string& viewLayer = {},
                int width = -1, int height = -1);

// The same for the colour of one still's inputs, as loadBuffers reads them: the colour file, else a
// render folder's colour file, else the layered file's colour pass. The file it came from in *from.
Image readAlpha(const BufferFiles& files, int width, int height, std::string* from = nullptr);

// The same for one frame of a sequence (loadSequenceFrame's), with the sequence's --pass/--layer: for
// the sequence session, which writes withAlpha(denoised, alpha) for every frame that has one.
Image readFrameAlpha(const SequenceFrame& frame, const SequenceOptions& options);

// `rgb` (3 channels) with `alpha` (1 channel, the same size) as a 4-channel host image for writeImage;
// `rgb` itself when alpha is empty. Throws InputError when the sizes differ.
Image withAlpha(Image rgb, const Image& alpha);

}  // namespace atrous::io

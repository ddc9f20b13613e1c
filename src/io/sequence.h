// Frame sequences for the temporal denoiser (SVGF) and per-frame denoising of animations.
//
// Layout: a sequence directory holds frame_0000/, frame_0001/, ... (four or more digits, numbered
// without gaps from the first one present), each with
//   color.exr albedo.exr normal.exr position.exr depth.exr ids.exr motion.exr   (required)
//   reference.exr emission.exr variance.exr                                     (optional)
// as the renderer writes them (ALGORITHMS.md §1: depth in R (1e30 = background), ids R = mesh id
// (-1 = background), motion R = dx, G = dy in pixels, previous - current). Other entries are ignored.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "atrous/image.h"

namespace atrous::io {

// The buffers every frame must have, in the order they are checked.
extern const char* const kSequenceBuffers[7];

struct SequenceFrame {
    int index = 0;
    std::string dir;
    Image color, albedo, normal, position, depth, ids, motion;  // 3-channel host images
    Image reference;  // empty when reference.exr is absent
    Image emission;   // empty when emission.exr is absent
    Image variance;   // empty when variance.exr is absent (per-frame EAW/SURE use it when given)
};

// The frame directories of `dir`, sorted by number. Throws InputError when `dir` is not a
// readable directory, holds no frame_NNNN directory, or the numbering has a gap (the message
// names the first missing frame).
std::vector<std::string> listSequenceFrames(const std::string& dir);

// Checks every frame without decoding pixels: each required buffer exists and every buffer of
// every frame (optional ones included) has the first frame's size, read from the EXR headers.
// Throws InputError naming the missing file, or both files whose sizes differ. Returns the size.
void validateSequence(const std::vector<std::string>& frameDirs, int& width, int& height);

// Loads one frame directory. Throws InputError naming the file when a required buffer is missing
// or unreadable, or naming both files when two buffers differ in size.
SequenceFrame loadSequenceFrame(const std::string& frameDir);

// "frame_0007" for 7 (at least four digits).
std::string sequenceFrameName(int index);

// The number of a "frame_NNNN" name (four to eight digits), or -1 when `name` is not one.
int parseSequenceFrameName(const std::string& name);

// Removes the entries of `dir` named frame_NNNN + `suffix` ("" for the frame directories of
// `atrous render --frames`, ".exr"/".png" for the files of `atrous denoise --sequence`) for which
// keep(NNNN) is false; directories are removed with their contents. Returns the removed names,
// sorted. Throws RuntimeError naming the entry when one cannot be removed.
std::vector<std::string> removeSequenceEntries(const std::string& dir, const std::string& suffix,
                                               const std::function<bool(int)>& keep);

}  // namespace atrous::io

// Frame sequences for the temporal denoiser (SVGF) and per-frame denoising of animations
// (docs/inputs.md, "Sequences").
//
// Four layouts:
// - atrous's: frame_0000/, frame_0001/, ... (four or more digits, numbered without gaps from the
//   first one present), each with color.exr and any of albedo.exr normal.exr position.exr
//   depth.exr ids.exr motion.exr emission.exr variance.exr reference.exr, as `atrous render
//   --frames` writes them (depth in R, 1e30 = background; ids R = mesh id, -1 = background;
//   motion R = dx, G = dy in pixels, previous - current, y down).
// - numbered frame folders with another prefix (0001/, frame0001/ ...: one prefix, the number
//   last) holding a colour file: each read as `--in DIR` reads a folder, so atrous's names or
//   another renderer's (LuxCore's RGB.exr, ALBEDO.exr, AVG_SHADING_NORMAL.exr ...: dirBufferFile,
//   buffer_set.h).
// - numbered files per buffer in one folder: color_0001.exr, albedo_0001.exr, ... (a buffer's
//   name as above without ".exr", then '_', '.' or '-', then the number); a frame per colour file,
//   named by it.
// - other renderers': numbered layered EXR files (Blender's render0001.exr, ..., Mitsuba's aov
//   output 0000.exr, ...: one common prefix, the number last), each read as `atrous denoise --in
//   FILE.exr` reads it; motion from the file's motion pass (Blender's Vector: see buffer_set.cpp)
//   or from a companion <stem>_motion.exr.
// A buffer must be in every frame or in none. Other entries are ignored.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "atrous/image.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/pass_map.h"

namespace atrous::io {

// The buffers of a frame directory, in the order they are checked (color first: required).
extern const char* const kSequenceBuffers[10];

// How layered frames are read: `--pass` and `--layer`, applied to every frame as `denoise --in
// FILE.exr` applies them (a frame_NNNN-folder sequence refuses both: its files are plain EXRs).
struct SequenceOptions {
    std::vector<PassRequest> passes;
    std::string viewLayer;
};

struct SequenceFrame {
    int index = 0;
    std::string dir;  // the frame directory or layered file
    // Host images as the filters read them (depth 1 plane, ids and motion 2, the rest 3); empty
    // when the frame has no such buffer.
    Image color, albedo, normal, position, depth, ids, motion, reference, emission, variance;
    // The file each buffer came from, by kSequenceBuffers' order ("" when absent), for messages.
    std::string files[10];
    std::shared_ptr<ExrInfo> layered;  // the frame's layered file (`--add-pass` copies it); else null
    // The file `buffer` (a name of kSequenceBuffers, or the library's "ids") came from, else the frame.
    std::string fileOf(const std::string& buffer) const;
};

// The frames of `dir` (frame directories or numbered layered files), sorted by number. Throws
// InputError when `dir` is not a readable directory, holds no frame, or the numbering has a gap
// (the message names the first missing frame).
// `dir` may also be a pattern as compositors write one (DIR/render####.exr, DIR/render%04d.exr):
// the files it matches, each a frame read as `--in FILE.exr` reads it. `range` picks the frames
// from `start` to `end` (inclusive; -1: the first / the last present) every `step`-th; a frame of
// that selection that is missing is an InputError naming it.
struct FrameRange {
    int start = -1, end = -1, step = 1;
};
std::vector<std::string> listSequenceFrames(const std::string& dir, const FrameRange& range = {});
// Whether a --sequence argument is a frame pattern (DIR/render####.exr, DIR/render%04d.exr; not an
// existing directory), and the folder it names: the directory, or the pattern's ("." without one).
bool isSequencePattern(const std::string& dirOrPattern);
std::string sequenceFolder(const std::string& dirOrPattern);

// Checks every frame without decoding pixels: each has a colour, every buffer is in every frame or
// in none (a layered frame's passes as mapPasses finds them, its motion companion too), every
// buffer of every frame has the first frame's size and fits its file (exr_limits.h, from the EXR
// headers), and --pass/--layer apply. Throws InputError naming the frame's file and the problem (or
// both files whose sizes differ). Returns the size and the buffers present (names of kSequenceBuffers).
std::vector<std::string> validateSequence(const std::vector<std::string>& frames, int& width, int& height,
                                         const SequenceOptions& options = {});

// Loads one frame. Throws InputError naming the file when a buffer is unreadable, when one of
// `expected` (validateSequence's list; empty: no check) is missing, or naming both files when two
// buffers differ in size.
SequenceFrame loadSequenceFrame(const std::string& frame, const std::vector<std::string>& expected = {},
                                const SequenceOptions& options = {});

// Whether a frame of listSequenceFrames is a layered EXR file (else a folder or per-buffer files of
// plain EXRs: `--pass`, `--layer` and `--add-pass` do not apply).
bool isLayeredSequenceFrame(const std::string& frame);

// "frame_0007" for 7 (at least four digits).
std::string sequenceFrameName(int index);

// The number of a "frame_NNNN" name (four to eight digits), or -1 when `name` is not one.
int parseSequenceFrameName(const std::string& name);
// The number at the end of a frame folder's name ("0012" or "frame12" -> 12, at most eight digits),
// and its prefix; -1 when the name does not end in a digit.
int parseFolderFrameName(const std::string& name, std::string* prefix = nullptr);
// The number at the end of a layered frame file's stem ("render0012.exr" -> 12, at least one
// digit), and its prefix; -1 for companions (<stem>_motion.exr, <stem>_reference.exr) and others.
int parseLayeredFrameName(const std::string& fileName, std::string* prefix = nullptr);

// Removes the entries of `dir` named frame_NNNN + `suffix` ("" for the frame directories of
// `atrous render --frames`, ".exr"/".png" for the files of `atrous denoise --sequence`) for which
// keep(NNNN) is false; directories are removed with their contents. Returns the removed names,
// sorted. Throws RuntimeError naming the entry when one cannot be removed.
std::vector<std::string> removeSequenceEntries(const std::string& dir, const std::string& suffix,
                                               const std::function<bool(int)>& keep);

}  // namespace atrous::io

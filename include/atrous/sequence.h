// Denoising an animation from its files to files (docs/temporal.md, docs/inputs.md "Sequences"):
// the session `atrous denoise --sequence`, Python's atrous.denoise_sequence and the Blender add-on
// run. It reads any layout src/io/sequence.h lists (atrous's frame_NNNN folders, one folder per
// frame with a renderer's own file names such as LuxCore's, numbered files per buffer, numbered
// layered EXRs such as Blender's renderNNNN.exr, or a pattern render####.exr / render%04d.exr),
// checks every frame's headers before anything is written, denoises each frame through its
// method's SequenceDenoiser (atrous/sequence_methods.h: temporal with the frames around it, svgf
// with its history; a still method on its own), and moves the
// output frames (+ .png previews, + preview.mp4 through ffmpeg when it is on PATH) into place only
// when every frame is done. The outputs keep their input's names (render0001.exr ->
// OUT/render0001.exr, a frame folder frame_0001/ -> OUT/frame_0001.exr), or follow a pattern
// OUT = DIR/clean####.exr (atrous/io/sequence_output.h). Bad input throws InputError naming the frame's file.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/device.h"
#include "atrous/param_set.h"

namespace atrous {

struct SequenceDenoiseOptions {
    // A sequence method (sequenceMethods(), atrous/sequence_methods.h: temporal, svgf, a
    // registered one) or a still method (denoiseMethods(), each frame on its own; auto is resolved
    // per frame by the buffers it has). "" = the first sequence method (temporal).
    std::string method;
    Device device = Device::Cpu;
    // The still method's options (its method field is overwritten by `method` for a still method;
    // with a sequence method that ends with a still method it is that one, the CLI's --spatial).
    // Their weights serve a sequence method whose parameters read the learned weights too.
    DenoiseOptions frame;
    // The sequence method's parameters: a set of its row's table (SequenceMethodInfo::params);
    // empty = the row's defaults.
    ParamSet params;
    // Layered frames: "BUFFER=NAME" requests (the CLI's --pass) and the view layer (--layer),
    // applied to every frame; a sequence of plain EXR folders refuses both.
    std::vector<std::string> passes;
    std::string viewLayer;
    // Each output frame a copy of its layered input frame with this pass added (--add-pass).
    std::string addPass;
    // The frames start .. end (inclusive; -1 = the first / the last present), every step-th.
    int start = -1, end = -1, step = 1;
    float exposure = 1.0f;  // of the PNG previews
    bool pngs = true;       // OUT/NAME.png beside each EXR
    bool preview = true;    // OUTDIR/preview.mp4 through ffmpeg when it is on PATH (needs pngs)
};

// One denoised frame, as it is done.
struct SequenceFrameReport {
    int index = 0;          // the frame's number in the input
    int position = 0, count = 0;  // this is the position-th frame (1-based) of the run's count (k/N counters)
    std::string input;      // the frame's file or folder
    std::string output;     // OUT/NAME.exr (where it will be once the run is done; NAME: the input's, or the pattern's)
    std::string method;     // the method and its SequenceOutput::detail: "temporal (+-3 frames, 3.8 averaged per pixel in 6 ms; then auto -> blend)"
    std::string methodUsed; // the still method that ran (blend, sure, ...), else the sequence method's name
    double milliseconds = 0;
    double reprojected = -1;  // fraction of the frame that reprojects onto the previous one (-1: not tested)
    bool hasReference = false;  // the frame has a reference.exr: then the MSEs below
    double mse = 0, mseInput = 0;
    std::string line;       // the line `atrous denoise --sequence` prints for it
};

struct SequenceReport {
    int width = 0, height = 0;
    std::vector<std::string> buffers;  // the buffers every frame has (color, albedo, ...)
    std::vector<SequenceFrameReport> frames;
    double filterMsPerFrame = 0, wallMsPerFrame = 0;
    std::string preview;               // OUTDIR/preview.mp4 when written, else ""
    std::vector<std::string> notes;    // what the run noticed (motion, ids, sign conventions, ffmpeg)
};

// Called as the run goes (a CLI's progress lines): each frame when it is denoised, each note when
// it is made, and `warning` for what the run did beside its own files (the frame files of an
// earlier run it removed from the output folder: the CLI's stderr). Any may be empty.
struct SequenceEvents {
    std::function<void(const SequenceFrameReport&)> frame;
    std::function<void(const std::string&)> note;
    std::function<void(const std::string&)> warning;
};

// Denoises every frame of `input` (a folder or a frame pattern) into `out`: a folder (created; an
// existing one keeps its other files, this run's files replace those of the same name and an
// earlier run's frame_NNNN.exr/.png that this run does not write are removed), the frames keeping
// their input's names, or a pattern DIR/NAME####.exr / DIR/NAME%04d.exr. Throws InputError for bad
// input or options (a bad pattern, an output folder that is the input's or inside it: nothing
// reaches the output then) and RuntimeError when the output cannot be moved into place.
SequenceReport denoiseSequence(const std::string& input, const std::string& out,
                               const SequenceDenoiseOptions& options, const SequenceEvents& events = {});

}  // namespace atrous

// `atrous denoise --method temporal|svgf|eaw|sure|learned|blend|auto --sequence DIR --out OUTDIR`:
// denoises every frame of a sequence directory (layout in src/io/sequence.h and docs/svgf.md).
// temporal (the default with --sequence): the frames t-K..t+K averaged onto t, then a still method
// (atrous/temporal.h, docs/temporal.md). SVGF carries its history from frame to frame; the still
// methods denoise each frame on its own through atrous::denoise() (auto: resolved per frame, by
// the buffers the frame has).
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "atrous/denoise.h"
#include "atrous/device.h"
#include "atrous/learned.h"
#include "atrous/svgf.h"
#include "atrous/temporal.h"
#include "io/sequence.h"

namespace atrous::cli {

struct SequenceDenoiseArgs {
    std::string method = "temporal";  // temporal | svgf | a still method (denoiseMethods())
    std::string sequenceDir;
    std::string outDir;
    Device device = Device::Cpu;
    SvgfParams svgf;              // used by --method svgf
    // The still methods' options (method and device are set from the fields above); with temporal,
    // frameOptions.method is the still method run on the average (--spatial).
    DenoiseOptions frameOptions;
    TemporalParams temporal;      // used by --method temporal
    LearnedWeights svgfLearnedWeights;  // svgf.learnedSpatial's (--learned-weights); empty = the built-in ones
    io::SequenceOptions layers;   // --pass and --layer, applied to every layered frame
    std::string addPass;          // --add-pass: each output frame a copy of its layered frame with this pass
    io::FrameRange range;         // --start, --end, --step
    float exposure = 1.0f;        // of the PNG previews
    bool preview = true;          // animated OUTDIR/preview.mp4 through ffmpeg when it is on PATH
    bool quiet = false;           // no per-frame lines on stdout
};

// Checks the whole sequence first (every frame and buffer present, one size: nothing is written
// otherwise), then writes OUTDIR/frame_NNNN.exr (linear HDR) and frame_NNNN.png (preview) per
// input frame, and OUTDIR/preview.mp4 when ffmpeg is available (if not, it says so and skips).
// Prints one line per frame (time, and MSE against reference.exr when the frame has one).
// Throws InputError for bad input (the CLI turns it into exit code 2). Returns 0.
int runSequenceDenoise(const SequenceDenoiseArgs& args);

// Registers one flag per row of svgfParams() (params.h) on `cmd`: --svgf-<name> (--svgf-sigma-l,
// --svgf-alpha, ...; --svgf-depth-tolerance, --svgf-normal-cos, --taa and --taa-alpha keep their
// spellings), writing into `params`; the defaults shown are the struct's. Ranges are checked later
// (checkParamFlags, or validateSvgfParams: a ParamError naming the field).
void addSvgfOptions(CLI::App& cmd, SvgfParams& params);
// The same for temporalParams(): --temporal-radius, --temporal-color-sigmas, ...
void addTemporalOptions(CLI::App& cmd, TemporalParams& params);

// Full path of an executable named `name` on PATH, or "" when there is none.
std::string findOnPath(const std::string& name);
// `s` single-quoted for std::system's shell (ffmpeg's command lines).
std::string shellQuote(const std::string& s);

}  // namespace atrous::cli

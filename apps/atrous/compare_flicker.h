// `atrous compare --sequence` without a reference (issue 49): the reference-free flicker measure
// (metrics.h, computeFlicker) of each sequence, the frames placed by the motion vectors, depth,
// normals and ids of the sequence that was denoised (--input), and a ranking by it.
#pragma once
#include <CLI/CLI.hpp>

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "atrous/image.h"
#include "atrous/metrics.h"

namespace atrous::cli {

// A sequence's frames by number: a frame's reference.exr when it has one and preferReference
// (`atrous render --frames --reference-spp`), else its colour (frame_NNNN.exr as `denoise
// --sequence` writes them, or any layout --sequence reads).
using SequenceImages = std::vector<std::pair<int, Image>>;
SequenceImages sequenceImages(const std::string& dir, bool preferReference);

// What places frame t-1 on frame t, by frame number: each frame's motion (the renderer's vectors;
// else from its Position pass, a camera fitted per frame; else estimated from its colours, as
// `denoise --sequence` does), depth, normal and ids.
class FlickerGuide {
public:
    // dir: a sequence in any layout --sequence reads. A note on how the motion was found is added
    // to *notes (for stderr) when it is not the renderer's.
    static FlickerGuide load(const std::string& dir, std::vector<std::string>* notes);
    const std::string& dir() const { return mDir; }
    bool has(int frame) const { return mFrames.count(frame) > 0; }
    // The sequence's flicker over every step t-1 -> t (computeFlicker, the steps' sums pooled: relMse
    // over every pixel that reprojects, reprojected its share). InputError naming `name` and the frame
    // when the guide lacks one of its frames or a size differs.
    FlickerMetrics measure(const SequenceImages& seq, const std::string& name) const;

private:
    struct Buffers {
        Image motion, depth, normal, ids;
    };
    std::map<int, Buffers> mFrames;
    std::string mDir;
};

struct FlickerCompareArgs {
    std::vector<std::string> sequences;  // judged, in the order given
    std::string input;                   // --input: the guide ("" = the first judged sequence)
    bool json = false;
};

// compare's --no-reference and --input.
void addFlickerOptions(CLI::App& cmd, bool& noReference, std::string& input);

// compare --sequence A [B ...] --no-reference: each sequence's flicker and share reprojected, then the
// ranking (least flicker first). Prints a table, or JSON with --json.
void runFlickerCompare(const FlickerCompareArgs& a);

}  // namespace atrous::cli

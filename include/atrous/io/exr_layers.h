// Layered EXR files as other renderers write them: Blender's multilayer EXR (one part per pass in
// Blender 5, "ViewLayer.Combined", "ViewLayer.Denoising Albedo", ...; or one part with channels
// "ViewLayer.Combined.R" in older versions), Mitsuba 3's aov integrator (one part, the image as
// R,G,B and each AOV as "name.R", "name.X", ...), and any file with several named layers.
//
// A file is flattened into channels with a full name (the part's name is put in front when the
// file has several parts and the channel's own name does not already start with it), and the
// channels are grouped into layers: the full name without its last dot-separated component
// ("ViewLayer.Combined" of "ViewLayer.Combined.R"; "" for R, G, B at the root). docs/inputs.md.
#pragma once
#include <string>
#include <vector>

#include "atrous/image.h"

namespace atrous::io {

struct ExrPartInfo {
    std::string name;  // the part's name attribute ("" when it has none)
    std::string type;  // "scanlineimage", "tiledimage", "deepscanline", ...
    int x0 = 0, y0 = 0, width = 0, height = 0;  // its data window
};

struct ExrChannelInfo {
    int part = 0;          // index into ExrInfo::parts
    std::string name;      // the channel's name inside its part
    std::string fullName;  // part-qualified name (see above)
    std::string type;      // "half", "float" or "uint"
    int xSampling = 1, ySampling = 1;
};

struct ExrLayer {
    std::string name;                     // full layer name ("" = the root layer)
    std::vector<int> channels;            // indices into ExrInfo::channels, in file order
    std::vector<std::string> components;  // their last name components ("R", "G", "B", "A", "X", ...)
    // The part before the layer's own last component ("ViewLayer" of "ViewLayer.Combined"), and
    // that component ("Combined"): the view layer and the pass name in Blender's files.
    std::string prefix() const;
    std::string passName() const;
};

struct ExrInfo {
    std::string path;
    // The image (exr_limits.h): the first part's data window clipped to its display window, in the
    // file's pixel coordinates. A pass is read from its part placed by the part's data window,
    // which must cover this window; pixels outside it are dropped.
    int x0 = 0, y0 = 0, width = 0, height = 0;
    std::vector<ExrPartInfo> parts;
    std::vector<ExrChannelInfo> channels;
    std::vector<ExrLayer> layers;  // in order of first appearance
};

// True when the file starts with the EXR magic number (whatever its extension).
bool isExrFile(const std::string& path);

// Reads the headers only. Throws InputError naming the file when it is not a readable EXR, or when
// its parts claim more pixels than the file can hold (exr_limits.h, rules 1 and 2).
ExrInfo inspectExr(const std::string& path);

// Picks `count` (1, 2 or 3) components of a layer for a buffer: R,G,B / X,Y,Z / U,V,W (either
// case; their first two for 2), otherwise the first non-alpha components in file order; a
// one-component layer is repeated.
// For 1: "Z", "V", "Y", "R" or "X" when present, else the first non-alpha component. Empty when the
// layer has no usable component (only A), or fewer than `count` but more than one.
std::vector<int> pickComponents(const ExrInfo& info, const ExrLayer& layer, int count);

// Reads the given channels (indices into info.channels, 1..3 of them, in parts whose data windows
// cover the image window) into a 3-channel host Image; one channel is repeated into all three, two
// fill R,G (B = 0). Half and uint channels are converted to float. `what` names the buffer in
// messages. A part that does not cover the image, a deep part or a subsampled channel is refused.
Image readExrChannels(const ExrInfo& info, const std::vector<int>& channels, const std::string& what);
// The same for several buffers at once: the file is opened and each part decoded once (a
// single-part file such as Mitsuba's holds every pass in the same chunks). whats[k] names set k;
// outChannels[k] (when given) is the channel count of image k (at least the set's: 1 for a
// depth, 2 for motion; 3 when absent).
std::vector<Image> readExrChannelSets(const ExrInfo& info, const std::vector<std::vector<int>>& sets,
                                      const std::vector<std::string>& whats, const std::vector<int>& outChannels = {});

// A layer to write: a full layer name ("" for the root) and a host image with at least as many
// channels as `components` names (channel i is written as component i).
struct ExrOutLayer {
    std::string name;
    const Image* image = nullptr;
    std::vector<std::string> components = {"R", "G", "B"};
};

// Writes a copy of `source` (every part and channel, at its own pixel type and compression, header
// attributes kept) with `added` appended: to a single-part file as channels "<name>.R/G/B" of the
// part, to a multipart file as new parts named "<view layer>.<name>" when the first part's name
// has a view layer, else "<name>" (channels R,G,B). Atomic (writeFileAtomically). Throws
// InputError when a name is already taken or the source has deep or differently sized parts.
void writeExrWithLayers(const std::string& outPath, const ExrInfo& source, const std::vector<ExrOutLayer>& added);

// A multilayer file from scratch (tests, tools): one part per entry when `multipart`, each part named
// after its layer with channels "<name>.R", ... (Blender 5's layout), otherwise one part with
// channels "<name>.R" ("R" for the root layer). `halfFloat` stores half channels. Atomic.
void writeLayeredExr(const std::string& path, const std::vector<ExrOutLayer>& layers, bool multipart,
                     bool halfFloat = false);

}  // namespace atrous::io

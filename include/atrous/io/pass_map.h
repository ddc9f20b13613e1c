// Which layer of a layered EXR is which denoiser buffer (docs/inputs.md). The rules are by pass
// name, case-insensitive, in tiers: the first tier with a match wins, and inside a tier the first
// name of the list that matches. Two layers matching the same name under different view layers
// (two Blender view layers, say) are ambiguous: an InputError unless a view layer is chosen.
// Explicit choices (`--pass BUFFER=NAME`) win over the rules.
#pragma once
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "atrous/buffers.h"
#include "atrous/image.h"
#include "atrous/io/exr_layers.h"

namespace atrous::io {

// The buffers and their conventions: include/atrous/buffers.h.
using atrous::Buffer;
using atrous::bufferChannels;
using atrous::bufferName;
using atrous::bufferTakesGrey;
using atrous::kBufferCount;

// The buffer of a --pass name ("color", "albedo", ..., also "ids" for object_id); InputError otherwise.
Buffer parseBufferName(const std::string& name);

struct PassRequest {
    Buffer buffer;
    std::string name;  // a layer's full name, a layer's pass name, or a full channel name
};

// "BUFFER=NAME" (e.g. "albedo=ViewLayer.Denoising Albedo"); InputError otherwise.
PassRequest parsePassRequest(const std::string& spec);
// Every --pass of a command line, the same buffer at most once (requireDistinctPasses).
std::vector<PassRequest> parsePassRequests(const std::vector<std::string>& specs);
// InputError when two requests name the same buffer (whichever path reads them).
void requireDistinctPasses(const std::vector<PassRequest>& requests);

// The channel-count rule (docs/inputs.md, "Channels"): a buffer takes bufferChannels(b) components;
// one channel is repeated into all three where a grey value means the same thing (colour,
// variance, albedo, emission; depth and ids take one), and refused for the directions and points
// (normal, position: 3; motion: 2), where (x, x, x) or (x, -x) would be a silent wrong answer
// (bufferTakesGrey).
// Throws InputError "<source> has N channels; motion needs 2 ..." when `have` components cannot be
// buffer b by that rule.
void requireComponents(Buffer b, int have, const std::string& source);

struct PassChoice {
    int layer = -1;             // index into ExrInfo::layers; -1: absent
    std::vector<int> channels;  // indices into ExrInfo::channels
    std::string rule;           // how it was chosen ("pass name 'Denoising Albedo'", "--pass", ...)
    bool found() const { return !channels.empty(); }
};

struct PassMap {
    std::array<PassChoice, kBufferCount> pass;
    const PassChoice& operator[](Buffer b) const { return pass[size_t(b)]; }
};

// Maps every buffer of a layered file. `viewLayer` (may be empty) keeps only layers under that
// prefix (and root layers). Throws InputError naming the file (and the part) for an ambiguous
// match, a request that names nothing, or a layer with unusable channels.
PassMap mapPasses(const ExrInfo& info, const std::vector<PassRequest>& requests, const std::string& viewLayer);

// The pass for one buffer of a file given for that buffer alone (`--albedo file.exr`): its only
// layer when it has one, else the buffer's rules. Throws InputError when it has several layers and
// none is that buffer's, naming the file and its layers.
PassChoice passForFile(const ExrInfo& info, Buffer b, const std::vector<PassRequest>& requests,
                       const std::string& viewLayer);

// Reads a pass as an image of bufferChannels(b) planes (3 for a grey pass of a 3-component buffer:
// repeated) and brings it to atrous's conventions (conformBuffer).
Image readPass(const ExrInfo& info, const PassChoice& pass, Buffer b);
// The same for several passes, decoding the file once (readExrChannelSets).
std::vector<Image> readPasses(const ExrInfo& info, const std::vector<std::pair<Buffer, const PassChoice*>>& passes);

// atrous's conventions for a buffer read from anywhere (docs/inputs.md): normals longer than 1 normalised
// (shorter ones, means across an edge, kept; zero stays zero: background); depth <= 0, non-finite or >= 1e9 becomes the background value 1e30;
// non-finite positions, ids and motion become 0; albedo is clamped to [0, 1] (Cycles writes an
// emitter's radiance there). Colour, variance, emission are left as they are (the filters repair
// non-finite colour).
void conformBuffer(Buffer b, Image& img);

// A layer of Mitsuba 3's moment integrator's second moments ("m2_<output>": the mean of the squared
// samples of each output it writes beside): never taken as a buffer by the rules above (the file's
// variance would need its sample count, which Mitsuba does not write); a --pass may name one.
bool isSecondMomentLayer(const ExrLayer& layer);

// The file's layer names, comma-separated ("(root)" for the root layer), for messages.
std::string layerList(const ExrInfo& info);

// One line per layer for `atrous inspect`: name, components, types, part.
std::string describeLayer(const ExrInfo& info, const ExrLayer& layer);

}  // namespace atrous::io

// The learned à-trous filter (docs/learned.md): a small per-pixel network gives guide features and
// per-level bandwidths and centre weights for a 5-level à-trous cascade. CPU inference; the
// weights ship with the library (compiled in) or come from a weight file.
#pragma once
#include <memory>
#include <string>

#include "atrous/image.h"

namespace atrous {

// Parsed, checked network weights. Opaque; copyable (shared).
class LearnedWeights {
public:
    // The weights built into the library (trained by `make train`, docs/learned.md).
    static LearnedWeights builtin();
    // A weight file (python/atrous/learn/weights.py's format). Throws InputError naming `path`
    // and the problem (missing, not a weight file, other version or shape, truncated, bad checksum).
    static LearnedWeights load(const std::string& path);
    // The same from bytes; `name` is what error messages call them.
    static LearnedWeights parse(const void* data, size_t size, const std::string& name);
    struct Impl;
    std::shared_ptr<const Impl> impl;
};

// The buffers, all host images of the colour's size, 3 channels (depth: channel 0). color is
// required; the others may be invalid views (their inputs read as absent: albedo 1, normal 0,
// depth 1, variance 0, emission 0), but the network was trained with all of them.
struct LearnedInputs {
    ImageView color, variance, albedo, normal, depth, emission;
};

// The denoised colour (3 channels, host). Throws InputError for missing/mismatched buffers.
Image learnedDenoise(const LearnedInputs& in, const LearnedWeights& weights);

}  // namespace atrous

// The learned à-trous filter's weights (docs/learned.md): a small per-pixel network gives guide
// features, per-level bandwidths, centre weights and blend weights for a 5-level à-trous cascade
// on the still driver's prepared planes. The filter itself is reached through atrous::denoise
// (DenoiseMethod::Learned, include/atrous/denoise.h); the weights ship with the library (compiled
// in) or come from a weight file (version 4, or 3).
#pragma once
#include <cstddef>
#include <memory>
#include <string>

namespace atrous {

// Parsed, checked network weights. Opaque; copyable (shared).
class LearnedWeights {
public:
    // The weights built into the library (trained by `make train`, docs/learned.md).
    static LearnedWeights builtin();
    // A weight file (python/atrous/learn/weights.py's format, version 4, or 3). Throws InputError naming
    // `path` and the problem (missing, not a weight file, a retired version (1, 2) or another
    // version, another network shape, truncated, bad checksum, a non-finite weight).
    static LearnedWeights load(const std::string& path);
    // The same from bytes; `name` is what error messages call them.
    static LearnedWeights parse(const void* data, size_t size, const std::string& name);
    struct Impl;
    std::shared_ptr<const Impl> impl;
};

}  // namespace atrous

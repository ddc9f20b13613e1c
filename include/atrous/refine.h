// The refine stage's weights (docs/learned.md, "Refine"): a small U-Net that predicts a correction
// of a still method's output (DenoiseOptions::refine). The weights ship with the library (compiled
// in from src/filters/refine_default.atrf) or come from a weight file
// (python/atrous/learn/refine.py writes them).
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace atrous {

// Parsed, checked network weights. Opaque; copyable (shared). Empty = the built-in weights.
class RefineWeights {
public:
    static RefineWeights builtin();
    // A weight file. Throws InputError naming `path` and the problem (missing, not a refine weight
    // file, another version or network shape, truncated or over-long, bad checksum, a non-finite weight).
    static RefineWeights load(const std::string& path);
    // The same from bytes; `name` is what error messages call them.
    static RefineWeights parse(const void* data, size_t size, const std::string& name);
    bool empty() const { return !impl; }
    // What the file says made it: the training run's name and its optimiser steps.
    std::string run() const;
    std::uint32_t steps() const;
    struct Impl;
    std::shared_ptr<const Impl> impl;
};

}  // namespace atrous

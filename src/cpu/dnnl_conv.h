// The CPU's convolutions of the learned networks (the learned filter's context branch, the refine
// stage): a 3x3 or 1x1 convolution of channels-last tensors with bias and optional ReLU, the
// values of LearnedConv (filters/learned_context.h), through oneDNN where the build has it
// (ATROUS_ONEDNN), else through that functor. A oneDNN error is a RuntimeError "<who>: oneDNN: ...".
// accumulate: out = [relu](out + conv(in)) (oneDNN's sum post-op): a convolution of a
// concatenation as the sum of its parts' convolutions, without the concatenated copy.
#pragma once
#include "filters/learned_context.h"

namespace atrous::filters {

void learnedConvCpu(const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu,
                    const char* who, bool accumulate = false);

}  // namespace atrous::filters

// The CPU's convolutions of the learned networks (the learned filter's context branch, the refine
// stage): a 3x3 or 1x1 convolution of channels-last tensors with bias and optional ReLU, the
// values of LearnedConv (filters/learned_context.h), through oneDNN where the build has it
// (ATROUS_ONEDNN), else through that functor. A oneDNN error is a RuntimeError "<who>: oneDNN: ...".
#pragma once
#include "filters/learned_context.h"

namespace atrous::filters {

void learnedConvCpu(const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu,
                    const char* who);

}  // namespace atrous::filters

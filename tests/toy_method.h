// A toy still method (tests/toy_method.cpp): one registry row (registerDenoiseMethod) whose cascade
// is the toy edge-stop policy (tests/toy_policy.h). Linked into a program, it is in that program's
// `denoise --help`, --method choices and viewer list with no other edit (tests/toy_method_test.cpp
// links it into a copy of the CLI, atrous_toy, and into the viewer's pipeline).
#pragma once
#include "atrous/denoise.h"

namespace atrous::toy {

// Three levels (steps 1, 2, 4) of ToyStop on the prepared colour, guided by the albedo's green
// channel (σ² = 0.01) when an albedo is given, else the plain B3 à-trous.
void toyCascade(const PreparedView& planes, const DenoiseOptions& options, const ImageView& out);

// Adds the "toy" row (registerDenoiseMethod); the method's value once it is there.
void registerToy();
DenoiseMethod toyMethod();

// Adds the toy sequence method "toyseq" (tests/toy_sequence_method.cpp, registerSequenceMethod).
void registerToySequence();

}  // namespace atrous::toy

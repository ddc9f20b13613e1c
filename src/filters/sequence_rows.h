// The built-in rows of the registry of sequence methods (include/atrous/sequence_methods.h), each
// in its method's own file: temporal_method.cpp, svgf_method.cpp.
#pragma once
#include "atrous/sequence_methods.h"

namespace atrous::filters {

SequenceMethodInfo temporalMethodRow();
SequenceMethodInfo svgfMethodRow();

}  // namespace atrous::filters

// "Every parameter changes the output": the one check behind EAW's and SURE's parameter tests.
#pragma once
#include <gtest/gtest.h>

#include "atrous/denoise.h"
#include "denoise_test_util.h"

namespace atrous::test {

// Returns changed(name, mutate): denoises `s` with a copy of `base` that `mutate` edited and
// expects the output to differ from base's somewhere by more than 1e-4 (the filters are
// deterministic, so an unchanged output differs by exactly 0; 1e-4 is far above float rounding of
// outputs of order 1, so a change that only reorders arithmetic does not count).
inline auto outputChangeCheck(const SyntheticScene& s, const DenoiseOptions& base) {
    return [&s, base, ref = denoise(s.inputs(), base)](const char* name, auto mutate) {
        DenoiseOptions o = base;
        mutate(o);
        EXPECT_GT(maxAbsDiff(denoise(s.inputs(), o), ref), 1e-4) << name << " did not change the output";
    };
}

}  // namespace atrous::test

// Helpers shared by the CPU and CUDA stage-report tests (tests/stage_times_test.cpp,
// tests/cuda/stage_times_cuda_test.cu).
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "atrous/stage_time.h"

namespace atrous::test {

inline std::vector<std::string> stageNames(const std::vector<StageTime>& stages) {
    std::vector<std::string> v;
    for (const StageTime& s : stages) v.push_back(s.name);
    return v;
}

// The sum of the stage times, each checked finite and >= 0.
inline double stageSum(const std::vector<StageTime>& stages) {
    double s = 0;
    for (const StageTime& t : stages) {
        EXPECT_TRUE(std::isfinite(t.milliseconds)) << t.name;
        EXPECT_GE(t.milliseconds, 0.0) << t.name;
        s += t.milliseconds;
    }
    return s;
}

}  // namespace atrous::test

// Per-stage timings of one denoiser run (EAW/SURE in DenoiseReport, SVGF in SvgfReport), for the
// viewer's timing panel, `atrous denoise` and `atrous bench --json`.
#pragma once
#include <string>
#include <vector>

namespace atrous {

// One stage's time: wall clock on the CPU (the stage's loops are synchronous), GPU time between
// two cudaEvents on the stream on CUDA. Names are short and stable ("sanitize", "fireflies",
// "demodulate", "sigma scales", "level 0", "sure 0", ..., "remodulate"; SVGF: "demodulate",
// "reproject", "accumulate", "variance", "level 0", ..., "remodulate", "taa").
struct StageTime {
    std::string name;
    double milliseconds = 0;
};

}  // namespace atrous

// The per-stage reports on CUDA (cudaEvents on the stream, src/cuda/cuda_stage_clock.cu): the same
// stage list as the CPU path, GPU times that are finite, >= 0 and add up. Skipped without a GPU.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/device.h"
#include "atrous/svgf.h"
#include "../denoise_test_util.h"
#include "../stage_times_test_util.h"

using namespace atrous;

TEST(StageTimesCuda, DenoiseStagesMatchTheCpuListAndFitInTheTotal) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    const test::SyntheticScene scene = test::makeScene(96, 80, 0.4f, 5);
    for (auto m : {DenoiseMethod::Eaw, DenoiseMethod::Sure, DenoiseMethod::Learned}) {
        DenoiseOptions o;
        o.method = m;
        DenoiseReport cpu, gpu;
        test::denoiseReporting(scene.inputs(), o, cpu);
        o.device = Device::Cuda;
        test::denoiseReporting(scene.inputs(), o, gpu);
        EXPECT_EQ(test::stageNames(gpu.stages), test::stageNames(cpu.stages)) << denoiseMethodName(m);
        // GPU time between the first and last event lies inside the host's wall-clock window
        // around the driver (which also waits for the final synchronisation); 0.01 ms of slack for
        // the two clocks' different resolutions.
        EXPECT_LE(test::stageSum(gpu.stages), gpu.milliseconds + 0.01) << denoiseMethodName(m);
    }
}

TEST(StageTimesCuda, SvgfReportOnTheGpu) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    const test::SyntheticScene scene = test::makeScene(64, 48, 0.4f, 6);
    SvgfParams p;
    p.levels = 3;
    SvgfDenoiser d(p, Device::Cuda);
    d.setTiming(true);
    Frame f;
    f.color = &scene.noisy;
    f.albedo = &scene.albedo;
    f.normal = &scene.normal;
    f.depth = &scene.depth;
    for (int i = 0; i < 2; ++i) d.denoiseFrameOnDevice(f);
    const SvgfReport rep = d.lastReport();
    const std::vector<std::string> expected = {"demodulate", "reproject", "accumulate", "variance",
                                               "level 0",    "level 1",   "level 2",    "remodulate", "safety net"};
    EXPECT_EQ(test::stageNames(rep.stages), expected);
    // milliseconds sums the same float event intervals in double: equal up to rounding.
    EXPECT_NEAR(rep.milliseconds, test::stageSum(rep.stages), 1e-6);
    EXPECT_GT(rep.milliseconds, 0.0);
}

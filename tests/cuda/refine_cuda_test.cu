// The refine stage on the GPU (src/cuda/refine.cu: the functors of filters/refine.h through
// CudaExec) against the CPU's functor path and its oneDNN path, and through denoise() with
// device cuda against the CPU's. Skips without a CUDA device.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "atrous/denoise.h"
#include "atrous/device.h"
#include "atrous/refine.h"
#include "core/parallel.h"
#include "cuda/cuda_exec.cuh"
#include "filters/refine.h"
#include "../denoise_test_util.h"

using namespace atrous;
using namespace atrous::filters;

namespace {

double worstRel(const Image& a, const Image& b) {
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        if (!std::isfinite(a.data()[i])) return 1e30;
        worst = std::max(worst, double(std::fabs(a.data()[i] - b.data()[i])) / (std::fabs(b.data()[i]) + 1e-3));
    }
    return worst;
}

}  // namespace

// The same functors on both sides; nvcc and GCC may contract different multiply-adds, and oneDNN
// sums in another order: 1e-4 relative (refine_test's CPU tolerance).
TEST(RefineCuda, GpuEqualsCpu) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    const RefineWeights w = RefineWeights::builtin();
    for (auto [width, height] : {std::pair{37, 29}, std::pair{257, 130}}) {
        test::SyntheticScene s = test::makeScene(width, height, 0.3f, 11);
        Image lc(width, height, 3), base(width, height, 3);
        CpuExec{}.forEachPixel(width, height, RefineLogColour{s.noisy.view(), lc.view()});
        for (size_t i = 0; i < base.size(); ++i) base.data()[i] = 0.8f * s.truth.data()[i] + 0.2f * s.noisy.data()[i];
        Image cpuF = base.clone(), cpuD = base.clone(), t(width, height, 3);
        runRefine(CpuExec{}, w, RefineViews{lc.view(), t.view(), s.albedo.view(), s.normal.view(), cpuF.view()}, true);
        runRefine(CpuExec{}, w, RefineViews{lc.view(), t.view(), s.albedo.view(), s.normal.view(), cpuD.view()}, false);
        Image dLc = lc.to(Device::Cuda), dT(width, height, 3, Device::Cuda), dA = s.albedo.to(Device::Cuda),
              dN = s.normal.to(Device::Cuda), dOut = base.to(Device::Cuda);
        runRefine(CudaExec{}, w, RefineViews{dLc.view(), dT.view(), dA.view(), dN.view(), dOut.view()});
        const Image gpu = dOut.to(Device::Cpu);
        const double vsF = worstRel(gpu, cpuF), vsD = worstRel(gpu, cpuD);
        std::printf("%dx%d: GPU vs CPU functors %.3g, vs oneDNN %.3g\n", width, height, vsF, vsD);
        EXPECT_LE(vsF, 1e-4);
        EXPECT_LE(vsD, 1e-4);
    }
}

// denoise() with the refine method on the GPU against the CPU: the still path's own GPU/CPU tolerance grows by
// the stage's (denoise_cuda_test holds SURE to 1e-2 absolute; the stage amplifies at most e^3).
TEST(RefineCuda, DenoiseOnGpuMatchesCpu) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    test::SyntheticScene s = test::makeScene(96, 64, 0.3f, 5);
    DenoiseOptions o;
    o.method = DenoiseMethod::Refine;
    const Image cpu = denoise(s.inputs(), o);
    o.device = Device::Cuda;
    const Image gpu = denoise(s.inputs(), o);
    EXPECT_LT(test::maxAbsDiff(gpu, cpu), 2e-2);
}

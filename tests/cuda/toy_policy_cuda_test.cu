// The toy edge-stop policy (tests/toy_policy.h) compiled for the GPU through the shared à-trous
// functor, and run against the CPU's functor where a GPU is available (skipped otherwise).
#include <gtest/gtest.h>

#include <cmath>

#include "atrous/device.h"
#include "core/parallel.h"
#include "cuda/cuda_exec.cuh"
#include "../toy_policy.h"

using namespace atrous;

TEST(ToyPolicyCuda, FunctorOnTheGpuEqualsTheCpu) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    const int w = 61, h = 37;
    Image in(w, h, 3), guide(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            guide(x, y, 0) = x < w / 2 ? 0.0f : 1.0f;
            for (int c = 0; c < 3; ++c) in(x, y, c) = 0.1f * float((x * 7 + y * 3 + c) % 11);
        }
    auto stop = [](const Image& i, const Image& g, Image& o) {
        toy::ToyStop t;
        t.step_ = 2;
        t.invSigma2 = 5.0f;
        t.in = i.view(), t.guide = g.view(), t.out = o.view();
        return t;
    };
    Image ref(w, h, 3);
    filters::runAtrousLevelFunctor(CpuExec{}, stop(in, guide, ref));
    const Image dIn = in.to(Device::Cuda), dGuide = guide.to(Device::Cuda);
    Image dOut(w, h, 3, Device::Cuda);
    filters::runAtrousLevelFunctor(CudaExec{}, stop(dIn, dGuide, dOut));
    CudaExec{}.synchronize();
    const Image got = dOut.to(Device::Cpu);
    // The same fastExp on both sides (no __expf): only FMA contraction differs.
    for (size_t i = 0; i < got.size(); ++i) ASSERT_NEAR(got.data()[i], ref.data()[i], 1e-5f) << i;
}

// The learned filter v3 on the GPU (src/cuda/learned.cu: the functors of filters/learned.h through
// CudaExec) against the CPU row engine and the JAX forward pass on tests/learned_fixture.bin.
// Skips without a CUDA device.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "atrous/device.h"
#include "core/parallel.h"
#include "cuda/cuda_exec.cuh"
#include "filters/learned.h"
#include "../learned_fixture.h"

using namespace atrous;
using namespace atrous::filters;
using atrous::test::fixture;

namespace {

LearnedWeights fixtureWeights() {
    return LearnedWeights::parse(fixture().weights.data(), fixture().weights.size(), "fixture weights");
}

double worstRel(const Image& a, const Image& b) {
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        if (!std::isfinite(a.data()[i])) return 1e30;
        worst = std::max(worst, double(std::fabs(a.data()[i] - b.data()[i])) / std::max(1.0f, std::fabs(b.data()[i])));
    }
    return worst;
}

// The cascade on the GPU, planes copied there (absent ones stay invalid).
Image runGpu(const PreparedView& host, const LearnedWeights& w) {
    auto up = [](const ImageView& v, Image& store) {
        if (!v.valid()) return ImageView{};
        Image h(v.width, v.height, v.channels);
        std::copy(v.data, v.data + v.plane() * size_t(v.channels), h.data());
        store = h.to(Device::Cuda);
        return store.view();
    };
    Image d, var, albedo, normal, depth;
    const PreparedView P = preparedView(up(host.color, d), up(host.variance, var), up(host.albedo, albedo), up(host.normal, normal),
                          up(host.depth, depth));
    Image out(host.color.width, host.color.height, 3, Device::Cuda);
    runLearned(CudaExec{}, w, P, out.view());
    return out.to(Device::Cpu);
}

Image runCpu(const PreparedView& p, const LearnedWeights& w) {
    Image out(p.color.width, p.color.height, 3);
    runLearned(CpuExec{}, w, p, out.view());
    return out;
}

}  // namespace

// GPU against the CPU row engine: the same functions; nvcc and GCC may contract different
// multiply-adds (both round IEEE divisions and square roots, neither uses fast math), ~1e-7
// relative per operation through 5 levels: 1e-5 of max(1, |cpu|), half the JAX tolerance of
// learned_test (2e-5), which the GPU is held to as well.
TEST(LearnedCuda, GpuEqualsCpuAndJax) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    const LearnedWeights w = fixtureWeights();
    const Image gpu = runGpu(fixture().planes(), w), cpu = runCpu(fixture().planes(), w);
    const double vsCpu = worstRel(gpu, cpu), vsJax = worstRel(gpu, fixture().expect);
    std::printf("GPU vs CPU %.3g, GPU vs JAX %.3g\n", vsCpu, vsJax);
    EXPECT_LE(vsCpu, 1e-5);
    EXPECT_LE(vsJax, 2e-5);
}

// Absent albedo, normal and depth, and the built-in weights: GPU equals CPU.
TEST(LearnedCuda, AbsentPlanesAndBuiltinWeights) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    PreparedView p = fixture().planes();
    p.albedo = p.normal = p.depth = ImageView{};
    EXPECT_LE(worstRel(runGpu(p, fixtureWeights()), runCpu(p, fixtureWeights())), 1e-5);
    EXPECT_LE(worstRel(runGpu(fixture().planes(), LearnedWeights::builtin()),
                       runCpu(fixture().planes(), LearnedWeights::builtin())),
              1e-5);
}

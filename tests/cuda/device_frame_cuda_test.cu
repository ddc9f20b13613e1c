// The viewer's device-resident CUDA frame (issue 7): the accumulation and motion functors under
// CudaExec against CpuExec, the renderer's device buffers against its host download, and
// denoise() on inputs already on the GPU (read in place, report reduced on the GPU) against the
// same call on host inputs. Skipped without a GPU.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "atrous/denoise.h"
#include "atrous/device.h"
#include "atrous/error.h"
#include "atrous/render.h"
#include "render/accumulate.h"
#include "render/bvh_render.h"
#include "render/integrator.h"
#include "../motion_test_util.h"
#include "../denoise_test_util.h"

using namespace atrous;
using namespace atrous::test;

namespace {

struct Set {
    Image color, variance, albedo, normal, position, depth, ids, emission;
    Image outColor, outVariance, outAlbedo, outNormal, outPosition, outDepth, outIds, outEmission;
    Image moments, normalMean, counts;
    Image* all[19] = {&color,      &variance,    &albedo,      &normal,    &position,  &depth,       &ids,
                      &emission,   &outColor,    &outVariance, &outAlbedo, &outNormal, &outPosition, &outDepth,
                      &outIds,     &outEmission, &moments,     &normalMean, &counts};
    Set(int w, int h, Device d) {
        for (int k = 0; k < 16; ++k) *all[k] = Image(w, h, 3, d);
        moments = Image(w, h, kAccumMomentChannels, d);
        normalMean = Image(w, h, kAccumNormalChannels, d);
        counts = Image(w, h, kAccumCountChannels, d);
    }
    AccumulateFrame functor(const AccumulateParams& p) const {
        AccumulateFrame a;
        a.p = p;
        a.color = color.view(), a.variance = variance.view(), a.albedo = albedo.view(), a.normal = normal.view();
        a.position = position.view(), a.depth = depth.view(), a.ids = ids.view(), a.emission = emission.view();
        a.outColor = outColor.view(), a.outVariance = outVariance.view(), a.outAlbedo = outAlbedo.view();
        a.outNormal = outNormal.view(), a.outPosition = outPosition.view(), a.outDepth = outDepth.view();
        a.outIds = outIds.view(), a.outEmission = outEmission.view();
        a.moments = moments.view(), a.normalMean = normalMean.view(), a.counts = counts.view();
        return a;
    }
};

double maxRelDiff(const Image& a, const Image& b) {
    const Image ha = a.to(Device::Cpu), hb = b.to(Device::Cpu);
    double worst = 0;
    for (size_t i = 0; i < ha.size(); ++i) {
        const double x = ha.data()[i], y = hb.data()[i];
        worst = std::max(worst, std::fabs(x - y) / std::max(1.0, std::fabs(x)));
    }
    return worst;
}

}  // namespace

TEST(DeviceFrameCuda, AccumulationMatchesTheCpuFunctor) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    const int w = 67, h = 41, spp = 2;  // odd sizes: the kernel's bounds check
    Set cpu(w, h, Device::Cpu), gpu(w, h, Device::Cuda);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int frame = 1; frame <= 40; ++frame) {
        for (int k = 0; k < 8; ++k) {
            Image& img = *cpu.all[k];
            for (size_t i = 0; i < img.size(); ++i) {
                float v = u(rng);
                if (k == 3 && u(rng) < 0.3f) v = 0.0f;           // normals: some misses
                if (k == 5) v = u(rng) < 0.2f ? kBackgroundDepth : 1.0f + 5.0f * v;  // depth
                img.data()[i] = v;
            }
            gpu.all[k]->copyFrom(img);
        }
        const AccumulateParams p = makeAccumulateParams(frame == 1, true, frame, spp, kBackgroundDepth);
        runAccumulateFrame(Device::Cpu, cpu.functor(p));
        runAccumulateFrame(Device::Cuda, gpu.functor(p));
    }
    // Same float operations; nvcc may contract a·b + c into an FMA where GCC does not (or the
    // reverse), a few ulps per step: 1e-5 relative after 40 frames.
    for (int k = 8; k < 19; ++k) EXPECT_LT(maxRelDiff(*cpu.all[k], *gpu.all[k]), 1e-5) << "buffer " << k;
}

TEST(DeviceFrameCuda, MotionMatchesTheCpuFunctor) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    const int w = 50, h = 30;
    Image depth(w, h, 3);
    for (size_t i = 0; i < depth.size(); ++i) depth.data()[i] = i % 7 == 0 ? kBackgroundDepth : 2.0f + float(i % 13);
    const Image depthGpu = depth.to(Device::Cuda);
    Image mCpu(w, h, 3), mGpu(w, h, 3, Device::Cuda);
    MotionFromDepth m =
        motionFromDepth(pt::makeLookAtCamera(Vec3(0.2f, 0.1f, 5.0f), Vec3(0, 0, 0), Vec3(0, 1, 0), 45.0f),
                        pt::makeLookAtCamera(Vec3(-0.3f, 0.0f, 5.2f), Vec3(0, 0, 0), Vec3(0, 1, 0), 45.0f), depth, mCpu);
    runMotionFromDepth(Device::Cpu, m);
    m.depth = depthGpu.view();
    m.motion = mGpu.view();
    runMotionFromDepth(Device::Cuda, m);
    // Pixels of motion; sqrt/division may differ by an ulp between nvcc and GCC: 1e-3 px.
    const Image back = mGpu.to(Device::Cpu);
    for (size_t i = 0; i < back.size(); ++i) EXPECT_NEAR(back.data()[i], mCpu.data()[i], 1e-3) << i;
}

TEST(DeviceFrameCuda, RenderOnDeviceEqualsTheHostDownload) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    const Scene scene = Scene::builtin("cornell");
    RenderSettings s;
    s.width = 40;
    s.height = 32;
    s.spp = 2;
    CudaBvhRenderer r(scene);
    const RenderBuffers host = r.render(s);
    const RenderBuffers& dev = r.renderOnDevice(s);  // same settings and seed: the same samples
    EXPECT_EQ(dev.color.device(), Device::Cuda);
    EXPECT_EQ(maxRelDiff(host.color, dev.color), 0.0);
    EXPECT_EQ(maxRelDiff(host.depth, dev.depth), 0.0);
    EXPECT_EQ(maxRelDiff(host.emission, dev.emission), 0.0);
}

TEST(DeviceFrameCuda, DenoiseOnDeviceInputsMatchesHostInputsAndItsReport) {
    if (!cudaAvailable()) GTEST_SKIP() << "no CUDA device";
    SyntheticScene s = makeScene(64, 48, 0.4f, 17);
    s.noisy(3, 4, 1) = std::nanf("");          // one non-finite pixel
    s.noisy(10, 10, 0) = 500.0f;               // a firefly, with the large sample variance a
    for (int c = 0; c < 3; ++c) s.variance(10, 10, c) = 500.0f * 500.0f / 4;  // 1-of-4-samples spike has
    // (with a given variance, a bright pixel of small own variance is a highlight and kept: prepass.h)
    Image emission(64, 48, 3);
    emission(20, 20, 0) = emission(20, 20, 1) = emission(20, 20, 2) = 4.0f;
    DenoiseOptions o;
    o.device = Device::Cuda;
    Frame hin = s.inputs();
    hin.emission = &emission;
    DenoiseReport hostRep, devRep;
    const Image hostOut = test::denoiseReporting(hin, o, hostRep);  // host inputs: uploaded, result downloaded
    EXPECT_EQ(hostOut.device(), Device::Cpu);
    const Image c = s.noisy.to(Device::Cuda), v = s.variance.to(Device::Cuda), a = s.albedo.to(Device::Cuda),
                n = s.normal.to(Device::Cuda), p = s.position.to(Device::Cuda), d = s.depth.to(Device::Cuda),
                id = s.ids.to(Device::Cuda), e = emission.to(Device::Cuda);
    Frame din;
    din.color = &c, din.variance = &v, din.albedo = &a, din.normal = &n, din.position = &p, din.depth = &d;
    din.ids = &id, din.emission = &e;
    const Image devOut = test::denoiseReporting(din, o, devRep);  // device inputs: in place, result stays on the GPU
    EXPECT_EQ(devOut.device(), Device::Cuda);
    EXPECT_EQ(maxRelDiff(hostOut, devOut), 0.0);  // the same kernels on the same data
    EXPECT_EQ(devRep.nonFinitePixels, 1);
    EXPECT_EQ(hostRep.nonFinitePixels, 1);
    EXPECT_EQ(devRep.firefliesClamped, hostRep.firefliesClamped);
    EXPECT_GE(devRep.firefliesClamped, 1);
    EXPECT_DOUBLE_EQ(devRep.meanLuminanceIn, hostRep.meanLuminanceIn);
    EXPECT_DOUBLE_EQ(devRep.meanLuminanceAfterFirefly, hostRep.meanLuminanceAfterFirefly);
    // The CPU's report of the same inputs (double sums in another order: 1e-9 relative).
    DenoiseReport cpuRep;
    DenoiseOptions oc = o;
    oc.device = Device::Cpu;
    test::denoiseReporting(hin, oc, cpuRep);
    EXPECT_NEAR(devRep.meanLuminanceIn, cpuRep.meanLuminanceIn, 1e-9 * std::fabs(cpuRep.meanLuminanceIn));
    EXPECT_NEAR(devRep.meanLuminanceAfterFirefly, cpuRep.meanLuminanceAfterFirefly,
                1e-5 * std::fabs(cpuRep.meanLuminanceAfterFirefly));  // after: GPU vs CPU clamp, ulps
    EXPECT_EQ(devRep.firefliesClamped, cpuRep.firefliesClamped);
    // No variance (the viewer's first frame at 1 spp): the MAD noise estimate runs on the GPU for
    // a GPU colour. Same details in the same double arithmetic; FMA contraction may differ by an
    // ulp between GCC and nvcc, hence 1e-6 relative on σ and 1e-4 on the results (values ~1).
    hin.variance = nullptr;
    din.variance = nullptr;
    const Image hostEst = test::denoiseReporting(hin, o, hostRep);
    const Image devEst = test::denoiseReporting(din, o, devRep);
    EXPECT_TRUE(devRep.noiseEstimated);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(hostRep.noiseSigma[c], 0.0f);
        EXPECT_NEAR(devRep.noiseSigma[c], hostRep.noiseSigma[c], 1e-6 * hostRep.noiseSigma[c]) << c;
    }
    EXPECT_LT(maxRelDiff(hostEst, devEst), 1e-4);
    din.variance = &v;
    // A negative variance on the GPU is still an InputError naming the pixel.
    Image badVar = s.variance.clone();
    badVar(5, 7, 2) = -1.0f;
    const Image badVarGpu = badVar.to(Device::Cuda);
    din.variance = &badVarGpu;
    const std::string msg = inputErrorOf(din, o);
    EXPECT_NE(msg.find("(5, 7)"), std::string::npos) << "InputError: '" << msg << "'";
}

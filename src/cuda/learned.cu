// The learned filter v3 on the GPU: the functors of filters/learned.h launched by CudaExec (pass A,
// pass B one thread per pixel with the MLP in registers, the five levels as AtrousLevel<LearnedStop>).
// The weights are copied to the device once per call; the temporaries are one device image.
#include <chrono>

#include "atrous/error.h"
#include "cuda/cuda_exec.cuh"
#include "cuda/device_buffer.cuh"
#include "filters/learned.h"

namespace atrous::filters {

void runLearned(const CudaExec& exec, const LearnedWeights& weights, const LearnedPlanes& in, const ImageView& out,
                LearnedStageTimes* times) {
    checkLearnedPlanes(weights, in, out);
    const int w = in.d.width, h = in.d.height;
    const auto t0 = std::chrono::steady_clock::now();
    cuda::DeviceBuffer<LearnedNet> net(1);
    net.upload(&weights.impl->net, 1);
    Image temps(w, h, kLearnedTempChannels, Device::Cuda);
    const LearnedTemps T = learnedTemps(temps.data(), w, h);
    runLearnedFunctors(exec, net.data(), in, T, out);
    exec.synchronize();
    if (times) times->levels = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace atrous::filters

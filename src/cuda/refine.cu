// The refine stage on the GPU: the functors of filters/refine.h launched by CudaExec (the
// convolutions as LearnedConv, one thread per output sample). The network is copied to the device
// and the tensors allocated once per call.
#include "atrous/refine.h"
#include "cuda/cuda_exec.cuh"
#include "cuda/device_buffer.cuh"
#include "filters/refine.h"

namespace atrous::filters {

void runRefine(const CudaExec& exec, const RefineWeights& weights, const RefineViews& v) {
    const int w = v.out.width, h = v.out.height;
    cuda::DeviceBuffer<RefineNet> net(1);
    net.upload(&refineNet(weights), 1);
    cuda::DeviceBuffer<float> block(refineFloats(w, h));
    runRefineFunctors(exec, net.data(), v, refinePlanes(block.data(), w, h));
    exec.synchronize();
}

}  // namespace atrous::filters

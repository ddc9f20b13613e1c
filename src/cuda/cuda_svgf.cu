// CUDA instantiation of the SVGF driver: the same stage functors as the CPU backend
// (src/filters/svgf_*.h), launched as kernels by CudaExec on the default stream.
#include "cuda/cuda_exec.cuh"
#include "filters/svgf_pipeline.h"

namespace atrous::detail {

std::unique_ptr<SvgfBackend> makeSvgfCudaBackend(const SvgfParams& params) {
    return std::make_unique<svgf::SvgfBackendImpl<CudaExec>>(params);
}

}  // namespace atrous::detail

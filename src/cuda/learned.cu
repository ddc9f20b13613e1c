// The learned filter's stages compiled for the GPU: the functors of filters/learned.h launched by
// CudaExec. Not wired to a public entry point yet (docs/learned.md, "Status"); compiling it here
// keeps the shared math GPU-clean.
#include "cuda/cuda_exec.cuh"
#include "filters/learned.h"

namespace atrous::filters {

// The cascade on the GPU: every view of `prep` (and net) in device memory.
void runLearnedCascadeCuda(const CudaExec& exec, const LearnedPrepare& prep, const ImageView& tmp,
                           const ImageView& out) {
    runLearnedCascade(exec, prep, tmp, out);
}

}  // namespace atrous::filters

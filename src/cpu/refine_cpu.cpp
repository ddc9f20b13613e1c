// The refine stage on the CPU (filters/refine.h): the per-pixel passes through the functors on
// TBB, the convolutions through oneDNN (cpu/dnnl_conv.h), or all through the functors (the
// reference the tests compare with).
#include <memory>

#include "atrous/refine.h"
#include "core/parallel.h"
#include "cpu/dnnl_conv.h"
#include "filters/refine.h"

namespace atrous::filters {

void runRefine(const CpuExec& exec, const RefineWeights& weights, const RefineViews& v, bool functors) {
    const int w = v.out.width, h = v.out.height;
    // Not zero-filled: every tensor is written whole before it is read.
    std::unique_ptr<float[]> block(new float[refineFloats(w, h)]);
    const RefinePlanes P = refinePlanes(block.get(), w, h);
    const RefineNet* net = &refineNet(weights);
    if (functors) {
        runRefineFunctors(exec, net, v, P);
        return;
    }
    runRefinePasses(exec, net, v, P,
                    [](const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu) {
                        learnedConvCpu(in, out, k, b, ks, relu, "refine");
                    });
}

}  // namespace atrous::filters

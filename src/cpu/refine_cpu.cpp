// The refine stage on the CPU (filters/refine.h): the per-pixel passes through the functors on
// TBB, the convolutions through oneDNN (cpu/dnnl_conv.h), or all through the functors (the
// reference the tests compare with).
#include <algorithm>
#include <cstdlib>
#include <memory>
#include <new>
#include <vector>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "atrous/refine.h"
#include "core/parallel.h"
#include "cpu/dnnl_conv.h"
#include "filters/refine.h"

namespace atrous::filters {
namespace {

// The network's block (~90 MB at 512², ~700 MB at 1080p), fresh per call: in 4 KiB pages its
// first touch cost ~20 000 page faults per 100 MB (a sixth of the stage's time at 512²), so it is
// 2 MiB-aligned and advised for transparent huge pages where Linux offers them.
struct FreeBlock {
    void operator()(float* p) const { std::free(p); }
};
std::unique_ptr<float[], FreeBlock> refineBlock(size_t floats) {
    constexpr size_t kHuge = size_t(2) << 20;
    const size_t bytes = (floats * sizeof(float) + kHuge - 1) / kHuge * kHuge;
    auto* p = static_cast<float*>(std::aligned_alloc(kHuge, bytes));
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, bytes, MADV_HUGEPAGE);  // advice only: without it the block is still valid
#endif
    return std::unique_ptr<float[], FreeBlock>(p);
}

}  // namespace

void runRefine(const CpuExec& exec, const RefineWeights& weights, const RefineViews& v, bool functors) {
    const int w = v.out.width, h = v.out.height;
    // Not zero-filled: every tensor is written whole before it is read.
    const auto block = refineBlock(refineFloats(w, h));
    const RefinePlanes P = refinePlanes(block.get(), w, h);
    const RefineNet* net = &refineNet(weights);
    if (functors) {
        runRefineFunctors(exec, net, v, P);
        return;
    }
    auto conv = [](const LearnedTensor& in, const LearnedTensor& out, const float* k, const float* b, int ks, bool relu) {
        learnedConvCpu(in, out, k, b, ks, relu, "refine");
    };
    // The decoder without the concatenation: conv(skip) with the bias, then conv(up2 lo) summed
    // into it before the ReLU (oneDNN's nhwc kernels run a 56-channel input at half the rate of
    // a 32- and a 24-channel one; the skip tensor is not copied). The kernel's input channels are
    // [lo's, skip's] (HWIO), split per tap.
    auto catConv = [&](const LearnedTensor& lo, const LearnedTensor& skip, const LearnedTensor& cat,
                       const LearnedTensor& out, const float* k, const float* b) {
        const int cl = lo.channels, cs = skip.channels, co = out.channels;
        std::vector<float> kl(size_t(9 * cl * co)), ksk(size_t(9 * cs * co));
        for (int t = 0; t < 9; ++t) {
            const float* kt = k + size_t(t) * size_t(cl + cs) * size_t(co);
            std::copy(kt, kt + size_t(cl * co), kl.begin() + ptrdiff_t(t * cl * co));
            std::copy(kt + size_t(cl * co), kt + size_t((cl + cs) * co), ksk.begin() + ptrdiff_t(t * cs * co));
        }
        const std::vector<float> zero(size_t(co), 0.0f);
        learnedConvCpu(skip, out, ksk.data(), b, 3, false, "refine");
        const LearnedTensor up{cat.data, skip.width, skip.height, cl};
        exec.forEachPixel(up.width, up.height, RefineUp2{lo, up});
        learnedConvCpu(up, out, kl.data(), zero.data(), 3, true, "refine", true);
    };
    runRefinePasses(exec, net, v, P, conv, catConv);
}

}  // namespace atrous::filters

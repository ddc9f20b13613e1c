// The CPU half of the one dispatcher (docs/architecture.md, principle 1). A per-pixel functor has
// `void operator()(int x, int y) const`; CpuExec runs it on TBB threads, CudaExec
// (src/cuda/cuda_exec.cuh) as a CUDA kernel. Drivers that chain several functors are templates on
// the executor, so the level loop of a filter is written once as well.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "atrous/device.h"

namespace atrous {

// Runs f(x, y) for every pixel of a width x height grid on TBB threads. Rows are the unit of
// work (grain: a few rows), and the inner x loop is a plain loop the compiler can vectorise.
// Compiled for the build's baseline (x86-64), not ISA-dispatched (src/cpu/isa_dispatch.h): run
// through parallelForIsa's flattened wrappers, SVGF's μ2 - μ1² (svgf_variance.h) was contracted
// into an FMA, which keeps the rounding error of l² where svgf_test expects exact cancellation.
// Dispatched, SVGF's reprojection ran 2.99 -> 2.33 ms at 512² (whole SVGF ~2%); a stage that
// pays gets a src/cpu row loop that calls parallelForIsa.
template <class F>
void parallelFor2dCpu(int width, int height, const F& f, int grainRows = 4) {
    if (width <= 0 || height <= 0) return;
    tbb::parallel_for(tbb::blocked_range<int>(0, height, grainRows), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y) {
#pragma omp simd
            for (int x = 0; x < width; ++x) f(x, y);
        }
    });
}

// Runs f(y) for every row; for functors that process a whole row at a time.
template <class F>
void parallelForRowsCpu(int height, const F& f, int grainRows = 4) {
    if (height <= 0) return;
    tbb::parallel_for(tbb::blocked_range<int>(0, height, grainRows), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y) f(y);
    });
}

struct CpuExec {
    Device device() const { return Device::Cpu; }
    template <class F>
    void forEachPixel(int width, int height, const F& f) const { parallelFor2dCpu(width, height, f); }
    void synchronize() const {}
};

}  // namespace atrous

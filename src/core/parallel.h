// The CPU half of the one dispatcher (docs/architecture.md, principle 1). A per-pixel functor has
// `void operator()(int x, int y) const`; CpuExec runs it on TBB threads, CudaExec
// (src/cuda/cuda_exec.cuh) as a CUDA kernel. Drivers that chain several functors are templates on
// the executor, so the level loop of a filter is written once as well.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "atrous/device.h"
#include "core/isa_dispatch.h"

namespace atrous {

namespace detail {

// Rows [y0, y1) of parallelFor2dCpu / parallelForRowsCpu, the body the ISA wrappers compile.
template <class F>
struct PixelRows {
    const F& f;
    int width;
    void operator()(int y0, int y1) const {
        for (int y = y0; y < y1; ++y) {
#pragma omp simd
            for (int x = 0; x < width; ++x) f(x, y);
        }
    }
};
template <class F>
struct WholeRows {
    const F& f;
    void operator()(int y0, int y1) const {
        for (int y = y0; y < y1; ++y) f(y);
    }
};

}  // namespace detail

// Runs f(x, y) for every pixel of a width x height grid on TBB threads, with the loops of the
// CPU ISA in use (cpu::parallelForIsa: f is compiled for baseline x86-64, AVX2 and AVX-512). Rows
// are the unit of work (grain: a few rows), and the inner x loop is a plain loop the compiler can
// vectorise.
template <class F>
void parallelFor2dCpu(int width, int height, const F& f, int grainRows = 4) {
    if (width <= 0 || height <= 0) return;
    cpu::parallelForIsa(cpu::activeIsa(), 0, height, grainRows, detail::PixelRows<F>{f, width});
}

// Runs f(y) for every row; for functors that process a whole row at a time.
template <class F>
void parallelForRowsCpu(int height, const F& f, int grainRows = 4) {
    if (height <= 0) return;
    cpu::parallelForIsa(cpu::activeIsa(), 0, height, grainRows, detail::WholeRows<F>{f});
}

struct CpuExec {
    Device device() const { return Device::Cpu; }
    template <class F>
    void forEachPixel(int width, int height, const F& f) const { parallelFor2dCpu(width, height, f); }
    void synchronize() const {}
};

}  // namespace atrous

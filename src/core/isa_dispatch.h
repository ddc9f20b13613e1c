// The one place the CPU loops pick their instruction set (src/core/cpu_isa.h): parallelForIsa
// runs a body compiled for baseline x86-64, AVX2 (x86-64-v3) or AVX-512 on TBB threads. CpuExec
// (parallel.h), the row engine (src/cpu/atrous_rows.h) and the row loops of src/cpu come through
// here, so no stage writes its own dispatch.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/cpu_isa.h"

namespace atrous::cpu {

// ISA dispatch, written once: body(i0, i1) (a force-inlined or flattened operator()) compiled
// for baseline x86-64, AVX2 (x86-64-v3) and AVX-512, run over [begin, end) in TBB blocks of
// `grain` with the loops of `isa`.
template <class Body, class Index>
ATROUS_TARGET_BASELINE void isaRangeBaseline(const Body& body, Index i0, Index i1) {
    body(i0, i1);
}
#if ATROUS_CPU_MULTI_ISA
template <class Body, class Index>
ATROUS_TARGET_AVX2 void isaRangeAvx2(const Body& body, Index i0, Index i1) {
    body(i0, i1);
}
template <class Body, class Index>
ATROUS_TARGET_AVX512 void isaRangeAvx512(const Body& body, Index i0, Index i1) {
    body(i0, i1);
}
#endif

// The wrapper of `isa` for Body (the baseline one where the others are not compiled).
template <class Body, class Index>
auto isaRangeFn(Isa isa) -> void (*)(const Body&, Index, Index) {
#if ATROUS_CPU_MULTI_ISA
    if (isa == Isa::Avx512) return &isaRangeAvx512<Body, Index>;
    if (isa == Isa::Avx2) return &isaRangeAvx2<Body, Index>;
#else
    (void)isa;
#endif
    return &isaRangeBaseline<Body, Index>;
}

template <class Index, class Body>
void parallelForIsa(Isa isa, Index begin, Index end, Index grain, const Body& body) {
    void (*fn)(const Body&, Index, Index) = isaRangeFn<Body, Index>(isa);
    tbb::parallel_for(tbb::blocked_range<Index>(begin, end, grain),
                      [&](const tbb::blocked_range<Index>& r) { fn(body, r.begin(), r.end()); });
}

// The AVX-512 switch (avx512Switch(), filters::atrousCpuAvx512()) as an ISA: the AVX-512 loops, or
// the ISA in use capped at AVX2 (tests turn the switch off to run the AVX2 loops on an AVX-512 CPU).
inline Isa isaFromAvx512Switch(bool avx512) {
    if (avx512) return Isa::Avx512;
    const Isa a = activeIsa();
    return a == Isa::Avx512 ? Isa::Avx2 : a;
}

// The form the stages call with the row engine's switch.
template <class Index, class Body>
void parallelForIsa(bool avx512, Index begin, Index end, Index grain, const Body& body) {
    parallelForIsa(isaFromAvx512Switch(avx512), begin, end, grain, body);
}

}  // namespace atrous::cpu

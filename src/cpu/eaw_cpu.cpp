// CPU path of one EAW/SURE level: the rS plane and the taps through the shared row engine
// (src/cpu/atrous_rows.h) with the EawStop policy (filters/eaw.h), the same math as the functor.
//
// Where it pays:
// - the pair's 1/σ_c² is max(r(p), r(q)) of a per-pixel plane r = eawColorRecip(S) computed once
//   per level, not one division per tap;
// - the id term and the depth term are compiled out when they are off (their loads too): the
//   policy's kDepth/kIds.
#include <tbb/scalable_allocator.h>

#include <memory>

#include "atrous/error.h"
#include "core/parallel.h"
#include "cpu/atrous_rows.h"
#include "filters/eaw.h"

namespace atrous::filters {

namespace {

// r = eawColorRecip(S) over the flat pixel range [i0, i1).
struct ColorRecipRange {
    EawLevelParams p;
    const float* S;
    float* r;
    ATROUS_FORCE_INLINE void operator()(size_t i0, size_t i1) const {
        const float* ATROUS_RESTRICT s = S;
        float* ATROUS_RESTRICT o = r;
#pragma omp simd
        for (size_t i = i0; i < i1; ++i) o[i] = eawColorRecip(p, s[i]);
    }
};

template <bool kPropagate>
void runRows(const EawLevel& f, bool avx512) {
    const bool depth = f.p.invDepth > 0.0f, ids = f.p.idPenalty > 0.0f;
    if (depth && ids) cpu::runAtrousRows(EawStop<kPropagate, true, true>{f}, avx512);
    else if (depth) cpu::runAtrousRows(EawStop<kPropagate, true, false>{f}, avx512);
    else if (ids) cpu::runAtrousRows(EawStop<kPropagate, false, true>{f}, avx512);
    else cpu::runAtrousRows(EawStop<kPropagate, false, false>{f}, avx512);
}

}  // namespace

void runEawLevel(const CpuExec& exec, const EawLevel& level) {
    EawLevel f = level;
    // The level's r plane, when the caller gave none: from the scalable allocator, whose cache
    // hands the same block back level after level (not an Image: that would zero-fill it first).
    std::unique_ptr<float, void (*)(void*)> store(nullptr, scalable_aligned_free);
    if (!f.rS.valid()) {
        store.reset(static_cast<float*>(scalable_aligned_malloc(f.S.plane() * sizeof(float), 64)));
        if (!store) throw RuntimeError("out of host memory for the EAW colour scale plane");
        f.rS = ImageView{store.get(), f.cIn.width, f.cIn.height, 1};
    }
    if (!atrousCpuFastPath()) {
        if (f.p.propagate)
            runAtrousLevelFunctor(exec, EawColorRecip{f.p, f.S, f.rS}, SureStop{f});
        else
            runAtrousLevelFunctor(exec, EawColorRecip{f.p, f.S, f.rS}, EawStop<false>{f});
        return;
    }
    const bool avx512 = atrousCpuAvx512();
    const size_t count = size_t(f.cIn.width) * size_t(f.cIn.height);
    cpu::parallelForIsa(avx512, size_t(0), count, size_t(16384), ColorRecipRange{f.p, f.S.channel(0), f.rS.channel(0)});
    if (f.p.propagate)
        runRows<true>(f, avx512);
    else
        runRows<false>(f, avx512);
}

}  // namespace atrous::filters

// CPU path of one SVGF à-trous level: the luminance stop plane, then the taps through the shared
// row engine (src/cpu/atrous_rows.h) with the SvgfStop policy (filters/svgf_atrous.h), the same
// math as the functor: the tap weight, the depth and normal stops, fastLog/fastExp and the
// luminance stop are the shared functions of svgf_atrous.h / svgf_common.h, and every pixel sums
// its taps in the functor's order. The functor's skipped taps (empty pixel, across an edge) are
// weight-0 selects in the row loops, which add exactly nothing (see SvgfStop).
//
// Where the time went before (scalar functor, 512²: ~24 ms per level on 2 cores):
// - logf per tap in the normal stop: now the polynomial fastLog, also used by the GPU;
// - the 3x3 prefiltered variance and the luminance stop's 1/(σ_l sqrt(g) + ε) recomputed with
//   branches for every pixel: now once per level into a plane, the interior branch-free;
// - branches per tap, which kept GCC from vectorising anything: now selects (selectF).
#include <cstddef>

#include "core/parallel.h"
#include "cpu/atrous_rows.h"
#include "filters/svgf_atrous.h"

namespace atrous::svgf {

namespace {

// Rows [y0, y1) of the luminance stop plane: g3x3(var) in the functor's summation order (its
// weights sum to exactly 1 inside, so the division by Σk is a no-op there); the border through
// the functor's own renormalised version.
struct LumStopRows {
    AtrousLumStop f;
    ATROUS_FORCE_INLINE void operator()(int y0, int y1) const {
        const int w = f.variance.width, h = f.variance.height;
        const float sigmaL = f.sigmaL;
        const float* ATROUS_RESTRICT var = f.variance.channel(0);
        for (int y = y0; y < y1; ++y) {
            const size_t rowP = size_t(y) * w;
            float* ATROUS_RESTRICT pil = f.out.channel(0) + rowP;
            if (y > 0 && y < h - 1 && w > 2) {
                const float* ATROUS_RESTRICT vm = var + rowP - w;
                const float* ATROUS_RESTRICT v0 = var + rowP;
                const float* ATROUS_RESTRICT vp = var + rowP + w;
#pragma omp simd
                for (int x = 1; x < w - 1; ++x) {
                    float sum = 0.0f;
                    sum = fmaf(0.0625f, vm[x - 1], sum);
                    sum = fmaf(0.125f, vm[x], sum);
                    sum = fmaf(0.0625f, vm[x + 1], sum);
                    sum = fmaf(0.125f, v0[x - 1], sum);
                    sum = fmaf(0.25f, v0[x], sum);
                    sum = fmaf(0.125f, v0[x + 1], sum);
                    sum = fmaf(0.0625f, vp[x - 1], sum);
                    sum = fmaf(0.125f, vp[x], sum);
                    sum = fmaf(0.0625f, vp[x + 1], sum);
                    pil[x] = atrousLumStopRecip(sigmaL, sum);
                }
                f(0, y);
                f(w - 1, y);
            } else {
                for (int x = 0; x < w; ++x) f(x, y);
            }
        }
    }
};

}  // namespace

void runSvgfAtrous(const CpuExec& exec, const Atrous& level) {
    Atrous f = level;
    const int w = f.illum.width, h = f.illum.height;
    if (w <= 0 || h <= 0) return;
    Image scratch;
    f.lumStop = filters::levelPlane(exec, f.lumStop, w, h, scratch);
    const AtrousLumStop stop{f.sigmaL, f.variance, f.lumStop};
    if (!filters::atrousCpuFastPath()) {
        exec.forEachPixel(w, h, stop);
        filters::runAtrousLevelFunctor(exec, SvgfStop{f});
        return;
    }
    const bool avx512 = filters::atrousCpuAvx512();
    cpu::parallelForIsa(avx512, 0, h, 8, LumStopRows{stop});
    cpu::runAtrousRows(SvgfStop{f}, avx512);
}

}  // namespace atrous::svgf

// CPU row loops of the still filters' demodulation and remodulation (filters::Demodulate,
// filters::Remodulate, modulation.h) and of the global noise estimate's variance
// (filters::GlobalVariance, noise_estimate.h): a' of a row at once (cpu::modulationRow), then
// vectorised x loops with the functors' arithmetic. Through forEachPixel the functors stayed
// scalar (the rim rule's 3x3 scan behind a branch): 1.3 and 2 ms at 512x512 on 2 cores.
// FP exceptions are never unmasked or tested here; without -ftrapping-math GCC if-converts the
// selects (results unchanged: no reassociation or contraction is allowed by this).
#include "atrous/platform.h"
ATROUS_NO_TRAPPING_MATH

#include <type_traits>
#include <vector>

#include "core/parallel.h"
#include "core/isa_dispatch.h"
#include "cpu/modulation_rows.h"
#include "filters/modulation.h"
#include "filters/noise_estimate.h"

namespace atrous::filters {

namespace {

// a' rows for [y0, y1) of one task, handed to body(y, a) per row.
template <class Body>
void modulationRows(const AlbedoRule& rule, const ImageView& albedo, int w, int y0, int y1, Body&& body) {
    std::vector<float> buf(3 * size_t(w) + cpu::modulationRowScratch(w));
    float* const a[3] = {buf.data(), buf.data() + w, buf.data() + 2 * size_t(w)};
    for (int y = y0; y < y1; ++y) {
        cpu::modulationRowOrOne(rule, albedo, y, w, a, buf.data() + 3 * size_t(w));
        body(y, a);
    }
}

}  // namespace

void runDemodulate(const CpuExec&, const Demodulate& f) {
    const int w = f.in.width, h = f.in.height;
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 8, [&](int y0, int y1) {
        const Demodulate g = f;
        const bool hasE = g.emission.valid(), hasVar = g.var.valid();
        modulationRows(g.rule, g.albedo, w, y0, y1, [&](int y, float* const (&a)[3]) {
            const size_t o = size_t(y) * size_t(w);
            for (int k = 0; k < 3; ++k) {
                // in and out may be the same plane (no restrict): each x reads then writes itself.
                const float* in = g.in.channel(k) + o;
                float* out = g.out.channel(k) + o;
                const float* ATROUS_RESTRICT e = hasE ? g.emission.channel(k) + o : in;
                float* var = hasVar ? g.var.channel(k) + o : nullptr;
                const float* ATROUS_RESTRICT ak = a[k];
                // One loop body, compiled with and without the variance update (each vectorised).
                auto row = [&](auto withVar) {
#pragma omp simd
                    for (int x = 0; x < w; ++x) {
                        const float u = hasE ? e[x] : 0.0f;
                        const float ev = hasE ? (finite(u) ? u : 0.0f) : 0.0f;
                        const float ia = 1.0f / ak[x];
                        out[x] = (in[x] - ev) * ia;
                        if constexpr (decltype(withVar)::value) var[x] *= ia * ia;
                    }
                };
                if (hasVar) row(std::true_type{});
                else row(std::false_type{});
            }
        });
    });
}

void runRemodulate(const CpuExec&, const Remodulate& f) {
    const int w = f.base.width, h = f.base.height;
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 8, [&](int y0, int y1) {
        const Remodulate g = f;
        const bool hasDetail = g.detail.valid(), hasE = g.emission.valid();
        std::vector<float> prod(static_cast<size_t>(w));
        modulationRows(g.rule, g.albedo, w, y0, y1, [&](int y, float* const (&a)[3]) {
            const size_t o = size_t(y) * size_t(w);
            for (int k = 0; k < 3; ++k) {
                const float* base = g.base.channel(k) + o;  // may be `out`
                float* out = g.out.channel(k) + o;
                const float* ATROUS_RESTRICT d = hasDetail ? g.detail.channel(k) + o : base;
                const float* ATROUS_RESTRICT ak = a[k];
                float* ATROUS_RESTRICT p = prod.data();
                // (F + detail) · a', then + e in a second loop: the functor adds the emission
                // behind a branch, so the product is rounded before the sum (no multiply-add).
#pragma omp simd
                for (int x = 0; x < w; ++x) {
                    float v = base[x];
                    if (hasDetail) v += d[x];
                    p[x] = v * ak[x];
                }
                if (hasE) {
                    const float* ATROUS_RESTRICT e = g.emission.channel(k) + o;
#pragma omp simd
                    for (int x = 0; x < w; ++x) out[x] = p[x] + e[x];
                } else {
#pragma omp simd
                    for (int x = 0; x < w; ++x) out[x] = p[x];
                }
            }
        });
    });
}

void runGlobalVariance(const CpuExec&, const GlobalVariance& f) {
    const int w = f.var.width, h = f.var.height;
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 8, [&](int y0, int y1) {
        const GlobalVariance g = f;
        AlbedoRule rule;  // pixelModulationAlbedo's defaults: the rim rule on, non-finite read as 0
        rule.eps = g.eps, rule.floor = g.floor;
        modulationRows(rule, g.albedo, w, y0, y1, [&](int y, float* const (&a)[3]) {
            const size_t o = size_t(y) * size_t(w);
            for (int k = 0; k < 3; ++k) {
                float* ATROUS_RESTRICT var = g.var.channel(k) + o;
                const float* ATROUS_RESTRICT ak = a[k];
                const float fv = g.floorVar[k];
#pragma omp simd
                for (int x = 0; x < w; ++x) var[x] = fv * ak[x] * ak[x];
            }
        });
    });
}

}  // namespace atrous::filters

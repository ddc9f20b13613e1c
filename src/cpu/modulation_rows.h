// The modulation albedo a' (filters::pixelModulationAlbedo, filter_math.h) for a whole image row,
// for the CPU row loops of the still filters (src/cpu/modulation_cpu.cpp, src/cpu/noise_cpu.cpp).
// The per-pixel function scans the 3x3 neighbourhood of the rim rule behind a branch, which kept
// every functor that calls it (Demodulate, Remodulate, the noise estimate) scalar; here the 3x3
// minimum of the neighbours' largest channel is taken for the whole row first (a vertical then a
// horizontal minimum: exact, minima do not round), and the x loop applies the same per-pixel
// arithmetic with selects, so the values are those of the functor bit for bit
// (tests/modulation_test.cpp). Call it from inside an ISA-dispatched body (cpu::parallelForIsa).
#pragma once
#include <cstddef>

#include "filters/modulation.h"

namespace atrous::cpu {

// Scratch a row needs: 2 rows of w floats.
inline size_t modulationRowScratch(int w) { return 2 * size_t(w); }

// a[c][x] = a'_c of pixel (x, y), c = 0..2, under `rule` (1 without an albedo).
ATROUS_FORCE_INLINE inline void modulationRow(const filters::AlbedoRule& rule, const ImageView& albedo, int y,
                                              float* const (&a)[3], float* scratch) {
    using namespace filters;
    const int w = albedo.valid() ? albedo.width : 0;
    if (!albedo.valid()) return;  // the caller fills 1 (modulationRowOrOne)
    const int h = albedo.height;
    const bool rimOn = rule.rim && rule.floor > 0.0f;
    float* ATROUS_RESTRICT mn = scratch;       // the 3x3 minimum
    float* ATROUS_RESTRICT vm = scratch + w;   // the vertical minimum of rows y-1..y+1
    if (rimOn) {
        // Largest channel of the raw albedo (maxChannel of the stored values, as the functor's
        // scan), non-finite read as 0; minimum over the three rows (clamped), then over x-1..x+1.
        for (int k = 0; k < 3; ++k) {
            const size_t o = size_t(clampIdx(y + k - 1, h - 1)) * size_t(w);
            const float* ATROUS_RESTRICT r = albedo.channel(0) + o;
            const float* ATROUS_RESTRICT g = albedo.channel(1) + o;
            const float* ATROUS_RESTRICT b = albedo.channel(2) + o;
            if (k == 0) {
#pragma omp simd
                for (int x = 0; x < w; ++x) {
                    const float m = maxChannel(r[x], g[x], b[x]);
                    vm[x] = finite(m) ? m : 0.0f;
                }
            } else {
#pragma omp simd
                for (int x = 0; x < w; ++x) {
                    const float m = maxChannel(r[x], g[x], b[x]);
                    vm[x] = minSel(vm[x], finite(m) ? m : 0.0f);
                }
            }
        }
        if (w == 1) {
            mn[0] = vm[0];
        } else {
            mn[0] = minSel(vm[0], vm[1]);
#pragma omp simd
            for (int x = 1; x < w - 1; ++x) mn[x] = minSel(minSel(vm[x - 1], vm[x]), vm[x + 1]);
            mn[w - 1] = minSel(vm[w - 2], vm[w - 1]);
        }
    } else {
        for (int x = 0; x < w; ++x) mn[x] = 1e30f;  // never below a tenth of the floor: no rim
    }
    const size_t o = size_t(y) * size_t(w);
    const float* ATROUS_RESTRICT r = albedo.channel(0) + o;
    const float* ATROUS_RESTRICT g = albedo.channel(1) + o;
    const float* ATROUS_RESTRICT b = albedo.channel(2) + o;
    float* ATROUS_RESTRICT a0 = a[0];
    float* ATROUS_RESTRICT a1 = a[1];
    float* ATROUS_RESTRICT a2 = a[2];
    const float nf = rule.nonFinite, floor = rule.floor, eps = rule.eps;
#pragma omp simd
    for (int x = 0; x < w; ++x) {
        const float v0 = finite(r[x]) ? r[x] : nf, v1 = finite(g[x]) ? g[x] : nf, v2 = finite(b[x]) ? b[x] : nf;
        const float mp = maxChannel(v0, v1, v2);
        // pixelModulationAlbedo's test, then its 3x3 scan's outcome (mn) where the test holds.
        const bool scan = rimOn & (mp > 0.0f) & (mp < kRimFloorMul * floor);
        const float nearBlack = scan & (mn[x] < kBlackAlbedoFraction * floor) ? 1.0f : 0.0f;
        const float t = modulationTerm(mp, floor * (1.0f + nearBlack * (kRimFloorMul - 1.0f)));
        a0[x] = modulationAlbedo(v0, t, eps);
        a1[x] = modulationAlbedo(v1, t, eps);
        a2[x] = modulationAlbedo(v2, t, eps);
    }
}

// modulationRow, or 1 everywhere without an albedo.
ATROUS_FORCE_INLINE inline void modulationRowOrOne(const filters::AlbedoRule& rule, const ImageView& albedo, int y,
                                                   int w, float* const (&a)[3], float* scratch) {
    if (albedo.valid()) {
        modulationRow(rule, albedo, y, a, scratch);
        return;
    }
    for (int c = 0; c < 3; ++c)
        for (int x = 0; x < w; ++x) a[c][x] = 1.0f;
}

}  // namespace atrous::cpu

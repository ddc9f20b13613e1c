// The one demodulate/remodulate pair (docs/algorithms.md, "Albedo demodulation"): the still
// filters (still_prepare.h, still_finish.h), their noise estimate (noise_estimate.h) and SVGF (svgf_pipeline.h)
// run these two functors. What differs between the callers is data: the albedo rule (AlbedoRule:
// floor, rim rule, what a non-finite albedo reads as) and which optional buffers they give.
#pragma once
#include "atrous/image.h"
#include "atrous/platform.h"
#include "filters/filter_math.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::filters {

// How an albedo pixel becomes the divisors a'_c (pixelModulationAlbedo, filter_math.h).
// Still filters: eps 1e-3, DenoiseOptions::albedoFloor, rim rule on, non-finite reads 0.
// SVGF: eps 1e-3, kDefaultAlbedoFloor, no rim rule, non-finite reads 1 (svgfAlbedoRule).
struct AlbedoRule {
    float eps = 1e-3f;
    float floor = 0.0f;
    bool rim = true;
    float nonFinite = 0.0f;
    ATROUS_INLINE void at(const ImageView& albedo, int x, int y, float (&a)[3]) const {
        pixelModulationAlbedo(albedo, x, y, eps, floor, a, nonFinite, rim);
    }
};

// out_c = (in_c - e_c) / a'_c; var_c /= a'_c² in place. Optional (invalid view: skipped):
// emission (non-finite reads 0), var. kSample (SVGF): a pixel whose input has a non-finite
// channel is no sample, out = 0 and valid = 0 (SVGF keeps its history there), else valid = 1, and
// |out| is clamped to maxAbs. The still filters' input is sanitised before (prepass.h), so their
// instance skips those tests (they cost half again its time: docs/decisions.md). `out` may be `in`.
template <bool kSample>
struct DemodulateT {
    AlbedoRule rule;
    ImageView albedo, in, out;
    ImageView emission, var, valid;
    float maxAbs = 3.4e38f;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const bool hasE = emission.valid(), hasVar = var.valid();
        float c[3];
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
            c[k] = in(x, y, k);
            if (kSample) ok = ok && finite(c[k]);
        }
        if (kSample) valid(x, y, 0) = ok ? 1.0f : 0.0f;
        float a[3];
        rule.at(albedo, x, y, a);
        for (int k = 0; k < 3; ++k) {
            float e = 0.0f;
            if (hasE) {
                const float u = emission(x, y, k);
                e = finite(u) ? u : 0.0f;
            }
            const float ia = 1.0f / a[k];
            const float v = (c[k] - e) * ia;
            if (kSample) out(x, y, k) = !ok ? 0.0f : (v > maxAbs ? maxAbs : (v < -maxAbs ? -maxAbs : v));
            else out(x, y, k) = v;
            if (hasVar) var(x, y, k) *= ia * ia;
        }
    }
};

using Demodulate = DemodulateT<false>;        // the still filters and their noise estimate
using DemodulateSample = DemodulateT<true>;   // SVGF

// out_c = (base_c + detail_c) · a'_c + e_c, with the same a'_c as Demodulate (so the pair is an
// identity wherever the filter leaves a pixel alone). Optional: detail (SURE's kept detail),
// emission. kGuard (SVGF, whose history may hold anything): a non-finite emission reads 0 and a
// non-finite result leaves as 0; the still filters' inputs are finite by then (prepass.h).
template <bool kGuard>
struct RemodulateT {
    AlbedoRule rule;
    ImageView base, detail, albedo, emission, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const bool hasDetail = detail.valid(), hasE = emission.valid();
        float a[3];
        rule.at(albedo, x, y, a);
        for (int k = 0; k < 3; ++k) {
            float v = base(x, y, k);
            if (hasDetail) v += detail(x, y, k);
            v *= a[k];
            if (hasE) {
                const float e = emission(x, y, k);
                v += (!kGuard || finite(e)) ? e : 0.0f;
            }
            out(x, y, k) = (!kGuard || finite(v)) ? v : 0.0f;
        }
    }
};

using Remodulate = RemodulateT<false>;       // the still filters
using RemodulateGuarded = RemodulateT<true>;  // SVGF

// The still filters' pair on `exec`. The CpuExec overloads (src/cpu/modulation_cpu.cpp) run row
// loops: a' of a whole row at once (cpu::modulationRow, the rim rule's 3x3 scan as row minima),
// then a vectorised x loop with the same arithmetic (bit-equal, tests/modulation_test.cpp).
// Demodulate's `out` may be its `in`, Remodulate's `out` its `base` (both work pixel by pixel).
template <class Exec>
void runDemodulate(const Exec& exec, const Demodulate& f) {
    exec.forEachPixel(f.in.width, f.in.height, f);
}
template <class Exec>
void runRemodulate(const Exec& exec, const Remodulate& f) {
    exec.forEachPixel(f.base.width, f.base.height, f);
}
void runDemodulate(const CpuExec& exec, const Demodulate& f);
void runRemodulate(const CpuExec& exec, const Remodulate& f);

}  // namespace atrous::filters

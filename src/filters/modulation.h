// The one demodulate/remodulate pair (docs/algorithms.md, "Albedo demodulation"): the still
// filters (denoise_driver.h), their noise estimate (noise_estimate.h) and SVGF (svgf_pipeline.h)
// run these two functors. What differs between the callers is data: the albedo rule (AlbedoRule:
// floor, rim rule, what a non-finite albedo reads as) and which optional buffers they give.
#pragma once
#include "atrous/image.h"
#include "atrous/platform.h"
#include "filters/filter_math.h"

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
        if (rim) pixelModulationAlbedo<true>(albedo, x, y, eps, floor, a, nonFinite);
        else pixelModulationAlbedo<false>(albedo, x, y, eps, floor, a, nonFinite);
    }
};

// out_c = clamp((in_c - e_c) / a'_c, ±maxAbs); var_c /= a'_c² in place. Optional (invalid view:
// skipped): emission (non-finite reads 0), var, valid. With `valid`, a pixel whose input has a
// non-finite channel is no sample: out = 0 and valid = 0 (SVGF keeps its history there); else
// valid = 1. `out` may be `in`.
struct Demodulate {
    AlbedoRule rule;
    ImageView albedo, in, out;
    ImageView emission, var, valid;
    float maxAbs = 3.4e38f;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float c[3];
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
            c[k] = in(x, y, k);
            ok = ok && finite(c[k]);
        }
        if (valid.valid()) {
            valid(x, y, 0) = ok ? 1.0f : 0.0f;
            if (!ok) {
                for (int k = 0; k < 3; ++k) out(x, y, k) = 0.0f;
                return;
            }
        }
        float a[3];
        rule.at(albedo, x, y, a);
        for (int k = 0; k < 3; ++k) {
            float e = 0.0f;
            if (emission.valid()) {
                e = emission(x, y, k);
                e = finite(e) ? e : 0.0f;
            }
            const float ia = 1.0f / a[k];
            const float v = (c[k] - e) * ia;
            out(x, y, k) = v > maxAbs ? maxAbs : (v < -maxAbs ? -maxAbs : v);
            if (var.valid()) var(x, y, k) *= ia * ia;
        }
    }
};

// out_c = (base_c + detail_c) · a'_c + e_c, with the same a'_c as Demodulate (so the pair is an
// identity wherever the filter leaves a pixel alone); anything non-finite leaves as 0. Optional:
// detail (SURE's kept detail), emission (non-finite reads 0).
struct Remodulate {
    AlbedoRule rule;
    ImageView base, detail, albedo, emission, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float a[3];
        rule.at(albedo, x, y, a);
        for (int k = 0; k < 3; ++k) {
            float v = base(x, y, k);
            if (detail.valid()) v += detail(x, y, k);
            v *= a[k];
            if (emission.valid()) {
                const float e = emission(x, y, k);
                v += finite(e) ? e : 0.0f;
            }
            out(x, y, k) = finite(v) ? v : 0.0f;
        }
    }
};

}  // namespace atrous::filters

// The still path's finishing (docs/architecture.md, "The still path"), the same for every method:
// the non-finite guard of a registered cascade's output, the safety net (docs/algorithms.md, "The
// safety net": F' = F + s (y - F), s chosen by SURE on the residual) and the remodulation, out =
// (base + detail) * a' + the filtered emission. Templates on the executor.
#pragma once
#include <cmath>

#include "filters/modulation.h"
#include "filters/noise_estimate.h"
#include "filters/safety_net.h"
#include "filters/still_cascades.h"
#include "filters/still_state.h"
#include "filters/sure.h"

namespace atrous::filters {

// After a registered method's cascade: a sample it left non-finite is the prepared input's (NaN
// and Inf never reach an output, whatever a plug-in computes).
struct FiniteOr {
    ImageView out, fallback;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int k = 0; k < 3; ++k)
            if (!finite(out(x, y, k))) out(x, y, k) = fallback(x, y, k);
    }
};

// The safety net on F (its detail folded in). κ: an estimated variance (no variance buffer) can be
// off by a factor (spatially correlated noise from a pixel filter wider than a pixel, the
// quietest-quadrant rule), so it is calibrated on the image itself: where the filter only removed
// noise E[ΣD] ≈ ΣV, and that is most of an image. κ = the median window ratio ΣD/ΣV (at least 1),
// so the net acts where the residual is out of line with the rest. A given variance is trusted
// (κ = 1).
template <class Exec>
void safetyNet(const Exec& exec, const StillConfig& cfg, const KeptInput& kept, PlanePool& pool, Filtered& F) {
    const DenoiseOptions& o = cfg.opts;
    const int w = pool.width(), h = pool.height();
    Image detail = pool.take(2), boxH = pool.take(2);
    SureChoiceParams sp;
    sp.radius = o.safety.windowRadius;
    exec.forEachPixel(w, h, SafetyDetail{kept.y.view(), F.base.view(), F.detailView(), kept.var.view(), detail.view()});
    runSureBoxH(exec, SureBoxH{sp.radius, detail.view(), boxH.view()});
    float kappa = 1.0f;
    if (!cfg.varianceGiven) {
        Image ratio = pool.take(1);
        exec.forEachPixel(w, h, SafetyRatio{sp.radius, boxH.view(), ratio.view()});
        kappa = std::fmax(1.0f, medianFinite(exec, ratio.view(), 1.0f));
    }
    exec.forEachPixel(w, h, SafetyBlend{sp, kappa, o.safety.trigger, boxH.view(), kept.y.view(), F.base.view(), F.detailView(),
                                        ImageView{}});
    F.detail = Image();  // folded into base
}

// The whole finishing: into out.out, or in place in F's base, moved into *out.result.
template <class Exec>
void finish(const Exec& exec, const StillConfig& cfg, const Prepared& p, const KeptInput& kept, PlanePool& pool, Filtered& F,
            const StillOutputs& out) {
    const int w = pool.width(), h = pool.height();
    if (F.fallback.valid()) exec.forEachPixel(w, h, FiniteOr{F.base.view(), F.fallback});
    if (cfg.opts.safety.enabled) {
        safetyNet(exec, cfg, kept, pool, F);
        markStage(out.clock, "safety net");
    }
    Remodulate r;
    r.rule = stillAlbedoRule(cfg.opts);
    r.base = F.base.view(), r.detail = F.detailView(), r.albedo = p.albedo, r.emission = p.emission;
    r.out = out.out.valid() ? out.out : F.base.view();
    runRemodulate(exec, r);
    markStage(out.clock, "remodulate");
    exec.synchronize();
    if (!out.out.valid() && out.result) *out.result = std::move(F.base);
}

}  // namespace atrous::filters

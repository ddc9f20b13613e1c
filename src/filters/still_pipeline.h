// The still path (docs/architecture.md, "The still path"): preparation, the cascade of the
// method's registry row, finishing. Written once as a template on the executor (CpuExec in
// src/filters/denoise.cpp, CudaExec in src/cuda/cuda_denoise.cu). Inputs and outputs are views on
// the executor's device; the temporaries are allocated there, once per call, and recycled through
// one PlanePool (still_state.h).
#pragma once
#include "filters/still_cascades.h"
#include "filters/still_finish.h"
#include "filters/still_prepare.h"
#include "filters/still_state.h"
#include "filters/refine.h"

namespace atrous::filters {

// The features a call prepares: what its method's cascade reads (its row's `reads`, with the
// options' switches).
inline BufferMask preparedFeatures(const StillConfig& cfg) {
    return methodReads(denoiseMethodInfo(cfg.opts.method), cfg.opts);
}

// The row's cascade, with the input the give-back and the safety net keep taken where the
// cascade allows: before a cascade that overwrites the prepared colour, after the learned one
// (which only reads it) once its own temporaries are gone, so that Blend's peak is SURE's plus
// one plane set.
template <class Exec>
Filtered runCascade(const Exec& exec, const StillConfig& cfg, Prepared& p, PlanePool& pool, KeptInput& kept,
                    const StillOutputs& out) {
    const DenoiseOptions& o = cfg.opts;
    const DenoiseMethodInfo& row = denoiseMethodInfo(o.method);
    const bool giveBack = cfg.albedoGiveBack && p.albedo.valid();
    switch (row.kind) {
        case CascadeKind::Eaw:
        case CascadeKind::Sure:
            kept = keepInput(exec, o, giveBack, pool, p);
            markStage(out.clock, preparedStage(p));
            return eawCascade(exec, cfg, row.kind == CascadeKind::Sure, p, pool, kept, out);
        case CascadeKind::Learned:
        case CascadeKind::Blend: {
            markStage(out.clock, preparedStage(p));
            Filtered learned = learnedCascade(exec, cfg, p, pool, out);
            const bool blend = row.kind == CascadeKind::Blend;
            kept = keepInput(exec, o, blend && giveBack, pool, p);
            if (!kept.y.empty()) markStage(out.clock, "keep input");
            if (!blend) return learned;
            // F = (SURE's F + the learned F) / 2, in the demodulated units (remodulation is linear).
            Filtered F = eawCascade(exec, cfg, true, p, pool, kept, out);
            exec.forEachPixel(pool.width(), pool.height(), BlendMean{F.base.view(), F.detailView(), learned.base.view()});
            F.detail = Image();
            markStage(out.clock, "blend");
            return F;
        }
        case CascadeKind::Registered:
            kept = keepInput(exec, o, false, pool, p);
            markStage(out.clock, preparedStage(p));
            return registeredCascade(exec, row, cfg, p, pool, out);
        case CascadeKind::Auto:
            break;
    }
    throw InputError("the still path was given auto unresolved");
}

// The refine method's stage (filters/refine.h) on the finished output (the inputs were checked to
// have an albedo and a normal): lc, log1p of the noisy colour, is taken before the preparation
// (which may sanitise the colour in place).
template <class Exec>
void runStill(const Exec& exec, const StillInputs& in, const StillConfig& cfg, const StillOutputs& out) {
    const int w = in.color.width, h = in.color.height;
    PlanePool pool(w, h, exec.device());
    const bool refine = cfg.opts.method == DenoiseMethod::Refine && in.albedo.valid() && in.normal.valid();
    Image lc;
    if (refine) {
        lc = pool.take(3);
        exec.forEachPixel(w, h, RefineLogColour{in.color, lc.view()});
    }
    Prepared p = prepare(exec, in, cfg, preparedFeatures(cfg), pool, out);
    KeptInput kept;
    Filtered F = runCascade(exec, cfg, p, pool, kept, out);
    finish(exec, cfg, p, kept, pool, F, out);
    if (refine) {
        p = Prepared{};
        kept = KeptInput{};
        Image t = pool.take(3);
        runRefine(exec, cfg.opts.refineWeights, RefineViews{lc.view(), t.view(), in.albedo, in.normal,
                                                            out.out.valid() ? out.out : out.result->view()});
        markStage(out.clock, "refine");
    }
}

}  // namespace atrous::filters

// The level-loop driver of EAW, SURE and the learned method, written once as a template on the executor (CpuExec in
// src/filters/denoise.cpp, CudaExec in src/cuda/cuda_denoise.cu). Inputs and outputs are views on
// the executor's device; temporaries are allocated there.
#pragma once
#include <cmath>
#include <utility>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/image.h"
#include "atrous/learned.h"
#include "filters/eaw.h"
#include "filters/emission_filter.h"
#include "filters/learned.h"
#include "filters/modulation.h"
#include "filters/noise_estimate.h"
#include "filters/prepass.h"
#include "filters/safety_net.h"
#include "filters/stage_clock.h"
#include "filters/sure.h"

namespace atrous::filters {

constexpr int kMaxLevels = 10;
// Exponent added per unit squared id difference: ids are integers, so a differing id gives a
// weight of exactly 0 (fastExp returns 0 below -80).
constexpr float kIdPenalty = 1e4f;

struct DriverInputs {
    ImageView color, variance;  // variance always valid (a constant estimate when none was given)
    ImageView albedo, normal, position, depth, ids, emission;  // invalid when absent
};

// The learned filter's prepared planes (docs/learned.md), copied out after step 3 for training
// (filters::learnedPlanes, atrous.learned_planes): views the caller allocated (zero-filled) on the
// executor's device, each skipped when invalid. With them the driver stops after step 3.
struct DriverPlanes {
    ImageView d, var;        // 3 ch: the demodulated, firefly-clamped colour and its variance
    ImageView albedo;        // 3 ch: the sanitised albedo the demodulation divided by (when used)
    ImageView normal;        // 3 ch: the sanitised normal (when given)
    ImageView depth;         // 1 ch: the sanitised depth (when given)
    ImageView mod;           // 3 ch: the a' Remodulate multiplies by (1 where no albedo)
    ImageView emission;      // 3 ch: the filtered emission Remodulate adds (left 0 when none)
};

// out = a' of the rule (Remodulate's multiplier; 1 without an albedo).
struct ModulationOf {
    AlbedoRule rule;
    ImageView albedo, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float a[3];
        rule.at(albedo, x, y, a);
        for (int c = 0; c < 3; ++c) out(x, y, c) = a[c];
    }
};

struct DriverOutputs {
    ImageView out;           // 3 channels, required (not written when `planes` is set)
    ImageView afterFirefly;  // optional: c_0 after sanitising and firefly suppression (3 ch)
    ImageView fireflyFlag;   // optional: 1 where a firefly was clamped (1 ch)
    ImageView sureS;         // optional: s_i per level (levels channels)
    StageClock* clock = nullptr;  // optional: started by the caller, marked after each stage
    const DriverPlanes* planes = nullptr;  // optional: copy the prepared planes out and stop after step 3
};

// The caller's options held whole (as SvgfPipeline holds its SvgfParams), plus what the driver
// derives from the inputs: whether a variance was given, and the local noise estimate.
// The still filters' albedo rule (modulation.h): the options' eps and floor, the rim rule on,
// a non-finite albedo read as 0.
inline AlbedoRule stillAlbedoRule(const DenoiseOptions& o) {
    AlbedoRule r;
    r.eps = o.albedoEpsilon, r.floor = o.albedoFloor;
    return r;
}

struct DriverConfig {
    DenoiseOptions opts;  // opts.method is Eaw, Sure or Learned (Auto resolved by denoise())
    LearnedWeights learned{};  // the learned method's weights (loaded by denoise())
    bool varianceGiven = true;  // false: the variance is a constant estimate
    // Without a variance: the local estimate (noise_estimate.h) over quadrants of this radius
    // (0 = keep the constant), floored at noiseFloorVar (the global estimate times a fraction) and
    // capped at kNoiseCapMul times it.
    int noiseRadius = 0;
    float noiseFloorVar[3] = {0, 0, 0};
    // EAW and SURE with an albedo: the residual the albedo explains goes back after the cascade
    // (safety_net.h, runAlbedoGiveBack). Off only for tests that measure without it.
    bool albedoGiveBack = true;
};

// α_i = true var(d_i) / independence-propagated var(d_i) for the unweighted B3 cascade on white
// noise. The 2D kernels are separable (K = k ⊗ k), so Σ K² = (Σ k²)² and
// Σ (K_i - K_{i+1})² = (Σ k_i²)² + (Σ k_{i+1}²)² - 2 (Σ k_i k_{i+1})², computed from 1D kernels.
inline void sureDetailVarianceFactors(int levels, float* alpha) {
    const int reach = 4 * ((1 << levels) - 1) + 1;
    const int n = 2 * reach + 1, c = reach;
    std::vector<double> k(n, 0.0), next(n);
    k[c] = 1.0;
    const double h[5] = {1 / 16.0, 4 / 16.0, 6 / 16.0, 4 / 16.0, 1 / 16.0};
    const double sumH2 = (70.0 / 256.0) * (70.0 / 256.0);  // Σ h² of the 2D kernel
    const double h0 = (6 / 16.0) * (6 / 16.0);              // a_p of the 2D kernel
    double indVar = 1.0;                                     // independence var(c_i)
    for (int i = 0; i < levels; ++i) {
        const int step = 1 << i;
        for (int j = 0; j < n; ++j) {
            double s = 0;
            for (int q = -2; q <= 2; ++q) {
                const int jj = j + q * step;
                if (jj >= 0 && jj < n) s += h[q + 2] * k[jj];
            }
            next[j] = s;
        }
        double a = 0, b = 0, ab = 0;
        for (int j = 0; j < n; ++j) {
            a += k[j] * k[j];
            b += next[j] * next[j];
            ab += k[j] * next[j];
        }
        const double trueVar = a * a + b * b - 2.0 * ab * ab;
        const double indNext = indVar * sumH2;
        const double ind = indVar + indNext - 2.0 * h0 * indVar;
        alpha[i] = float(trueVar / ind);
        indVar = indNext;
        k.swap(next);
    }
}

template <class Exec>
void runDenoise(const Exec& exec, const DriverInputs& in, const DriverConfig& cfg, const DriverOutputs& out) {
    const int w = in.color.width, h = in.color.height;
    const Device dev = exec.device();
    const DenoiseOptions& o = cfg.opts;
    const bool sure = o.method == DenoiseMethod::Sure;
    const bool learned = o.method == DenoiseMethod::Learned;
    const int levels = o.eaw.levels;

    // 1. Non-finite samples and features.
    Image c0(w, h, 3, dev), v0(w, h, 3, dev);
    runSanitizeColor(exec, SanitizeColor{in.color, in.variance, c0.view(), v0.view()});
    // The albedo the demodulation divides by, sanitised once (the noise estimate reads it too).
    ImageView albedo = o.demodulate ? in.albedo : ImageView{};
    Image albedoStore;
    if (albedo.valid()) albedo = sanitizedFeature(exec, albedo, w, h, 3, albedoStore);
    if (!cfg.varianceGiven && cfg.noiseRadius > 0 && albedo.valid()) {
        // The global estimate is of the demodulated colour: in the colour's units it scales with
        // the albedo (noise_estimate.h). Without an albedo the constant given is that already.
        GlobalVariance gv;
        for (int c = 0; c < 3; ++c) gv.floorVar[c] = cfg.noiseFloorVar[c];
        gv.eps = o.albedoEpsilon;
        gv.floor = o.albedoFloor;
        gv.albedo = albedo;
        gv.var = v0.view();
        exec.forEachPixel(w, h, gv);
    }
    // Features: sanitised copies (on the CPU the buffers themselves when already clean), zeros
    // when absent.
    Image emissionStore, normalStore, positionStore, depthStore, idsStore, emissionA, emissionB;
    ImageView emission;
    if (in.emission.valid()) {
        // Filter the reflected part only: c_0 = color - emission (emission added back at the end).
        emission = sanitizedFeature(exec, in.emission, w, h, 3, emissionStore);
        exec.forEachPixel(w, h, SubtractEmission{emission, c0.view()});
        // The emission added back is filtered along emitter edges (filters/emission_filter.h).
        if (o.eaw.emissionLevels > 0) {
            emissionA = Image(w, h, 3, dev);
            emissionB = Image(w, h, 3, dev);
            emission = runEmissionFilter(exec, o.eaw.emissionLevels, o.eaw.emissionScale, v0.view(), emission,
                                         emissionA.view(), emissionB.view());
        }
    }
    const ImageView normal = sanitizedFeature(exec, in.normal, w, h, 3, normalStore);
    const ImageView position = sanitizedFeature(exec, in.position, w, h, 3, positionStore);
    const ImageView depth = sanitizedFeature(exec, in.depth, w, h, 1, depthStore);
    const ImageView ids = sanitizedFeature(exec, in.ids, w, h, 2, idsStore);
    markStage(out.clock, "sanitize");

    // 2. Fireflies (before demodulation: the outlier is in radiance).
    // c0/v0 are dead after this step: without the firefly pass they become cA/vA (no copy), with
    // it they are reused below as the cascade's second buffers (fewer image-sized temporaries).
    Image cA, vA;
    if (o.firefly.enabled) {
        cA = Image(w, h, 3, dev);
        vA = Image(w, h, 3, dev);
        runFireflyClamp(exec, FireflyClamp{o.firefly.k, cfg.varianceGiven ? 1 : 0, c0.view(), v0.view(), cA.view(),
                                           vA.view(), out.fireflyFlag});
    } else {
        cA = std::move(c0);
        vA = std::move(v0);
    }
    if (out.afterFirefly.valid()) {
        exec.forEachPixel(w, h, Copy3{cA.view(), out.afterFirefly});
    }
    markStage(out.clock, "fireflies");
    if (!cfg.varianceGiven && cfg.noiseRadius > 0) {
        // The variance from the colour itself (after the emission is taken out and the fireflies
        // clamped with the constant estimate, so that they do not raise it): noise_estimate.h.
        Image demod(w, h, 3, dev), energy(w, h, 3, dev);
        Demodulate d;
        d.rule = stillAlbedoRule(o);
        d.albedo = albedo, d.in = cA.view(), d.out = demod.view();
        exec.forEachPixel(w, h, d);
        DetailEnergy de;
        de.color = demod.view(), de.energy = energy.view(), de.normal = normal, de.depth = depth;  // albedo fit off
        for (int c = 0; c < 3; ++c) de.maxDiff2[c] = kNoiseEdgeSigmas2 * kNoiseCapMul * cfg.noiseFloorVar[c];
        exec.forEachPixel(w, h, de);
        Image rows(w, h, 8, dev);
        exec.forEachPixel(w, h, QuadrantRows{cfg.noiseRadius, energy.view(), rows.view()});
        LocalVariance lv;
        lv.radius = cfg.noiseRadius;
        lv.capMul = kNoiseCapMul;
        for (int c = 0; c < 3; ++c) lv.floorVar[c] = cfg.noiseFloorVar[c];
        lv.eps = o.albedoEpsilon;
        lv.floor = o.albedoFloor;
        lv.rows = rows.view();
        lv.albedo = albedo;
        lv.var = vA.view();
        lv.normal = in.normal.valid() ? normal : ImageView{};
        exec.forEachPixel(w, h, lv);
    }

    // 3. Albedo demodulation.
    if (albedo.valid()) {
        Demodulate d;
        d.rule = stillAlbedoRule(o);
        d.albedo = albedo;
        d.in = d.out = cA.view();
        d.var = vA.view();
        exec.forEachPixel(w, h, d);
    }
    if (out.planes) {
        const DriverPlanes& P = *out.planes;
        if (P.d.valid()) exec.forEachPixel(w, h, Copy3{cA.view(), P.d});
        if (P.var.valid()) exec.forEachPixel(w, h, Copy3{vA.view(), P.var});
        if (P.albedo.valid() && albedo.valid()) exec.forEachPixel(w, h, Copy3{albedo, P.albedo});
        if (P.normal.valid() && in.normal.valid()) exec.forEachPixel(w, h, Copy3{normal, P.normal});
        if (P.depth.valid() && in.depth.valid()) exec.forEachPixel(w, h, CopyChannels<1>{depth, P.depth});
        if (P.mod.valid()) exec.forEachPixel(w, h, ModulationOf{stillAlbedoRule(o), albedo, P.mod});
        if (P.emission.valid() && emission.valid()) exec.forEachPixel(w, h, Copy3{emission, P.emission});
        markStage(out.clock, "demodulate");
        exec.synchronize();
        return;
    }
    // The safety net's input y and its summed variance, kept before the cascade overwrites them.
    // The albedo give-back reads the same y.
    const bool giveBack = cfg.albedoGiveBack && !learned && albedo.valid();
    Image safetyIn, safetyVar;
    if (o.safety.enabled || giveBack) {
        safetyIn = Image(w, h, 3, dev);
        exec.forEachPixel(w, h, Copy3{cA.view(), safetyIn.view()});
    }
    if (o.safety.enabled) {
        safetyVar = Image(w, h, 1, dev);
        exec.forEachPixel(w, h, SafetyVariance{vA.view(), safetyVar.view()});
    }
    markStage(out.clock, "demodulate");

    // 4-5. The learned method: its cascade (filters/learned.h) on the prepared planes, d_out in
    // `learnedOut`; a feature that was not given is an invalid plane (the network reads it as absent).
    Image* cur = &cA;
    Image cB, vB, detail, boxH, acc, learnedOut;
    if (learned) {
        learnedOut = Image(w, h, 3, dev);
        const LearnedPlanes P{cA.view(), vA.view(), albedo, in.normal.valid() ? normal : ImageView{},
                              in.depth.valid() ? depth : ImageView{}};
        runLearned(exec, cfg.learned, P, learnedOut.view());
        cur = &learnedOut;
        markStage(out.clock, "learned");
    } else {
        // 4. Per-pixel scales of the automatic σ_c and σ_x.
        Image S(w, h, 1, dev), invX(w, h, 1, dev), invZ(w, h, 1, dev);
        runColorScale(exec, ColorScale{o.eaw.sigmaColor, o.eaw.colorScale * o.eaw.colorScale, vA.view(), S.view()});
        runFootprint(exec, Footprint{in.position.valid() ? 1 : 0, o.eaw.sigmaPosition,
                                     o.eaw.positionScale * o.eaw.positionScale, position, depth, invX.view(),
                                     invZ.view()});
        markStage(out.clock, "sigma scales");

        // 5. The cascade. SURE also propagates the variance and keeps Σ s_i d_i in `acc`.
        cB = c0.empty() ? Image(w, h, 3, dev) : std::move(c0);  // fully overwritten by level 0
        float alpha[kMaxLevels];
        for (int i = 0; i < kMaxLevels; ++i) alpha[i] = 1.0f;
        SureChoiceParams choice;
        if (sure) {
            vB = v0.empty() ? Image(w, h, 3, dev) : std::move(v0);  // fully overwritten by level 0
            detail = Image(w, h, 2, dev);
            boxH = Image(w, h, 2, dev);
            acc = Image(w, h, 3, dev);
            if (o.sure.correlatedVariance) sureDetailVarianceFactors(levels, alpha);
            choice.radius = o.sure.windowRadius;
            choice.jamesStein = o.sure.mode == SureMode::JamesStein ? 1 : 0;
            choice.count = int(o.sure.candidates.size());
            for (int k = 0; k < choice.count && k < kMaxSureCandidates; ++k) choice.candidates[k] = o.sure.candidates[k];
        }
        // Each level's 1/σ_c² factors (EawLevel::rS). The CPU level takes its plane from the scalable
        // allocator per level instead, as it did before the shared cascade (docs/benchmarks.md, "One
        // cascade": holding an image through the cascade was a suspect of a slower sanitise stage).
        Image rS = dev == Device::Cpu ? Image() : Image(w, h, 1, dev);
        cur = &cA;
        Image* nxt = &cB;
        Image* vcur = &vA;
        Image* vnxt = &vB;
        const float invSigmaN2 = o.eaw.sigmaNormal > 0 && in.normal.valid() ? 1.0f / (o.eaw.sigmaNormal * o.eaw.sigmaNormal) : 0.0f;
        for (int i = 0; i < levels; ++i) {
            EawLevelParams lp;
            lp.step = 1 << i;
            lp.colorMul = std::pow(o.eaw.colorLevelFactor, 2.0f * float(i));
            lp.invNormal = o.eaw.normalStepScale ? invSigmaN2 / float(lp.step * lp.step) : invSigmaN2;
            lp.autoPosition = o.eaw.sigmaPosition > 0 ? 0 : 1;
            lp.invDepth = o.eaw.sigmaDepth > 0 && in.depth.valid() ? 1.0f / (o.eaw.sigmaDepth * o.eaw.sigmaDepth) : 0.0f;
            lp.idPenalty = o.eaw.useIds && in.ids.valid() ? kIdPenalty : 0.0f;
            lp.propagate = sure ? 1 : 0;
            lp.detailVarScale = alpha[i];
            EawLevel f;
            f.p = lp;
            f.cIn = cur->view();
            f.cOut = nxt->view();
            if (sure) {
                f.vIn = vcur->view();
                f.vOut = vnxt->view();
                f.detail = detail.view();
            }
            f.S = S.view();
            f.rS = rS.empty() ? ImageView{} : rS.view();
            f.normal = normal;
            f.position = position;
            f.invX = invX.view();
            f.depth = depth;
            f.invZ = invZ.view();
            f.ids = ids;
            runEawLevel(exec, f);
            markStage(out.clock, "level", i);
            if (sure) {
                // Levels below sure.firstLevel keep s_i = 0 (their details are dropped, as in EAW): the
                // per-level risk assumes the levels' noise is independent, but adjacent fine levels'
                // detail noise correlates at ~0.7 after colour-weighted levels (docs/quality.md), so
                // their individual SURE choices keep noise. Adding 0·d_i to acc is a no-op, so such a
                // level runs no window passes unless its s_i map is asked for (it is then all 0).
                const bool dropped = i < o.sure.firstLevel;
                if (!dropped || out.sureS.valid()) {
                    runSureBoxH(exec, SureBoxH{choice.radius, detail.view(), boxH.view()});
                    ImageView sOut;
                    if (out.sureS.valid()) sOut = ImageView{out.sureS.channel(i), w, h, 1};
                    SureChoiceParams levelChoice = choice;
                    if (dropped) {
                        levelChoice.jamesStein = 0;
                        levelChoice.count = 1;
                        levelChoice.candidates[0] = 0.0f;
                    }
                    runSureChoose(exec, SureChoose{levelChoice, boxH.view(), cur->view(), nxt->view(), acc.view(), sOut});
                }
                markStage(out.clock, "sure", i);
                std::swap(vcur, vnxt);
            }
            std::swap(cur, nxt);
        }
    }

    // 6. The albedo give-back, F' = F + the part of y - F that the albedo explains (its time is
    // counted in the next stage), then the safety net: F' = F + s (y - F), s chosen by SURE on the
    // residual (safety_net.h).
    ImageView detailSum = sure ? acc.view() : ImageView{};
    if (giveBack) {
        runAlbedoGiveBack(exec, safetyIn.view(), cur->view(), detailSum, albedo);
        detailSum = ImageView{};
    }
    if (o.safety.enabled) {
        if (!sure) {
            detail = Image(w, h, 2, dev);
            boxH = Image(w, h, 2, dev);
        }
        SureChoiceParams sp;
        sp.radius = o.safety.windowRadius;
        exec.forEachPixel(w, h, SafetyDetail{safetyIn.view(), cur->view(), detailSum, safetyVar.view(), detail.view()});
        runSureBoxH(exec, SureBoxH{sp.radius, detail.view(), boxH.view()});
        // κ: an estimated variance (no variance buffer) can be off by a factor (spatially
        // correlated noise from a pixel filter wider than a pixel, the quietest-quadrant rule), so
        // it is calibrated on the image itself: where the filter only removed noise E[ΣD] ≈ ΣV,
        // and that is most of an image. κ = the median window ratio ΣD/ΣV (at least 1), so the net
        // acts where the residual is out of line with the rest. A given variance is trusted (κ = 1).
        float kappa = 1.0f;
        if (!cfg.varianceGiven) {
            Image ratio(w, h, 1, dev);
            exec.forEachPixel(w, h, SafetyRatio{sp.radius, boxH.view(), ratio.view()});
            kappa = std::fmax(1.0f, medianFinite(exec, ratio.view(), 1.0f));
        }
        exec.forEachPixel(w, h, SafetyBlend{sp, kappa, o.safety.trigger, boxH.view(), safetyIn.view(), cur->view(), detailSum, ImageView{}});
        detailSum = ImageView{};
        markStage(out.clock, "safety net");
    }

    // 7. out = (c_N + Σ s_i d_i) · albedo.
    Remodulate r;
    r.rule = stillAlbedoRule(o);
    r.base = cur->view(), r.detail = detailSum, r.albedo = albedo, r.emission = emission, r.out = out.out;
    exec.forEachPixel(w, h, r);
    markStage(out.clock, "remodulate");
    exec.synchronize();
}

}  // namespace atrous::filters

// The level-loop driver of EAW, SURE and the learned method, written once as a template on the executor (CpuExec in
// src/filters/denoise.cpp, CudaExec in src/cuda/cuda_denoise.cu). Inputs and outputs are views on
// the executor's device; temporaries are allocated there.
#pragma once
#include <cmath>
#include <exception>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
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
    // variance: invalid when estimated (no variance buffer): the driver then fills its own from the
    // global estimate (GlobalVariance, cfg.noiseFloorVar); the GPU path passes a constant estimate.
    ImageView color, variance;
    ImageView albedo, normal, position, depth, ids, emission;  // invalid when absent
    // Optional, host only (denoise() on DenoiseBuffers): the caller's Images behind color, variance
    // and emission, handed over. The driver then works in their storage (c_0 and var(c_0) are
    // sanitised in place, the emission filter ping-pongs through the emission's image) and may
    // keep any of them as its result; a handed-over image is left empty or holding intermediate
    // values. Null, or not the image the view is of: copies, as before.
    Image* colorStore = nullptr;
    Image* varianceStore = nullptr;
    Image* emissionStore = nullptr;
};

// What the CPU driver measures for the report while it runs (denoiseCpu; the GPU path reduces its
// afterFirefly and fireflyFlag planes instead).
struct DriverReport {
    int firefliesClamped = 0;
    double lumAfterSum = 0;  // Σ of the finite luminances of c_0 after the firefly pass
    double lumAfterCount = 0;
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
    // 3 channels, not written when `planes` is set. Invalid: the result is remodulated in place in
    // the driver's own planes and moved into *result.
    ImageView out;
    Image* result = nullptr;
    ImageView afterFirefly;  // optional: c_0 after sanitising and firefly suppression (3 ch)
    ImageView fireflyFlag;   // optional: 1 where a firefly was clamped (1 ch)
    ImageView sureS;         // optional: s_i per level (levels channels)
    StageClock* clock = nullptr;  // optional: started by the caller, marked after each stage
    const DriverPlanes* planes = nullptr;  // optional: copy the prepared planes out and stop after step 3
    DriverReport* report = nullptr;        // optional (CPU): the firefly count and the luminance after it
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
    DenoiseOptions opts;  // opts.method is Eaw, Sure, Learned or Blend (Auto resolved by denoise())
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

// The report's luminance after the firefly pass (DriverReport): nothing on a device executor (its
// caller reduces the afterFirefly plane); the CpuExec overload (src/cpu/driver_cpu.cpp) sums the
// finite luminances of `c` per row in double, the rows in order.
template <class Exec>
void reportLuminance(const Exec&, const ImageView&, DriverReport&) {}
void reportLuminance(const CpuExec& exec, const ImageView& c, DriverReport& report);
// The report's count of clamped pixels: nothing on a device executor (its caller reduces the flag
// plane); the CpuExec overload counts the flags (1 where the pass, dense step included, clamped).
template <class Exec>
void reportFireflies(const Exec&, const ImageView&, DriverReport&) {}
void reportFireflies(const CpuExec& exec, const ImageView& flag, DriverReport& report);

// The caller's image behind `v` when it was handed over (3 channels, on `dev`, the view's very
// storage), moved out of *store; else an empty image.
inline Image takeStore(Image* store, const ImageView& v, Device dev) {
    if (!store || store->empty() || store->device() != dev || store->channels() != 3 || store->data() != v.data ||
        store->width() != v.width || store->height() != v.height)
        return Image();
    return std::move(*store);
}

// Blend's mean: c = ((c + d) + l) / 2, d (SURE's kept detail sum) when valid.
struct BlendMean {
    ImageView c, d, l;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int k = 0; k < 3; ++k) {
            const float sureF = d.valid() ? c(x, y, k) + d(x, y, k) : c(x, y, k);
            c(x, y, k) = 0.5f * (sureF + l(x, y, k));
        }
    }
};

// After a registered method's cascade: a sample it left non-finite is the prepared input's (NaN
// and Inf never reach an output, whatever a plug-in computes).
struct FiniteOr {
    ImageView out, fallback;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int k = 0; k < 3; ++k)
            if (!finite(out(x, y, k))) out(x, y, k) = fallback(x, y, k);
    }
};

// A registered method's cascade, its errors named after the method: an InputError stays one, any
// other exception (or a throw of something that is no std::exception) becomes a RuntimeError.
inline void callCascade(const StillCascade& cascade, const char* name, const StillPlanes& P, const DenoiseOptions& o,
                        const ImageView& out) {
    const std::string who = std::string("method '") + name + "': ";
    try {
        cascade(P, o, out);
    } catch (const InputError& e) {
        throw InputError(who + e.what());
    } catch (const std::exception& e) {
        throw RuntimeError(who + e.what());
    } catch (...) {
        throw RuntimeError(who + "its cascade threw something that is not a std::exception");
    }
}

// Memory (docs/architecture.md, "Memory"): every temporary is allocated without a zero fill
// (each is written whole before it is read), once per call (the cascade's planes live through it:
// nothing is allocated per level), and dead planes are reused: the variance's buffer becomes EAW's
// second cascade buffer once the colour scale is taken from it, the emission filter ping-pongs
// through the emission's own copy, and the albedo give-back's window sums live in the cascade's
// spare buffer and the σ planes. On the CPU the sanitise and firefly passes work in place, and
// with DriverInputs' stores (denoise() on DenoiseBuffers) in the caller's images.
template <class Exec>
void runDenoise(const Exec& exec, const DriverInputs& in, const DriverConfig& cfg, const DriverOutputs& out) {
    const int w = in.color.width, h = in.color.height;
    const Device dev = exec.device();
    const DenoiseOptions& o = cfg.opts;
    // Blend runs the learned cascade and then SURE's on the same prepared planes (the features
    // prepared as for SURE, which reads more of them) and averages the two before remodulation.
    const bool blend = o.method == DenoiseMethod::Blend;
    const bool sure = o.method == DenoiseMethod::Sure || blend;
    const bool learned = o.method == DenoiseMethod::Learned;  // the learned method alone
    const DenoiseMethodInfo& info = denoiseMethodInfo(o.method);
    const bool network = info.usesWeights;  // the learned cascade runs
    const int levels = o.eaw.levels;
    constexpr bool kHost = std::is_same<Exec, CpuExec>::value;
    // A registered method's cascade (registerDenoiseMethod) in place of stages 4-5 (denoise()
    // has checked that it has one for this device). It reads every feature given, and no zeros.
    const StillCascade* own = info.registered() ? (kHost ? &info.cpu : &info.cuda) : nullptr;
    const bool givenOnly = learned || own;  // the features as given (invalid when absent)
    // The CPU row engine compiles the depth and id terms out when they are off: their planes are
    // then never read (the functor path, CUDA's and the tests' reference, reads them whatever).
    bool rowEngine = false;
    if constexpr (kHost) rowEngine = atrousCpuFastPath();
    auto planes = [&](int channels) { return Image::uninitialized(w, h, channels, dev); };
    const bool noise = !cfg.varianceGiven && cfg.noiseRadius > 0;

    // 1. Non-finite samples and features. c_0 and var(c_0): the caller's images when handed over
    // (then only scanned, and repaired in place where not finite), else copies.
    Image c0 = takeStore(in.colorStore, in.color, dev);
    if (c0.empty()) c0 = planes(3);
    // (A handed-over variance that denoise() dropped, all zero, still serves as var(c_0)'s storage.)
    Image v0 = in.varianceStore ? takeStore(in.varianceStore, in.variance.valid() ? in.variance : in.varianceStore->view(), dev)
                                : Image();
    if (v0.empty()) v0 = planes(3);
    runSanitizeColor(exec, SanitizeColor{in.color, in.variance, c0.view(), in.variance.valid() ? v0.view() : ImageView{}});
    // The albedo the demodulation divides by, sanitised once (the noise estimate reads it too).
    // Rims beside black albedo count their uncovered part as unmodulated, weighted by how much of
    // their colour the black neighbour explains (RimAlbedo, prepass.h).
    ImageView albedo = o.demodulate ? in.albedo : ImageView{};
    Image albedoStore, rimStore;
    if (albedo.valid()) albedo = sanitizedFeature(exec, albedo, w, h, 3, albedoStore);
    if (albedo.valid() && o.albedoFloor > 0.0f)
        albedo = rimAlbedo(exec, RimAlbedo{albedo, {}, c0.view(), in.emission, kBlackAlbedoFraction * o.albedoFloor}, rimStore);
    if (!in.variance.valid() || (noise && albedo.valid())) {
        // The global estimate in the colour's units, σ_c² a'_c² (noise_estimate.h): without an albedo
        // the constant σ_c², which the GPU path passes in as the variance.
        GlobalVariance gv;
        for (int c = 0; c < 3; ++c) gv.floorVar[c] = cfg.noiseFloorVar[c];
        gv.eps = o.albedoEpsilon;
        gv.floor = o.albedoFloor;
        gv.albedo = albedo;
        gv.var = v0.view();
        runGlobalVariance(exec, gv);
    }
    // Features: sanitised copies (on the CPU the buffers themselves when already clean), zeros
    // when absent (the level reads normal and position whatever).
    Image emissionStore, emissionA, emissionB;
    ImageView emission;
    if (in.emission.valid()) {
        // Filter the reflected part only: c_0 = color - emission (emission added back at the end).
        emission = sanitizedFeature(exec, in.emission, w, h, 3, emissionStore);
        exec.forEachPixel(w, h, SubtractEmission{emission, c0.view()});
        // The emission added back is filtered along emitter edges (filters/emission_filter.h),
        // between a new buffer and the emission's copy (or the caller's image, handed over): its
        // input is read by the first level only.
        if (o.eaw.emissionLevels > 0) {
            emissionA = planes(3);
            ImageView b;
            if (!emissionStore.empty()) {
                b = emissionStore.view();
            } else {
                emissionB = takeStore(in.emissionStore, in.emission, dev);
                if (emissionB.empty()) emissionB = planes(3);
                b = emissionB.view();
            }
            emission = runEmissionFilter(exec, o.eaw.emissionLevels, o.eaw.emissionScale, v0.view(), emission,
                                         emissionA.view(), b);
            if (emission.data != emissionA.data()) emissionA = Image();  // the other buffer holds it
            else emissionStore = Image(), emissionB = Image();
        }
    }
    // (The learned method reads no position, and a normal only when given: no zero planes for it.)
    Image normalStore, positionStore, depthStore, idsStore;
    const ImageView normal = givenOnly && !in.normal.valid() ? ImageView{} : sanitizedFeature(exec, in.normal, w, h, 3, normalStore);
    const ImageView position = learned || (own && !in.position.valid()) ? ImageView{}
                                                                         : sanitizedFeature(exec, in.position, w, h, 3, positionStore);
    // Depth: for the learned network, the depth stop, the noise estimate's edge test, a registered cascade.
    const bool depthStop = !givenOnly && o.eaw.sigmaDepth > 0 && in.depth.valid();
    const bool needDepth = network || own || depthStop || noise || out.planes;
    ImageView depth;
    if (needDepth && in.depth.valid()) depth = sanitizedFeature(exec, in.depth, w, h, 1, depthStore);
    else if (!rowEngine && !givenOnly) depth = sanitizedFeature(exec, ImageView{}, w, h, 1, depthStore);  // zeros
    const bool idStop = !learned && o.eaw.useIds && in.ids.valid();  // (a registered cascade: the ids given)
    ImageView ids;
    if (idStop) ids = sanitizedFeature(exec, in.ids, w, h, 2, idsStore);
    else if (!rowEngine && !givenOnly) ids = sanitizedFeature(exec, ImageView{}, w, h, 2, idsStore);  // zeros
    markStage(out.clock, "sanitize");

    // 2. Fireflies (before demodulation: the outlier is in radiance), into new planes: c_0 and
    // var(c_0) are free afterwards, and hold y (the give-back's and safety net's input) and the
    // σ planes.
    Image cA, vA, spareC, spareV;
    if (o.firefly.enabled) {
        cA = planes(3), vA = planes(3);
        // The flags (the caller's plane, else a scratch one) feed the dense-firefly step.
        Image flagStore = out.fireflyFlag.valid() ? Image{} : planes(1);
        const ImageView flag = out.fireflyFlag.valid() ? out.fireflyFlag : flagStore.view();
        const FireflyClamp pass{o.firefly.k, cfg.varianceGiven ? 1 : 0, c0.view(), v0.view(), cA.view(), vA.view(), flag};
        runFireflyClamp(exec, pass);
        {
            Image tmp = planes(1), sums = planes(1);
            runFireflyDense(exec, pass, tmp.view(), sums.view());
        }
        if (out.report) reportFireflies(exec, flag, *out.report);
        spareC = std::move(c0), spareV = std::move(v0);
    } else {
        cA = std::move(c0), vA = std::move(v0);
    }
    if (out.afterFirefly.valid()) exec.forEachPixel(w, h, Copy3{cA.view(), out.afterFirefly});
    if (out.report) reportLuminance(exec, cA.view(), *out.report);
    markStage(out.clock, "fireflies");

    // 3. Albedo demodulation, then (without a variance buffer) the variance from the colour
    // itself, after the emission is taken out and the fireflies clamped with the global estimate
    // so that they do not raise it (noise_estimate.h): of the demodulated colour, and demodulated.
    if (albedo.valid()) {
        Demodulate d;
        d.rule = stillAlbedoRule(o);
        d.albedo = albedo;
        d.in = d.out = cA.view();
        if (!noise) d.var = vA.view();
        runDemodulate(exec, d);
    }
    if (noise) {
        markStage(out.clock, "demodulate");
        LocalNoise ln;
        ln.radius = cfg.noiseRadius;
        for (int c = 0; c < 3; ++c) {
            ln.floorVar[c] = cfg.noiseFloorVar[c];
            ln.maxDiff2[c] = kNoiseEdgeSigmas2 * kNoiseCapMul * cfg.noiseFloorVar[c];
        }
        ln.capMul = kNoiseCapMul;
        ln.eps = o.albedoEpsilon;
        ln.floor = o.albedoFloor;
        ln.color = cA.view();
        ln.normal = in.normal.valid() ? normal : ImageView{};
        ln.depth = in.depth.valid() ? depth : ImageView{};
        ln.albedo = albedo;
        ln.var = vA.view();
        // Its energy plane: var(c_0)'s buffer, free since the firefly pass (the σ planes come later).
        if (!spareV.empty()) ln.scratch = spareV.view();
        runLocalNoise(exec, ln);
    }
    const char* const demodStage = noise ? "noise estimate" : "demodulate";
    if (out.planes) {
        const DriverPlanes& P = *out.planes;
        if (P.d.valid()) exec.forEachPixel(w, h, Copy3{cA.view(), P.d});
        if (P.var.valid()) exec.forEachPixel(w, h, Copy3{vA.view(), P.var});
        if (P.albedo.valid() && albedo.valid()) exec.forEachPixel(w, h, Copy3{albedo, P.albedo});
        if (P.normal.valid() && in.normal.valid()) exec.forEachPixel(w, h, Copy3{normal, P.normal});
        if (P.depth.valid() && in.depth.valid()) exec.forEachPixel(w, h, CopyChannels<1>{depth, P.depth});
        if (P.mod.valid()) exec.forEachPixel(w, h, ModulationOf{stillAlbedoRule(o), albedo, P.mod});
        if (P.emission.valid() && emission.valid()) exec.forEachPixel(w, h, Copy3{emission, P.emission});
        markStage(out.clock, demodStage);
        exec.synchronize();
        return;
    }
    // The safety net's input y and its summed variance, kept before the cascade overwrites them.
    // The albedo give-back reads the same y. With the learned cascade, after it (it only reads y),
    // when its own temporaries are gone: Blend's peak is then SURE's plus one plane set.
    const bool giveBack = cfg.albedoGiveBack && !givenOnly && albedo.valid();
    Image safetyIn, safetyVar;
    auto keepInput = [&] {
        if (o.safety.enabled || giveBack) {
            safetyIn = spareC.empty() ? planes(3) : std::move(spareC);
            runCopy3(exec, cA.view(), safetyIn.view());
        }
        if (o.safety.enabled) {
            safetyVar = planes(1);
            exec.forEachPixel(w, h, SafetyVariance{vA.view(), safetyVar.view()});
        }
    };
    if (!network) keepInput();
    markStage(out.clock, demodStage);

    // 4-5. The learned method: its cascade (filters/learned.h) on the prepared planes, d_out in
    // `learnedOut`; a feature that was not given is an invalid plane (the network reads it as absent).
    Image* cur = &cA;
    Image cB, vB, detail, boxH, acc, learnedOut, sigmas, invZ;
    if (network) {
        // (Its inputs are read only: Blend's SURE cascade then starts from the same planes.)
        learnedOut = spareC.empty() ? planes(3) : std::move(spareC);
        const LearnedPlanes P{cA.view(), vA.view(), albedo, in.normal.valid() ? normal : ImageView{},
                              in.depth.valid() ? depth : ImageView{}};
        runLearned(exec, cfg.learned, P, learnedOut.view());
        if (learned) cur = &learnedOut;
        markStage(out.clock, "learned");
        keepInput();
        if (o.safety.enabled || giveBack) markStage(out.clock, "keep input");
    }
    if (own) {
        // 4-5. A registered method's cascade, into learnedOut's planes.
        learnedOut = spareC.empty() ? planes(3) : std::move(spareC);
        // (A clean feature may be the caller's own image, with more channels than it stands for.)
        auto first = [](ImageView v, int n) { return v.valid() ? ImageView{v.data, v.width, v.height, n} : v; };
        StillPlanes P;
        P.device = dev;
        const DenoiseBufferUse& reads = info.reads;  // what the method reads of what was given
        P.color = cA.view(), P.variance = vA.view(), P.albedo = reads.albedo ? first(albedo, 3) : ImageView{};
        P.normal = reads.normal ? first(in.normal.valid() ? normal : ImageView{}, 3) : ImageView{};
        P.position = reads.position ? first(in.position.valid() ? position : ImageView{}, 3) : ImageView{};
        P.depth = reads.depth ? first(in.depth.valid() ? depth : ImageView{}, 1) : ImageView{};
        P.ids = reads.ids ? first(ids, 2) : ImageView{};
        callCascade(*own, info.name, P, o, learnedOut.view());
        exec.forEachPixel(w, h, FiniteOr{learnedOut.view(), cA.view()});
        cur = &learnedOut;
        markStage(out.clock, info.name);
    }
    if (!givenOnly) {
        // 4. Per-pixel scales of the automatic σ_c and σ_x (1/σ_z only for the depth stop). The
        // colour scale S, 1/σ_x² and each level's 1/σ_c² factors (EawLevel::rS) are the three planes
        // of `sigmas`, var(c_0)'s buffer when the firefly pass freed it.
        sigmas = spareV.empty() ? planes(3) : std::move(spareV);
        const ImageView S{sigmas.view().channel(0), w, h, 1}, invX{sigmas.view().channel(1), w, h, 1},
            rS{sigmas.view().channel(2), w, h, 1};
        if (depthStop || !rowEngine) invZ = planes(1);
        runColorScale(exec, ColorScale{o.eaw.sigmaColor, o.eaw.colorScale * o.eaw.colorScale, vA.view(), S});
        runFootprint(exec, Footprint{in.position.valid() ? 1 : 0, o.eaw.sigmaPosition,
                                     o.eaw.positionScale * o.eaw.positionScale, position, depth, invX,
                                     invZ.empty() ? ImageView{} : invZ.view()});
        markStage(out.clock, "sigma scales");

        // 5. The cascade. SURE also propagates the variance and keeps Σ s_i d_i in `acc`. EAW's
        // second buffer is the variance's, dead once S is taken from it.
        float alpha[kMaxLevels];
        for (int i = 0; i < kMaxLevels; ++i) alpha[i] = 1.0f;
        SureChoiceParams choice;
        if (sure) {
            cB = planes(3), vB = planes(3);  // fully overwritten by level 0
            detail = planes(2);
            if (!kHost) boxH = planes(2);  // the CPU's window passes keep a ring of rows instead
            acc = Image(w, h, 3, dev);  // zeros: Σ s_i d_i
            if (o.sure.correlatedVariance) sureDetailVarianceFactors(levels, alpha);
            choice.radius = o.sure.windowRadius;
            choice.jamesStein = o.sure.mode == SureMode::JamesStein ? 1 : 0;
            choice.count = int(o.sure.candidates.size());
            for (int k = 0; k < choice.count && k < kMaxSureCandidates; ++k) choice.candidates[k] = o.sure.candidates[k];
        } else {
            cB = std::move(vA);
        }
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
            lp.invDepth = depthStop ? 1.0f / (o.eaw.sigmaDepth * o.eaw.sigmaDepth) : 0.0f;
            lp.idPenalty = idStop ? kIdPenalty : 0.0f;
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
            f.S = S;
            f.rS = rS;
            f.normal = normal;
            f.position = position;
            f.invX = invX;
            f.depth = depth;
            f.invZ = invZ.empty() ? ImageView{} : invZ.view();
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
                    const ImageView bh = boxH.empty() ? ImageView{} : boxH.view();  // none on the CPU
                    ImageView sOut;
                    if (out.sureS.valid()) sOut = ImageView{out.sureS.channel(i), w, h, 1};
                    SureChoiceParams levelChoice = choice;
                    if (dropped) {
                        levelChoice.jamesStein = 0;
                        levelChoice.count = 1;
                        levelChoice.candidates[0] = 0.0f;
                    }
                    runSureWindow(exec, SureBoxH{choice.radius, detail.view(), bh},
                                  SureChoose{levelChoice, bh, cur->view(), nxt->view(), acc.view(), sOut});
                }
                markStage(out.clock, "sure", i);
                std::swap(vcur, vnxt);
            }
            std::swap(cur, nxt);
        }
    }

    // 6. The albedo give-back, F' = F + the part of y - F that the albedo explains (stage
    // "give-back"), then the safety net: F' = F + s (y - F), s chosen by SURE on the residual
    // (safety_net.h).
    ImageView detailSum = sure ? acc.view() : ImageView{};
    if (giveBack) {
        // Its window sums in planes the cascade is done with: the spare cascade buffer and the σ
        // planes (6 planes).
        Image* spare = cur == &cA ? &cB : &cA;
        GiveBackScratch scratch;
        int n = 0;
        for (Image* p : {spare, &sigmas})
            for (int c = 0; c < 3 && !p->empty(); ++c) scratch.plane[n++] = p->view().channel(c);
        scratch.count = n;
        runAlbedoGiveBack(exec, safetyIn.view(), cur->view(), detailSum, albedo, kGiveBackRadius, kGiveBackSignificance,
                          n == 6 ? &scratch : nullptr);
        detailSum = ImageView{};
        markStage(out.clock, "give-back");
    }
    if (blend) {
        // F = (SURE's F + the learned F) / 2, in the demodulated units (remodulation is linear).
        exec.forEachPixel(w, h, BlendMean{cur->view(), detailSum, learnedOut.view()});
        detailSum = ImageView{};
        learnedOut = Image();
        markStage(out.clock, "blend");
    }
    if (o.safety.enabled) {
        if (detail.empty()) detail = planes(2);
        if (boxH.empty()) boxH = planes(2);
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
            Image ratio = planes(1);
            exec.forEachPixel(w, h, SafetyRatio{sp.radius, boxH.view(), ratio.view()});
            kappa = std::fmax(1.0f, medianFinite(exec, ratio.view(), 1.0f));
        }
        exec.forEachPixel(w, h, SafetyBlend{sp, kappa, o.safety.trigger, boxH.view(), safetyIn.view(), cur->view(), detailSum, ImageView{}});
        detailSum = ImageView{};
        markStage(out.clock, "safety net");
    }

    // 7. out = (c_N + Σ s_i d_i) · albedo + the filtered emission: into out.out, or in place.
    Remodulate r;
    r.rule = stillAlbedoRule(o);
    r.base = cur->view(), r.detail = detailSum, r.albedo = albedo, r.emission = emission;
    r.out = out.out.valid() ? out.out : cur->view();
    runRemodulate(exec, r);
    markStage(out.clock, "remodulate");
    exec.synchronize();
    if (!out.out.valid() && out.result) *out.result = std::move(*cur);
}

}  // namespace atrous::filters

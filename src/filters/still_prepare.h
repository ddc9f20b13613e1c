// The still path's preparation (docs/architecture.md, "The still path"), the same for every
// method: sanitise (non-finite samples and features, the rim albedo, the global variance
// estimate), the emission split and its filter, fireflies, demodulation and the local noise
// estimate. Written once as templates on the executor (CpuExec, CudaExec).
#pragma once
#include "filters/emission_filter.h"
#include "filters/firefly_restore.h"
#include "filters/noise_estimate.h"
#include "filters/prepass.h"
#include "filters/still_state.h"

namespace atrous::filters {

// 1a. c_0 and var(c_0): the caller's images when handed over (then only scanned, and repaired in
// place where not finite), else new planes. Without a variance buffer var(c_0) is filled with the
// global estimate in the colour's units, σ_c² a'_c² (noise_estimate.h), once the albedo is known.
template <class Exec>
void sanitizeColor(const Exec& exec, const StillInputs& in, PlanePool& pool, Image& c0, Image& v0) {
    const Device dev = exec.device();
    c0 = takeStore(in.colorStore, in.color, dev);
    if (c0.empty()) c0 = pool.take(3);
    // (A handed-over variance that denoise() dropped, all zero, still serves as var(c_0)'s storage.)
    if (in.varianceStore)
        v0 = takeStore(in.varianceStore, in.variance.valid() ? in.variance : in.varianceStore->view(), dev);
    if (v0.empty()) v0 = pool.take(3);
    runSanitizeColor(exec, SanitizeColor{in.color, in.variance, c0.view(), in.variance.valid() ? v0.view() : ImageView{}});
}

// 1b. The albedo the demodulation divides by, sanitised once (the noise estimate reads it too).
// Rims beside black albedo count their uncovered part as unmodulated, weighted by how much of
// their colour the black neighbour explains (RimAlbedo, prepass.h).
template <class Exec>
void sanitizeAlbedo(const Exec& exec, const StillInputs& in, const DenoiseOptions& o, const Image& c0, Prepared& p) {
    const int w = in.color.width, h = in.color.height;
    ImageView albedo = o.demodulate ? in.albedo : ImageView{};
    if (albedo.valid()) albedo = sanitizedFeature(exec, albedo, w, h, 3, p.albedoStore);
    if (albedo.valid() && o.albedoFloor > 0.0f)
        albedo = rimAlbedo(exec, RimAlbedo{albedo, {}, c0.view(), in.emission, kBlackAlbedoFraction * o.albedoFloor}, p.rimStore);
    p.albedo = albedo;
}

// 1c. Without a variance buffer (or with the local estimate and an albedo): the global estimate
// into var(c_0), in the colour's units (without an albedo the constant σ_c², which the GPU path
// passes in as the variance).
template <class Exec>
void fillGlobalVariance(const Exec& exec, const StillInputs& in, const StillConfig& cfg, const Prepared& p, const Image& v0) {
    if (in.variance.valid() && !(p.noise && p.albedo.valid())) return;
    GlobalVariance gv;
    for (int c = 0; c < 3; ++c) gv.floorVar[c] = cfg.noiseFloorVar[c];
    gv.eps = cfg.opts.albedoEpsilon;
    gv.floor = cfg.opts.albedoFloor;
    gv.albedo = p.albedo;
    gv.var = v0.view();
    runGlobalVariance(exec, gv);
}

// 1d. The emission: c_0 = colour - emission (the reflected part is filtered; the emission is
// added back at the end), and the emission added back is filtered along emitter edges
// (emission_filter.h), between a new buffer and the emission's copy (or the caller's image,
// handed over): its input is read by the first level only.
template <class Exec>
void splitEmission(const Exec& exec, const StillInputs& in, const DenoiseOptions& o, PlanePool& pool, const Image& c0,
                   const Image& v0, Prepared& p) {
    if (!in.emission.valid()) return;
    const int w = in.color.width, h = in.color.height;
    ImageView emission = sanitizedFeature(exec, in.emission, w, h, 3, p.emissionStore);
    exec.forEachPixel(w, h, SubtractEmission{emission, c0.view()});
    if (o.eaw.emissionLevels > 0) {
        p.emissionA = pool.take(3);
        ImageView b;
        if (!p.emissionStore.empty()) {
            b = p.emissionStore.view();
        } else {
            p.emissionB = takeStore(in.emissionStore, in.emission, exec.device());
            if (p.emissionB.empty()) p.emissionB = pool.take(3);
            b = p.emissionB.view();
        }
        emission = runEmissionFilter(exec, o.eaw.emissionLevels, o.eaw.emissionScale, v0.view(), emission, p.emissionA.view(), b);
        if (emission.data != p.emissionA.data()) p.emissionA = Image();  // the other buffer holds it
        else p.emissionStore = Image(), p.emissionB = Image();
    }
    p.emission = emission;
}

// 1e. The features the call reads (`need`: the method's, and the noise estimate's normal and
// depth), sanitised: on the CPU the buffers themselves when already clean. A feature not given or
// not read stays invalid (a cascade that reads absent features as zeros makes its own).
template <class Exec>
void sanitizeFeatures(const Exec& exec, const StillInputs& in, BufferMask need, Prepared& p) {
    const int w = in.color.width, h = in.color.height;
    auto feature = [&](Buffer b, const ImageView& v, int channels, Image& store) {
        return need.has(b) && v.valid() ? sanitizedFeature(exec, v, w, h, channels, store) : ImageView{};
    };
    p.normal = feature(Buffer::Normal, in.normal, 3, p.normalStore);
    p.position = feature(Buffer::Position, in.position, 3, p.positionStore);
    p.depth = feature(Buffer::Depth, in.depth, 1, p.depthStore);
    p.ids = feature(Buffer::ObjectId, in.ids, 2, p.idsStore);
}

// 2. Fireflies (before demodulation: the outlier is in radiance), into new planes; c_0 and var(c_0)
// go back to the pool (the kept input, the σ planes). Without the pass, c_0 and var(c_0) are the
// prepared planes.
template <class Exec>
void clampFireflies(const Exec& exec, const StillConfig& cfg, PlanePool& pool, const StillOutputs& out, Image&& c0,
                    Image&& v0, Prepared& p) {
    const DenoiseOptions& o = cfg.opts;
    if (!o.firefly.enabled) {
        p.color = std::move(c0), p.variance = std::move(v0);
    } else {
        p.color = pool.take(3), p.variance = pool.take(3);
        // The flags (the caller's plane, else a scratch one) feed the dense-firefly step.
        Image flagStore = out.fireflyFlag.valid() ? Image{} : pool.take(1);
        const ImageView flag = out.fireflyFlag.valid() ? out.fireflyFlag : flagStore.view();
        const FireflyClamp pass{o.firefly.k, cfg.varianceGiven ? 1 : 0, c0.view(), v0.view(), p.color.view(), p.variance.view(), flag};
        runFireflyClamp(exec, pass);
        {
            Image tmp = pool.take(1), sums = pool.take(1);
            runFireflyDense(exec, pass, tmp.view(), sums.view());
            pool.give(std::move(tmp)), pool.give(std::move(sums));
        }
        if (out.report) reportFireflies(exec, flag, *out.report);
        pool.give(std::move(v0));
        if (o.firefly.restore) {
            // What the pass took, put back (firefly_restore.h); its difference image in c_0's
            // planes, which it no longer reads then (planes already touched: no page faults).
            Image share = pool.take(3), radius = pool.take(1);
            runFireflyRestore(exec, FireflyRestore{c0.view(), p.color.view(), flag, share.view(), c0.view(), radius.view(), {}});
            pool.give(std::move(share)), pool.give(std::move(radius));
        }
        pool.give(std::move(c0));
    }
    if (out.afterFirefly.valid()) exec.forEachPixel(p.color.width(), p.color.height(), Copy3{p.color.view(), out.afterFirefly});
    if (out.report) reportLuminance(exec, p.color.view(), *out.report);
}

// 3a. Albedo demodulation: c / a' and var / a'^2 (the variance only when it is not estimated next).
template <class Exec>
void demodulate(const Exec& exec, const DenoiseOptions& o, Prepared& p) {
    if (!p.albedo.valid()) return;
    Demodulate d;
    d.rule = stillAlbedoRule(o);
    d.albedo = p.albedo;
    d.in = d.out = p.color.view();
    if (!p.noise) d.var = p.variance.view();
    runDemodulate(exec, d);
}

// 3b. Without a variance buffer: the variance from the colour itself, after the emission is taken
// out and the fireflies clamped with the global estimate so that they do not raise it
// (noise_estimate.h): of the demodulated colour, and demodulated. Its energy plane is a spare
// plane when the firefly pass freed one (given back after).
template <class Exec>
void estimateLocalNoise(const Exec& exec, const StillInputs& in, const StillConfig& cfg, PlanePool& pool, Prepared& p) {
    LocalNoise ln;
    ln.radius = cfg.noiseRadius;
    for (int c = 0; c < 3; ++c) {
        ln.floorVar[c] = cfg.noiseFloorVar[c];
        ln.maxDiff2[c] = kNoiseEdgeSigmas2 * kNoiseCapMul * cfg.noiseFloorVar[c];
    }
    ln.capMul = kNoiseCapMul;
    ln.eps = cfg.opts.albedoEpsilon;
    ln.floor = cfg.opts.albedoFloor;
    ln.color = p.color.view();
    ln.normal = in.normal.valid() ? p.normal : ImageView{};
    ln.depth = in.depth.valid() ? p.depth : ImageView{};
    ln.albedo = p.albedo;
    ln.var = p.variance.view();
    Image scratch = pool.takeSpare(3);
    if (!scratch.empty()) ln.scratch = scratch.view();
    runLocalNoise(exec, ln);
    pool.give(std::move(scratch));
}

// The whole preparation, stages timed on out.clock. `need`: the features the call reads.
template <class Exec>
Prepared prepare(const Exec& exec, const StillInputs& in, const StillConfig& cfg, BufferMask need, PlanePool& pool,
                 const StillOutputs& out) {
    Prepared p;
    p.noise = !cfg.varianceGiven && cfg.noiseRadius > 0;
    if (p.noise) need = need.with(Buffer::Normal).with(Buffer::Depth);  // the estimate's edges
    Image c0, v0;
    sanitizeColor(exec, in, pool, c0, v0);
    sanitizeAlbedo(exec, in, cfg.opts, c0, p);
    fillGlobalVariance(exec, in, cfg, p, v0);
    splitEmission(exec, in, cfg.opts, pool, c0, v0, p);
    sanitizeFeatures(exec, in, need, p);
    markStage(out.clock, "sanitize");
    clampFireflies(exec, cfg, pool, out, std::move(c0), std::move(v0), p);
    markStage(out.clock, "fireflies");
    demodulate(exec, cfg.opts, p);
    if (p.noise) {
        markStage(out.clock, "demodulate");
        estimateLocalNoise(exec, in, cfg, pool, p);
    }
    return p;
}

// The stage name that ends the preparation (the clock's mark after it).
inline const char* preparedStage(const Prepared& p) { return p.noise ? "noise estimate" : "demodulate"; }

}  // namespace atrous::filters

// The still methods' cascades (docs/architecture.md, "The still path"), one per registry row's
// CascadeKind: EAW and SURE (the shared à-trous level with their edge stops, then the albedo
// give-back), the learned cascade, Blend (the learned and SURE cascades on one preparation, and
// their mean) and a registered row's own function. Each turns the prepared planes into the
// filtered colour in the demodulated units (Filtered); the finishing (still_finish.h) takes it
// from there. Templates on the executor.
#pragma once
#include <cmath>
#include <type_traits>

#include "filters/eaw.h"
#include "filters/learned.h"
#include "filters/prepass.h"
#include "filters/safety_net.h"
#include "filters/still_state.h"
#include "filters/sure.h"

namespace atrous::filters {

// α_i = true var(d_i) / independence-propagated var(d_i) for the unweighted B3 cascade on white
// noise (the closed form: sure_cpu.cpp; docs/algorithms-eaw-sure.md).
void sureDetailVarianceFactors(int levels, float* alpha);

// The input y the give-back and the safety net compare with, and its summed variance (the
// safety net's), copied before a cascade overwrites the prepared colour.
struct KeptInput {
    Image y, var;
};

template <class Exec>
KeptInput keepInput(const Exec& exec, const DenoiseOptions& o, bool giveBack, PlanePool& pool, const Prepared& p) {
    KeptInput k;
    const int w = pool.width(), h = pool.height();
    if (o.safety.enabled || giveBack) {
        k.y = pool.take(3);
        runCopy3(exec, p.color.view(), k.y.view());
    }
    if (o.safety.enabled) {
        k.var = pool.take(1);
        exec.forEachPixel(w, h, SafetyVariance{p.variance.view(), k.var.view()});
    }
    return k;
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

// The σ planes of the EAW stops: the colour scale S, 1/σ_x² and each level's 1/σ_c² factors (rS),
// three planes of one image, plus 1/z for the depth stop.
struct SigmaPlanes {
    Image planes, invZ;
    ImageView S, invX, rS;
};

// The features the EAW level reads, with zeros for the absent ones (the level reads normal and
// position whatever; the functor path, CUDA's and the tests' reference, reads depth and ids too,
// which the CPU row engine compiles out when their stops are off).
struct EawFeatures {
    ImageView normal, position, depth, ids;
    bool depthStop = false, idStop = false;
    Image zeros[4];
};

template <class Exec>
EawFeatures eawFeatures(const DenoiseOptions& o, const Prepared& p, const PlanePool& pool) {
    constexpr bool kHost = std::is_same<Exec, CpuExec>::value;
    bool rowEngine = false;
    if constexpr (kHost) rowEngine = atrousCpuFastPath();
    EawFeatures f;
    f.depthStop = o.eaw.sigmaDepth > 0 && p.depth.valid();
    f.idStop = p.ids.valid();  // prepared only when read: given, and the id stop on
    auto orZeros = [&](const ImageView& v, int channels, bool needed, Image& store) {
        if (v.valid() || !needed) return v;
        store = pool.zeroed(channels);
        return store.view();
    };
    f.normal = orZeros(p.normal, 3, true, f.zeros[0]);
    f.position = orZeros(p.position, 3, true, f.zeros[1]);
    f.depth = orZeros(p.depth, 1, !rowEngine, f.zeros[2]);
    f.ids = orZeros(f.idStop ? p.ids : ImageView{}, 2, !rowEngine, f.zeros[3]);
    return f;
}

// 4. Per-pixel scales of the automatic σ_c and σ_x (1/σ_z only for the depth stop, or for the
// functor path, which reads it whatever).
template <class Exec>
SigmaPlanes sigmaScales(const Exec& exec, const DenoiseOptions& o, const Prepared& p, const EawFeatures& f, PlanePool& pool) {
    constexpr bool kHost = std::is_same<Exec, CpuExec>::value;
    bool rowEngine = false;
    if constexpr (kHost) rowEngine = atrousCpuFastPath();
    const int w = pool.width(), h = pool.height();
    SigmaPlanes s;
    s.planes = pool.take(3);
    s.S = ImageView{s.planes.view().channel(0), w, h, 1};
    s.invX = ImageView{s.planes.view().channel(1), w, h, 1};
    s.rS = ImageView{s.planes.view().channel(2), w, h, 1};
    if (f.depthStop || !rowEngine) s.invZ = pool.take(1);
    runColorScale(exec, ColorScale{o.eaw.sigmaColor, o.eaw.colorScale * o.eaw.colorScale, p.variance.view(), s.S});
    runFootprint(exec, Footprint{p.position.valid() ? 1 : 0, o.eaw.sigmaPosition, o.eaw.positionScale * o.eaw.positionScale,
                                 f.position, f.depth, s.invX, s.invZ.empty() ? ImageView{} : s.invZ.view()});
    return s;
}

// The level parameters of level i.
inline EawLevelParams eawLevelParams(const DenoiseOptions& o, const EawFeatures& f, bool normalGiven, bool sure, int i,
                                     float alpha) {
    const float invSigmaN2 = o.eaw.sigmaNormal > 0 && normalGiven ? 1.0f / (o.eaw.sigmaNormal * o.eaw.sigmaNormal) : 0.0f;
    EawLevelParams lp;
    lp.step = 1 << i;
    lp.colorMul = std::pow(o.eaw.colorLevelFactor, 2.0f * float(i));
    lp.invNormal = o.eaw.normalStepScale ? invSigmaN2 / float(lp.step * lp.step) : invSigmaN2;
    lp.autoPosition = o.eaw.sigmaPosition > 0 ? 0 : 1;
    lp.invDepth = f.depthStop ? 1.0f / (o.eaw.sigmaDepth * o.eaw.sigmaDepth) : 0.0f;
    lp.idPenalty = f.idStop ? kIdPenalty : 0.0f;
    lp.propagate = sure ? 1 : 0;
    lp.detailVarScale = alpha;
    return lp;
}

// SURE's choice of the candidates from the options.
inline SureChoiceParams sureChoice(const DenoiseOptions& o) {
    SureChoiceParams choice;
    choice.radius = o.sure.windowRadius;
    choice.jamesStein = o.sure.mode == SureMode::JamesStein ? 1 : 0;
    choice.count = int(o.sure.candidates.size());
    for (int k = 0; k < choice.count && k < kMaxSureCandidates; ++k) choice.candidates[k] = o.sure.candidates[k];
    return choice;
}

// One SURE level's window passes: levels below sure.firstLevel keep s_i = 0 (their details are
// dropped, as in EAW; the per-level risk assumes independent levels, docs/algorithms-eaw-sure.md).
// Adding 0·d_i to acc is a no-op, so such a level runs no window passes unless its s_i map is
// asked for (it is then all 0).
template <class Exec>
void sureLevel(const Exec& exec, const DenoiseOptions& o, int i, const ImageView& detail, const ImageView& boxH,
               const ImageView& before, const ImageView& after, const ImageView& acc, const ImageView& sureS) {
    const bool dropped = i < o.sure.firstLevel;
    if (dropped && !sureS.valid()) return;
    SureChoiceParams choice = sureChoice(o);
    const int radius = choice.radius;
    if (dropped) choice.jamesStein = 0, choice.count = 1, choice.candidates[0] = 0.0f;
    const ImageView sOut = sureS.valid() ? ImageView{sureS.channel(i), before.width, before.height, 1} : ImageView{};
    runSureWindow(exec, SureBoxH{radius, detail, boxH}, SureChoose{choice, boxH, before, after, acc, sOut});
}

// 5. The EAW or SURE cascade on the prepared planes (which it overwrites), then the albedo
// give-back (F' = F + the part of y - F the albedo explains, safety_net.h). SURE also propagates
// the variance and keeps Σ s_i d_i in F's detail. EAW's second buffer is the variance's, dead once
// S is taken from it.
template <class Exec>
Filtered eawCascade(const Exec& exec, const StillConfig& cfg, bool sure, Prepared& p, PlanePool& pool,
                    const KeptInput& kept, const StillOutputs& out) {
    constexpr bool kHost = std::is_same<Exec, CpuExec>::value;
    const DenoiseOptions& o = cfg.opts;
    const int levels = o.eaw.levels;
    const EawFeatures f = eawFeatures<Exec>(o, p, pool);
    SigmaPlanes s = sigmaScales(exec, o, p, f, pool);
    markStage(out.clock, "sigma scales");
    float alpha[kMaxLevels];
    for (int i = 0; i < kMaxLevels; ++i) alpha[i] = 1.0f;
    Image cB, vB, detail, boxH, acc;
    if (sure) {
        cB = pool.take(3), vB = pool.take(3);  // fully overwritten by level 0
        detail = pool.take(2);
        if (!kHost) boxH = pool.take(2);  // the CPU's window passes keep a ring of rows instead
        acc = pool.zeroed(3);             // Σ s_i d_i
        if (o.sure.correlatedVariance) sureDetailVarianceFactors(levels, alpha);
    } else {
        cB = std::move(p.variance);
    }
    Image *cur = &p.color, *nxt = &cB, *vcur = &p.variance, *vnxt = &vB;
    for (int i = 0; i < levels; ++i) {
        EawLevel L;
        L.p = eawLevelParams(o, f, p.normal.valid(), sure, i, alpha[i]);
        L.cIn = cur->view(), L.cOut = nxt->view();
        if (sure) L.vIn = vcur->view(), L.vOut = vnxt->view(), L.detail = detail.view();
        L.S = s.S, L.rS = s.rS, L.invX = s.invX, L.invZ = s.invZ.empty() ? ImageView{} : s.invZ.view();
        L.normal = f.normal, L.position = f.position, L.depth = f.depth, L.ids = f.ids;
        runEawLevel(exec, L);
        markStage(out.clock, "level", i);
        if (sure) {
            sureLevel(exec, o, i, detail.view(), boxH.empty() ? ImageView{} : boxH.view(), cur->view(), nxt->view(),
                      acc.view(), out.sureS);
            markStage(out.clock, "sure", i);
            std::swap(vcur, vnxt);
        }
        std::swap(cur, nxt);
    }
    Filtered F;
    Image* spare = cur == &p.color ? &cB : &p.color;
    F.base = std::move(*cur);
    if (sure) F.detail = std::move(acc);
    if (cfg.albedoGiveBack && p.albedo.valid()) {
        // Its window sums in planes the cascade is done with: the spare cascade buffer and the σ
        // planes (6 planes).
        GiveBackScratch scratch;
        int n = 0;
        for (Image* q : {spare, &s.planes})
            for (int c = 0; c < 3 && !q->empty(); ++c) scratch.plane[n++] = q->view().channel(c);
        scratch.count = n;
        runAlbedoGiveBack(exec, kept.y.view(), F.base.view(), F.detailView(), p.albedo, kGiveBackRadius,
                          kGiveBackSignificance, n == 6 ? &scratch : nullptr);
        F.detail = Image();  // folded into base
        markStage(out.clock, "give-back");
    }
    pool.give(std::move(*spare));
    pool.give(std::move(s.planes));
    pool.give(std::move(detail));  // the safety net's planes
    pool.give(std::move(boxH));
    return F;
}

// The learned cascade (filters/learned.h) on the prepared planes, which it only reads (Blend's
// SURE cascade then starts from the same planes); a feature not given is an invalid plane (the
// network reads it as absent).
template <class Exec>
Filtered learnedCascade(const Exec& exec, const StillConfig& cfg, const Prepared& p, PlanePool& pool, const StillOutputs& out) {
    Filtered F;
    F.base = pool.take(3);
    PreparedView P;
    P.device = exec.device();
    P.color = p.color.view(), P.variance = p.variance.view(), P.albedo = p.albedo, P.normal = p.normal, P.depth = p.depth;
    runLearned(exec, cfg.learned, P, F.base.view());
    markStage(out.clock, "learned");
    return F;
}

// A cascade's errors named after the method: an InputError stays one, any other exception (or a
// throw of something that is no std::exception) becomes a RuntimeError.
inline void callCascade(const StillCascade& cascade, const char* name, const PreparedView& P, const DenoiseOptions& o,
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

// A registered row's cascade, given the planes of what it reads (a clean feature may be the
// caller's own image, with more channels than it stands for: the first ones). Its output's
// non-finite samples are replaced by the finishing (Filtered::fallback).
template <class Exec>
Filtered registeredCascade(const Exec& exec, const DenoiseMethodInfo& row, const StillConfig& cfg, const Prepared& p,
                           PlanePool& pool, const StillOutputs& out) {
    constexpr bool kHost = std::is_same<Exec, CpuExec>::value;
    auto first = [](ImageView v, int n) { return v.valid() ? ImageView{v.data, v.width, v.height, n} : v; };
    const BufferMask reads = methodReads(row, cfg.opts);
    PreparedView P;
    P.device = exec.device();
    P.color = p.color.view(), P.variance = p.variance.view();
    P.albedo = reads.has(Buffer::Albedo) ? first(p.albedo, 3) : ImageView{};
    P.normal = reads.has(Buffer::Normal) ? first(p.normal, 3) : ImageView{};
    P.position = reads.has(Buffer::Position) ? first(p.position, 3) : ImageView{};
    P.depth = reads.has(Buffer::Depth) ? first(p.depth, 1) : ImageView{};
    P.ids = reads.has(Buffer::ObjectId) ? first(p.ids, 2) : ImageView{};
    Filtered F;
    F.base = pool.take(3);
    callCascade(kHost ? row.cpu : row.cuda, row.name, P, cfg.opts, F.base.view());
    F.fallback = p.color.view();
    markStage(out.clock, row.name);
    return F;
}

}  // namespace atrous::filters

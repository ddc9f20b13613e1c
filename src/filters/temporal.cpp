// The offline sequence denoiser (include/atrous/temporal.h, docs/temporal.md): the CPU driver of
// the per-pixel stages in temporal_window.h, then a still method on the average.
#include "atrous/temporal.h"

#include <algorithm>
#include <map>
#include <string>
#include <cmath>

#include "atrous/error.h"
#include "atrous/params.h"
#include "core/parallel.h"
#include "atrous/timer.h"
#include "filters/firefly_restore.h"
#include "filters/prepass.h"
#include "filters/svgf_gbuffer.h"
#include "filters/temporal_window.h"

namespace atrous {

namespace svgf {
void checkFrame(const Frame& frame);  // svgf.cpp: sizes, channels, the colour's range
}

void validateTemporalParams(const TemporalParams& p) { validateParams(p, temporalParams()); }

static_assert(temporal::kStaticMotion == kTemporalStaticMotion, "temporal_window.h's copy of the static motion bound");

int temporalWindowRadius(const TemporalParams& p) {
    if (p.radius == 0 || p.causal) return p.radius;
    return std::max(p.radius, p.staticRadius);
}

void checkTemporalFrame(const Frame& frame) { svgf::checkFrame(frame); }

// A frame as the hops read it: its sanitised G-buffer and colour statistics, owned here.
struct PreparedFrame {
    Image depth, normal, ids, motion, grad, stats, color, emission, still;
    temporal::FrameViews views;
    // At least half of the frame's pixels moved less than kTemporalStaticMotion: the camera stood
    // still (TemporalParams::staticRadius applies to hops through this frame's motion). Where the
    // camera moves, a pixel that keeps its place on screen (an orbit's pivot) still sees its
    // highlights and reflections change.
    bool stillCamera = false;
};

struct TemporalCache::Impl {
    std::map<long long, PreparedFrame> frames;  // by the caller's frame id
    int width = 0, height = 0;
    bool stats = false;
    float fireflyK = 0.0f;
};
TemporalCache::TemporalCache() : mImpl(std::make_unique<Impl>()) {}
TemporalCache::~TemporalCache() = default;
TemporalCache::TemporalCache(TemporalCache&&) noexcept = default;
TemporalCache& TemporalCache::operator=(TemporalCache&&) noexcept = default;

namespace {

ImageView viewOf(const Image* img) { return img ? img->view() : ImageView{}; }

void prepare(const CpuExec& exec, const Frame& f, bool stats, float fireflyK, PreparedFrame& p) {
    const int w = f.color->width(), h = f.color->height();
    p.depth = Image::uninitialized(w, h, 1);
    p.normal = Image::uninitialized(w, h, 3);
    p.ids = Image::uninitialized(w, h, 1);
    p.motion = Image::uninitialized(w, h, 2);
    p.grad = Image::uninitialized(w, h, 2);
    exec.forEachPixel(w, h, svgf::SanitizeGbuffer{viewOf(f.depth), viewOf(f.normal), viewOf(f.ids), viewOf(f.motion),
                                                  p.depth.view(), p.normal.view(), p.ids.view(), p.motion.view()});
    exec.forEachPixel(w, h, svgf::DepthGradient{p.depth.view(), p.grad.view()});
    size_t still = 0;
    bool anyMotion = false;
    const size_t plane = p.motion.plane();
    for (size_t i = 0; i < plane; ++i) {
        const float mx = p.motion.data()[i], my = p.motion.data()[plane + i];
        still += std::fabs(mx) < kTemporalStaticMotion && std::fabs(my) < kTemporalStaticMotion;
        anyMotion = anyMotion || mx != 0.0f || my != 0.0f;
    }
    // A motion buffer of zeros only is what renderers write for an animation's first frame (no
    // previous frame): no sign of what moves, so not a still camera's.
    p.stillCamera = anyMotion && 2 * still >= plane;
    temporal::FrameViews& v = p.views;
    v.depth = p.depth.view(), v.normal = p.normal.view(), v.ids = p.ids.view(), v.motion = p.motion.view();
    v.grad = p.grad.view();
    p.still = Image::uninitialized(w, h, 1);
    v.still = p.still.view();
    exec.forEachPixel(w, h, temporal::StillAround{v});
    v.color = viewOf(f.color), v.albedo = viewOf(f.albedo), v.normalRaw = viewOf(f.normal);
    if (fireflyK > 0.0f) {
        // The still filters' firefly pass on the frame alone (no variance: the 3x3 spread only), so
        // that a neighbour's firefly, spread over 2x2 pixels by the bilinear taps, does not reach
        // the average as a blob their own firefly pass keeps.
        p.color = Image::uninitialized(w, h, 3);
        Image zero(w, h, 3), scratch = Image::uninitialized(w, h, 3), flag = Image::uninitialized(w, h, 1);
        filters::runFireflyClamp(exec, filters::FireflyClamp{fireflyK, 0, v.color, zero.view(), p.color.view(),
                                                             scratch.view(), flag.view()});
        // The emission is scaled with its colour: a firefly on a light (the sun seen through the
        // sky, where colour = emission) clamped in the colour alone would leave colour - emission,
        // which the still method filters, hugely negative in the average.
        if (f.emission) {
            p.emission = Image::uninitialized(w, h, 3);
            exec.forEachPixel(w, h, temporal::ScaleLikeColour{v.color, p.color.view(), viewOf(f.emission), p.emission.view()});
        }
        // What the clamp took, put back where clamped pixels are dense (as the still path does;
        // after the emission's scale, which reads the clamp's own factor). Of the reflected light
        // only, as in the still path (there the emission is split off before the pass): a clamped
        // sun's excess spread around it would be a glow of reflected light.
        Image radius = Image::uninitialized(w, h, 1);
        filters::FireflyRestore r{v.color, p.color.view(), flag.view(), scratch.view(), zero.view(), radius.view(), {}};
        Image before, after;
        if (f.emission) {
            before = Image::uninitialized(w, h, 3), after = Image::uninitialized(w, h, 3);
            exec.forEachPixel(w, h, filters::Copy3{v.color, before.view()});
            exec.forEachPixel(w, h, filters::SubtractEmission{viewOf(f.emission), before.view()});
            exec.forEachPixel(w, h, filters::Copy3{p.color.view(), after.view()});
            exec.forEachPixel(w, h, filters::SubtractEmission{p.emission.view(), after.view()});
            r.cIn = before.view(), r.cOut = after.view(), r.addTo = p.color.view();
        }
        filters::runFireflyRestore(exec, r);
        v.color = p.color.view();
    }
    v.emission = p.emission.empty() ? viewOf(f.emission) : p.emission.view();
    if (stats) {
        p.stats = Image::uninitialized(w, h, 3);
        v.stats = p.stats.view();
        exec.forEachPixel(w, h, temporal::DemodulatedLum{v});
        exec.forEachPixel(w, h, temporal::LocalStats{v});
    }
}

Image cloneOrEmpty(const Image* img) { return img ? img->clone() : Image(); }

// The frames lo .. hi of a window and what gatherTemporal reads of them.
struct WindowSpan {
    const std::vector<Frame>& frames;
    size_t center, lo, hi;
    const std::vector<long long>* ids;
    TemporalCache::Impl* cache;  // null: no cache
    // In the cache: it passed svgf::checkFrame (sizes, channels, the colour's range: a scan of
    // every value) when it was prepared, and an id names unchanged buffers: not scanned again.
    bool known(size_t i) const { return cache && cache->frames.count((*ids)[i]) > 0; }
};

// The cache holds what a frame's id was prepared into, for this size and these settings only.
void keepCacheFor(TemporalCache::Impl* cache, int w, int h, bool stats, float fireflyK) {
    if (!cache || (cache->width == w && cache->height == h && cache->stats == stats && cache->fireflyK == fireflyK))
        return;
    cache->frames.clear();
    cache->width = w, cache->height = h, cache->stats = stats, cache->fireflyK = fireflyK;
}

// The variance and position of frame i against the centre's: the same size and channels.
void checkExtraBuffers(const Frame& f, const Frame& c, size_t i, int w, int h) {
    for (const Image* extra : {f.variance, f.position}) {
        if (!extra) continue;
        const bool variance = extra == f.variance;
        const Image* theirs = variance ? c.variance : c.position;
        if (extra->width() != w || extra->height() != h || extra->channels() < 1 || extra->channels() != theirs->channels())
            throw InputError("temporal window: frame " + std::to_string(i) + ": its " + (variance ? "variance" : "position") +
                             " buffer differs in size or channels from the centre frame's colour or " +
                             (variance ? "variance" : "position"));
    }
}

// Every frame of the span is checked (unless the cache knows it) and must carry the centre's
// buffers (a missing one would read as a neutral default) at the centre's size.
void checkSpan(const WindowSpan& s, int w, int h) {
    const Frame& c = s.frames[s.center];
    if (!s.known(s.center)) svgf::checkFrame(c);
    auto same = [&](const Image* a, const Image* b) { return (a == nullptr) == (b == nullptr); };
    for (size_t i = s.lo; i <= s.hi; ++i) {
        const Frame& f = s.frames[i];
        if (i != s.center && !s.known(i)) svgf::checkFrame(f);
        if (f.color->width() != w || f.color->height() != h)
            throw InputError("temporal window: frame " + std::to_string(i) + " is " + std::to_string(f.color->width()) +
                             "x" + std::to_string(f.color->height()) + ", the centre frame " + std::to_string(w) + "x" +
                             std::to_string(h));
        if (!same(f.albedo, c.albedo) || !same(f.normal, c.normal) || !same(f.depth, c.depth) ||
            !same(f.ids, c.ids) || !same(f.motion, c.motion) || !same(f.emission, c.emission) ||
            !same(f.variance, c.variance) || !same(f.position, c.position))
            throw InputError("temporal window: frame " + std::to_string(i) + " has other buffers than the centre frame");
        checkExtraBuffers(f, c, i, w, h);
    }
}

// The span's prepared frames, from the cache where it has them, else prepared now (into `local`
// without a cache, else into the cache, which then drops the frames outside the span: windows
// only move forward).
std::vector<PreparedFrame*> prepareSpan(const CpuExec& exec, const WindowSpan& s, bool stats, float fireflyK,
                                        std::vector<PreparedFrame>& local) {
    std::vector<PreparedFrame*> prepared(s.hi - s.lo + 1);
    if (!s.cache) local.resize(s.hi - s.lo + 1);
    for (size_t i = s.lo; i <= s.hi; ++i) {
        if (!s.cache) {
            prepare(exec, s.frames[i], stats, fireflyK, local[i - s.lo]);
            prepared[i - s.lo] = &local[i - s.lo];
            continue;
        }
        auto it = s.cache->frames.find((*s.ids)[i]);
        if (it == s.cache->frames.end()) {
            it = s.cache->frames.emplace((*s.ids)[i], PreparedFrame{}).first;
            prepare(exec, s.frames[i], stats, fireflyK, it->second);
        } else {
            // The derived planes are the cache's; the caller's own buffers are read where they are now.
            temporal::FrameViews& v = it->second.views;
            if (it->second.color.empty()) v.color = viewOf(s.frames[i].color);
            v.albedo = viewOf(s.frames[i].albedo), v.normalRaw = viewOf(s.frames[i].normal);
            v.emission = it->second.emission.empty() ? viewOf(s.frames[i].emission) : it->second.emission.view();
        }
        prepared[i - s.lo] = &it->second;
    }
    if (s.cache) {
        for (auto it = s.cache->frames.begin(); it != s.cache->frames.end();) {
            bool in = false;
            for (size_t i = s.lo; i <= s.hi && !in; ++i) in = (*s.ids)[i] == it->first;
            it = in ? std::next(it) : s.cache->frames.erase(it);
        }
    }
    return prepared;
}

// The weights and tests of hop k (from frame `from` to `to`, k frames from the centre).
void setHopWeights(temporal::Hop& hop, const TemporalParams& params, int staticRadius, size_t k, bool still) {
    const float fo = params.causal ? params.causalFalloff : params.falloff;
    hop.weight = k > size_t(params.radius) ? 0.0f : fo > 0.0f ? std::exp(-float(k * k) / (2.0f * fo * fo)) : 1.0f;
    // Static tracks: equal weights out to staticRadius (offline), else as the others. Both frames'
    // motion must show a still camera: a hop reads the motion of one of them and the G-buffers of both.
    hop.staticWeight = !params.causal && still && k <= size_t(staticRadius) ? 1.0f : hop.weight;
    // ... and whose G-buffer test also accepts the static surfaces next to the pixel.
    hop.stillHop = !params.causal && still && staticRadius > 0;
    hop.depthTolerance = params.depthTolerance, hop.normalCos = params.normalCos;
    hop.colorSigmas = params.colorSigmas;
}

// The tracks of one side of the centre (dir -1: the frames before it, +1: after), hop by hop out
// to r frames, each hop adding what it keeps to the sums in g.
void gatherSide(const CpuExec& exec, const WindowSpan& s, const std::vector<PreparedFrame*>& prepared, int dir,
                size_t r, const TemporalParams& params, int staticRadius, TemporalGather& g, Image& track, Image& alive) {
    const size_t center = s.center, lo = s.lo, hi = s.hi;
    if ((dir < 0 && center == lo) || (dir > 0 && center == hi)) return;
    const int w = g.color.width(), h = g.color.height();
    exec.forEachPixel(w, h, temporal::StartTracks{track.view(), alive.view()});
    for (size_t k = 1; k <= r; ++k) {
        if (dir < 0 ? center < lo + k : center + k > hi) break;
        const size_t from = dir < 0 ? center - k + 1 : center + k - 1, to = dir < 0 ? center - k : center + k;
        temporal::Hop hop;
        hop.from = prepared[from - lo]->views, hop.to = prepared[to - lo]->views, hop.centre = prepared[center - lo]->views;
        hop.to.variance = viewOf(s.frames[to].variance);
        hop.backward = dir < 0;
        setHopWeights(hop, params, staticRadius, k, prepared[from - lo]->stillCamera && prepared[to - lo]->stillCamera);
        hop.track = track.view(), hop.alive = alive.view();
        hop.sumColor = g.color.view(), hop.sumAlbedo = g.albedo.view(), hop.sumNormal = g.normal.view();
        hop.sumEmission = g.emission.view(), hop.sumVariance = g.variance.view(), hop.count = g.frames.view();
        exec.forEachPixel(w, h, hop);
    }
}

}  // namespace

TemporalGather gatherTemporal(const std::vector<Frame>& window, size_t center, const TemporalParams& params,
                              TemporalCache* cache, const std::vector<long long>* ids) {
    validateTemporalParams(params);
    if ((cache == nullptr) != (ids == nullptr) || (ids && ids->size() != window.size()))
        throw InputError("temporal window: a cache needs one id per frame of the window");
    if (center >= window.size()) throw InputError("temporal window: the centre frame is outside the window");
    const Frame& c = window[center];
    if (!c.color || c.color->empty()) svgf::checkFrame(c);  // throws: the colour is missing
    const int w = c.color->width(), h = c.color->height();
    // Frames without motion are taken as still, so nothing would tell a moving object from the
    // background: the static window needs every frame's motion.
    TemporalParams own = params;
    for (const Frame& f : window) own.staticRadius = f.motion ? own.staticRadius : 0;
    const size_t r = size_t(temporalWindowRadius(own));
    const size_t lo = center > r ? center - r : 0, hi = params.causal ? center : std::min(window.size() - 1, center + r);
    const bool stats = params.colorSigmas > 0.0f;
    TemporalCache::Impl* cached = cache ? cache->mImpl.get() : nullptr;
    keepCacheFor(cached, w, h, stats, params.fireflyK);
    const WindowSpan span{window, center, lo, hi, ids, cached};
    checkSpan(span, w, h);
    const CpuExec exec;
    TemporalGather g;
    g.albedo = cloneOrEmpty(c.albedo);
    g.normal = cloneOrEmpty(c.normal);
    g.emission = cloneOrEmpty(c.emission);
    g.variance = cloneOrEmpty(c.variance);
    g.frames = Image(w, h, 2);  // Σw and Σw² (Finish leaves the effective frame count in channel 0)
    g.frames.fill(1.0f);
    if (lo == hi) {
        g.color = c.color->clone();
        return g;
    }
    std::vector<PreparedFrame> local;
    const std::vector<PreparedFrame*> prepared = prepareSpan(exec, span, stats, params.fireflyK, local);
    // The centre's colour as its neighbours' is taken (after the firefly pass).
    const PreparedFrame& pc = *prepared[center - lo];
    g.color = pc.color.empty() ? c.color->clone() : pc.color.clone();
    if (!pc.emission.empty()) g.emission = pc.emission.clone();  // scaled with the colour's firefly clamp
    Image track(w, h, 2), alive(w, h, 1);
    for (int dir = -1; dir <= 1; dir += 2) gatherSide(exec, span, prepared, dir, r, params, own.staticRadius, g, track, alive);
    exec.forEachPixel(w, h, temporal::Finish{g.color.view(), g.albedo.view(), g.normal.view(), g.emission.view(),
                                             g.variance.view(), g.frames.view()});
    return g;
}

namespace {

Image denoiseTemporalWith(const std::vector<Frame>& window, size_t center, const TemporalParams& params,
                          const DenoiseOptions& spatial, TemporalReport* report, TemporalCache* cache,
                          const std::vector<long long>* ids) {
    Timer timer;
    TemporalGather g = gatherTemporal(window, center, params, cache, ids);
    if (report) {
        report->gatherMs = timer.ms();
        double sum = 0;
        for (size_t i = 0; i < g.frames.plane(); ++i) sum += g.frames.data()[i];  // channel 0
        report->meanFrames = sum / double(g.frames.plane());
    }
    const Frame& c = window[center];
    DenoiseBuffers b;
    b.color = &g.color;
    b.variance = g.variance.empty() ? nullptr : &g.variance;
    b.emission = g.emission.empty() ? nullptr : &g.emission;
    b.albedo = g.albedo.empty() ? nullptr : &g.albedo;
    b.normal = g.normal.empty() ? nullptr : &g.normal;
    b.position = c.position;
    b.depth = c.depth;
    b.ids = c.ids;
    if (!report) return denoise(b, spatial);
    DenoiseResult r = denoiseWithReport(b, spatial);
    report->spatial = std::move(r.report);
    return std::move(r.image);
}

}  // namespace

Image denoiseTemporal(const std::vector<Frame>& window, size_t center, const TemporalParams& params,
                      const DenoiseOptions& spatial, TemporalCache* cache, const std::vector<long long>* ids) {
    return denoiseTemporalWith(window, center, params, spatial, nullptr, cache, ids);
}

TemporalResult denoiseTemporalWithReport(const std::vector<Frame>& window, size_t center,
                                         const TemporalParams& params, const DenoiseOptions& spatial,
                                         TemporalCache* cache, const std::vector<long long>* ids) {
    TemporalResult r;
    r.image = denoiseTemporalWith(window, center, params, spatial, &r.report, cache, ids);
    return r;
}

}  // namespace atrous

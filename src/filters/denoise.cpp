// The denoise() entry points (include/atrous/denoise.h): resolve the method, check the inputs
// (still_inputs.cpp), and run the still path (still_pipeline.h) on the CPU or, through
// src/cuda/cuda_denoise.cu, on the GPU; preparePlanes, the preparation alone.
#include "atrous/denoise.h"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/interop.h"
#include "atrous/learned.h"
#include "atrous/timer.h"
#include "core/parallel.h"
#include "filters/denoise_internal.h"
#include "filters/still_pipeline.h"

namespace atrous {

// The ranges are params.h's table (one row per field); the library's own limits must agree.
static_assert(filters::kMaxLevels == 10 && filters::kMaxSureCandidates == 8, "update params.h's ranges");

namespace filters {

// α_i = true var(d_i) / independence-propagated var(d_i) for the unweighted B3 cascade on white
// noise. The 2D kernels are separable (K = k ⊗ k), so Σ K² = (Σ k²)² and
// Σ (K_i - K_{i+1})² = (Σ k_i²)² + (Σ k_{i+1}²)² - 2 (Σ k_i k_{i+1})², computed from 1D kernels.
void sureDetailVarianceFactors(int levels, float* alpha) {
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

static ImageView viewOf(const Image* img) { return img ? img->view() : ImageView{}; }

StillInputs stillInputs(const Frame& in, const CheckedInputs& checked) {
    StillInputs si;
    si.color = in.color->view();
    // Without a variance buffer the CPU path makes its own from the estimate (GlobalVariance); the
    // GPU path is given the constant estimate.
    si.variance = in.variance ? in.variance->view() : checked.estimatedVariance.view();
    si.albedo = viewOf(in.albedo);
    si.normal = viewOf(in.normal);
    si.position = viewOf(in.position);
    si.depth = viewOf(in.depth);
    si.ids = viewOf(in.ids);
    si.emission = viewOf(in.emission);
    return si;
}

StillConfig stillConfig(const Frame& in, const DenoiseOptions& o, const CheckedInputs& checked, const DenoiseReport& rep) {
    StillConfig cfg{o};
    cfg.learned = checked.learned;
    cfg.varianceGiven = in.variance != nullptr;
    setNoiseEstimate(cfg, rep);
    return cfg;
}

Image denoiseCpu(const Frame& in, const DenoiseOptions& o, const CheckedInputs& checked, DenoiseReport& rep,
                 StillDebug* debug, const DenoiseBuffers* handedOver) {
    StillInputs si = stillInputs(in, checked);
    if (handedOver) si.colorStore = handedOver->color, si.varianceStore = handedOver->variance, si.emissionStore = handedOver->emission;
    Image out;
    StillReport sr;
    StillOutputs sout;
    sout.result = &out;  // remodulated in the path's own planes
    sout.report = &sr;
    if (debug && !debug->sureS.empty()) sout.sureS = debug->sureS.view();
    // A steady-clock read per stage (stages take >= 0.1 ms): always on, it costs nothing measurable.
    std::unique_ptr<StageClock> clock = makeStageClock(Device::Cpu);
    sout.clock = clock.get();
    Timer t;
    clock->start();
    // Without a variance, the planes the preparation fills with the estimate (var(c_0)): a
    // handed-over variance that was dropped (all zero) serves, or one made here, which the global
    // estimate first uses for its detail planes (one 3-plane image, first touched once).
    Image estimate;
    if (!in.variance && !(handedOver && handedOver->variance && !handedOver->variance->empty())) {
        estimate = Image::uninitialized(in.color->width(), in.color->height(), 3);
        si.varianceStore = &estimate;
    }
    if (!in.variance && !checked.sigmaEstimated) {
        // The global estimate (Donoho's MAD), timed as a stage of its own.
        const Image* albedo = o.demodulate && in.albedo ? in.albedo : nullptr;
        estimateNoiseSigma(*in.color, albedo, o.albedoEpsilon, o.albedoFloor, rep.noiseSigma,
                           estimate.empty() ? si.varianceStore : &estimate);
        markStage(sout.clock, "noise sigma");
    }
    runStill(CpuExec{}, si, stillConfig(in, o, checked, rep), sout);
    rep.milliseconds = t.ms();
    clock->collect(rep.stages);
    rep.meanLuminanceIn = checked.meanLuminanceIn;
    // c_0 after the pass is colour − emission: the emission's mean is added back so that both
    // figures are of the whole image (with the sky as emission, they differed by the sky).
    rep.meanLuminanceAfterFirefly = (sr.lumAfterCount > 0 ? sr.lumAfterSum / sr.lumAfterCount : 0.0) +
                                    (in.emission ? checked.meanLuminanceEmission : 0.0);
    rep.firefliesClamped = sr.firefliesClamped;
    return out;
}

}  // namespace filters

namespace {

// What denoise() and preparePlanes() do before the still path: an all-zero variance dropped, the
// inputs checked and the noise estimated (on the CPU denoise() leaves the global estimate to
// denoiseCpu, which times it).
filters::CheckedInputs checkCall(Frame& inputs, const DenoiseOptions& options, DenoiseReport& rep,
                                 bool deferNoiseSigma = false) {
    rep = DenoiseReport{};
    // A host variance of 3 channels or more is tested in checkInputs' one scan of the inputs (then
    // dropped before its values are checked); any other as before, on its own.
    const bool fused = inputs.variance && inputs.color && !inputs.color->empty() &&
                       inputs.color->device() == Device::Cpu && inputs.variance->device() == Device::Cpu &&
                       inputs.variance->channels() >= 3;
    bool varianceIgnored = !fused && inputs.variance && inputs.color && !inputs.color->empty() &&
                           inputs.variance->view().sameSize(inputs.color->view()) &&
                           filters::varianceIsEmpty(*inputs.variance);
    if (varianceIgnored) inputs.variance = nullptr;  // estimate the noise from the image instead
    filters::CheckedInputs checked =
        filters::checkInputs(inputs, options, rep, deferNoiseSigma, fused ? &varianceIgnored : nullptr);
    if (varianceIgnored) {
        inputs.variance = nullptr;
        rep.varianceIgnored = true;
        rep.buffersUsed += ",variance(ignored: all zero, e.g. a 1-spp render; noise estimated)";
    }
    return checked;
}

void requireHostInputs(const Frame& inputs) {
    for (Buffer b : {Buffer::Color, Buffer::Variance, Buffer::Albedo, Buffer::Normal, Buffer::Position, Buffer::Depth,
                     Buffer::ObjectId, Buffer::Emission})
        if (const Image* img = inputs.get(b); img && img->device() != Device::Cpu)
            throw InputError("denoise on the CPU needs host images (got a CUDA image)");
}

// A method resolved (auto) and checked against the device: a registered row needs a cascade there.
DenoiseOptions resolvedOptions(const Frame& inputs, const DenoiseOptions& options) {
    DenoiseOptions o = options;
    o.method = resolveDenoiseMethod(options.method, inputs);
    const DenoiseMethodInfo& info = denoiseMethodInfo(o.method);
    if (info.registered() && !(o.device == Device::Cuda ? info.cuda : info.cpu))
        throw InputError(std::string("method '") + info.name + "' has no cascade for " +
                         (o.device == Device::Cuda ? "CUDA" : "the CPU"));
    return o;
}

// ids of one channel (the object id alone): the material id is then the same everywhere.
Image twoChannelIds(const Image& ids) {
    const Image host = ids.to(Device::Cpu);
    Image ids2(host.width(), host.height(), 2);
    std::copy(host.data(), host.data() + host.plane(), ids2.data());
    return ids.device() != Device::Cpu ? ids2.to(ids.device()) : std::move(ids2);
}

// A frame whose buffers given as strided memory (BufferRef) are Images: the colour, variance and
// emission converted into images handed over to the filter (it works in them: its first pass
// reads the caller's memory where it is, as it reads an Image's), the features copied into planar
// storage of their own (named in `copies`). A frame of Images is taken as it is.
struct ImportedFrame {
    Frame frame;
    Image owned[kBufferCount];
    DenoiseBuffers handOver;  // color non-null when the colour was converted
    std::vector<std::string> copies;
};

std::string layoutText(const StridedImage& s) {
    return std::string(s.type == DataType::Float16 ? "float16" : "float32") + ", " + std::to_string(s.channels) +
           (s.channels == 1 ? " channel" : " channels");
}

void importStrided(const Frame& given, const DenoiseBuffers* handedOver, ImportedFrame& f) {
    f.frame = given;
    bool strided = false;
    for (int i = 0; i < kBufferCount; ++i) strided = strided || (given.get(Buffer(i)) && !given.get(Buffer(i)).isImage());
    if (!strided) return;
    if (handedOver) throw InputError("denoise: handed-over buffers are Images, not strided memory");
    for (int i = 0; i < kBufferCount; ++i) {
        const Buffer b = Buffer(i);
        const BufferRef r = given.get(b);
        if (!r || r.isImage()) continue;
        StridedImage s = r.strided();
        const int channels = b == Buffer::Depth ? 1 : b == Buffer::ObjectId ? std::min(s.channels, 2)
                                                  : b == Buffer::Motion ? 2 : 3;
        s.channels = s.channels > channels ? channels : s.channels;  // the first ones (RGBA: RGB)
        const char* name = b == Buffer::ObjectId ? "ids" : bufferName(b);
        f.owned[i] = importImage(s, channels, name);
        f.frame.set(b, &f.owned[i]);
        if (b != Buffer::Color && b != Buffer::Variance && b != Buffer::Emission)
            f.copies.push_back(std::string(name) + " (" + layoutText(s) + ")");
    }
    // The colour, variance and emission converted are the filter's working planes (CPU).
    if (!given.color.isImage() && f.owned[int(Buffer::Color)].device() == Device::Cpu) {
        DenoiseBuffers& h = f.handOver;
        h.color = &f.owned[int(Buffer::Color)];
        if (!given.variance.isImage() && given.variance) h.variance = &f.owned[int(Buffer::Variance)];
        if (!given.emission.isImage() && given.emission) h.emission = &f.owned[int(Buffer::Emission)];
    }
}

// denoise() with, optionally, the caller's images handed over (used on the CPU only).
// timed: the CUDA path records its stages (denoiseWithReport; the CPU's clock costs nothing).
Image denoiseWith(const Frame& given, const DenoiseOptions& options, const DenoiseBuffers* handedOver, DenoiseReport& rep,
                  bool timed, filters::StillDebug* debug = nullptr) {
    ImportedFrame imported;
    importStrided(given, handedOver, imported);
    if (imported.handOver.color) handedOver = &imported.handOver;  // the converted colour, variance, emission
    Frame inputs = imported.frame;
    const DenoiseOptions o = resolvedOptions(inputs, options);
    filters::CheckedInputs checked = checkCall(inputs, o, rep, true);
    rep.copies = imported.copies;
    if (readsWeights(denoiseMethodInfo(o.method))) checked.learned = o.weights.impl ? o.weights : LearnedWeights::builtin();
    Image ids2;
    if (inputs.ids && inputs.ids->channels() == 1) {
        ids2 = twoChannelIds(*inputs.ids);
        inputs.ids = &ids2;
    }
    rep.methodUsed = o.method;
    if (o.device == Device::Cuda) {
        requireCuda();
        return filters::denoiseCuda(inputs, o, checked, rep, timed);
    }
    requireHostInputs(inputs);
    return filters::denoiseCpu(inputs, o, checked, rep, debug, handedOver);
}

Frame frameOf(const DenoiseBuffers& b) {
    Frame in;
    in.color = b.color, in.variance = b.variance, in.albedo = b.albedo, in.normal = b.normal;
    in.position = b.position, in.depth = b.depth, in.ids = b.ids, in.emission = b.emission;
    return in;
}

}  // namespace

DenoiseBuffers handOver(const Frame& frame, Image& color, Image* variance, Image* emission) {
    DenoiseBuffers b;
    b.color = &color;
    b.variance = variance && !variance->empty() ? variance : nullptr;
    b.emission = emission && !emission->empty() ? emission : nullptr;
    b.albedo = frame.albedo, b.normal = frame.normal, b.position = frame.position, b.depth = frame.depth;
    b.ids = frame.ids;
    return b;
}

Image denoise(const Frame& given, const DenoiseOptions& options) {
    DenoiseReport rep;
    return denoiseWith(given, options, nullptr, rep, false);
}

DenoiseResult denoiseWithReport(const Frame& given, const DenoiseOptions& options) {
    DenoiseResult r;
    r.image = denoiseWith(given, options, nullptr, r.report, true);
    return r;
}

Image denoise(DenoiseBuffers& buffers, const DenoiseOptions& options) {
    DenoiseReport rep;
    return denoiseWith(frameOf(buffers), options, &buffers, rep, false);
}

DenoiseResult denoiseWithReport(DenoiseBuffers& buffers, const DenoiseOptions& options) {
    DenoiseResult r;
    r.image = denoiseWith(frameOf(buffers), options, &buffers, r.report, true);
    return r;
}

SureFractionsResult denoiseWithSureFractions(const Frame& inputs, const DenoiseOptions& options) {
    if (options.method != DenoiseMethod::Sure || options.device != Device::Cpu)
        throw InputError("SURE's fractions: the method must be sure and the device the CPU");
    if (!inputs.color || inputs.color->empty()) throw InputError("missing color buffer");
    filters::StillDebug dbg;
    dbg.sureS = Image(inputs.color->width(), inputs.color->height(), options.eaw.levels);
    SureFractionsResult r;
    r.image = denoiseWith(inputs, options, nullptr, r.report, true, &dbg);
    r.fractions = std::move(dbg.sureS);
    return r;
}

PreparedView PreparedPlanes::view() const {
    auto v = [](const Image& i) { return i.empty() ? ImageView{} : i.view(); };
    PreparedView p;
    p.device = Device::Cpu;
    p.color = v(color), p.variance = v(variance), p.albedo = v(albedo), p.normal = v(normal), p.position = v(position);
    p.depth = v(depth), p.ids = v(ids), p.modulation = v(modulation), p.emission = v(emission);
    return p;
}

PreparedPlanes preparePlanes(const Frame& given, const DenoiseOptions& options) {
    ImportedFrame imported;  // buffers given as strided memory, as denoise() takes them
    importStrided(given, nullptr, imported);
    Frame in = imported.frame;
    DenoiseOptions o = options;
    o.device = Device::Cpu;
    o.method = resolveDenoiseMethod(options.method, in);
    DenoiseReport rep;
    const filters::CheckedInputs checked = checkCall(in, o, rep);
    requireHostInputs(in);
    Image ids2;
    if (in.ids && in.ids->channels() == 1) {
        ids2 = twoChannelIds(*in.ids);
        in.ids = &ids2;
    }
    const filters::StillConfig cfg = filters::stillConfig(in, o, checked, rep);
    const filters::StillInputs si = filters::stillInputs(in, checked);
    const CpuExec exec;
    filters::PlanePool pool(in.color->width(), in.color->height(), Device::Cpu);
    filters::Prepared p = filters::prepare(exec, si, cfg, filters::preparedFeatures(cfg), pool, filters::StillOutputs{});
    auto copy = [&](const ImageView& v, int channels) {
        if (!v.valid()) return Image();
        Image c = Image::uninitialized(v.width, v.height, channels);
        for (int k = 0; k < channels; ++k) std::copy(v.channel(k), v.channel(k) + v.plane(), c.view().channel(k));
        return c;
    };
    PreparedPlanes out;
    out.color = std::move(p.color), out.variance = std::move(p.variance);
    out.albedo = copy(p.albedo, 3), out.normal = copy(p.normal, 3), out.position = copy(p.position, 3);
    out.depth = copy(p.depth, 1), out.ids = copy(p.ids, 2);
    out.modulation = Image::uninitialized(in.color->width(), in.color->height(), 3);
    exec.forEachPixel(out.modulation.width(), out.modulation.height(),
                      filters::ModulationOf{filters::stillAlbedoRule(o), p.albedo, out.modulation.view()});
    out.emission = p.emission.valid() ? copy(p.emission, 3) : Image(in.color->width(), in.color->height(), 3);
    return out;
}

}  // namespace atrous

#if !defined(ATROUS_HAVE_CUDA)
namespace atrous::filters {
Image denoiseCuda(const Frame&, const DenoiseOptions&, const CheckedInputs&, DenoiseReport&, bool) { noCudaBackend(); }
void estimateNoiseSigmaCuda(const Image&, const Image*, float, float, float[3]) { noCudaBackend(); }
}  // namespace atrous::filters
#endif

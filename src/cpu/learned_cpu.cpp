// The learned filter v4 on the CPU (filters/learned.h): the context branch once for the whole image
// (src/cpu/learned_context_cpu.cpp), pass A per pixel (vectorised x loop),
// pass B row-wise (the 3x3 box as column sums once per row, then the MLP on 16 pixels at a time
// with the pixel index innermost: the lane loops of learnedMlp<16> become vector instructions),
// the five levels through the shared row engine (src/cpu/atrous_rows.h) with the LearnedStop
// policy. Every loop body is ISA-dispatched (cpu::parallelForIsa: baseline, AVX2, AVX-512). With
// atrousCpuFastPath() off, the functors of learned.h instead (the reference the tests compare).
#include <sys/mman.h>
#include <tbb/scalable_allocator.h>

#include <chrono>
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <memory>
#include <vector>

#include "atrous/error.h"
#include "core/parallel.h"
#include "cpu/atrous_rows.h"
#include "filters/learned.h"

namespace atrous::filters {

namespace {

constexpr int kLanes = 16;
constexpr uintptr_t kHuge = uintptr_t(2) << 20;

// Pass A over the flat pixel range [i0, i1) (LearnedLogPass's math, contiguous pointers).
struct LogRange {
    const float *r, *g, *b, *vr, *vg, *vb;
    float *lr, *lg, *lb, *L, *v;
    ATROUS_FORCE_INLINE void operator()(size_t i0, size_t i1) const {
        const float *ATROUS_RESTRICT R = r, *ATROUS_RESTRICT G = g, *ATROUS_RESTRICT B = b;
        const float *ATROUS_RESTRICT VR = vr, *ATROUS_RESTRICT VG = vg, *ATROUS_RESTRICT VB = vb;
        float *ATROUS_RESTRICT oR = lr, *ATROUS_RESTRICT oG = lg, *ATROUS_RESTRICT oB = lb, *ATROUS_RESTRICT oL = L,
                               *ATROUS_RESTRICT oV = v;
#pragma omp simd
        for (size_t i = i0; i < i1; ++i) {
            oR[i] = learnedLogColour(R[i]);
            oG[i] = learnedLogColour(G[i]);
            oB[i] = learnedLogColour(B[i]);
            oL[i] = learnedLum(R[i], G[i], B[i]);
            oV[i] = learnedVariance(VR[i], VG[i], VB[i]);
        }
    }
};

// Pass B over rows [y0, y1) of T and acc (h rows); P's rows start pOffset values further on (a
// band of rows: the band's first row in the image).
struct NetRows {
    const LearnedNet* net;
    PreparedView P;
    LearnedTemps T;
    ImageView acc;
    size_t pOffset = 0;
    LearnedTensor z;    // the context's z (whole image, 1/4 resolution); invalid: no context
    int rowOffset = 0;  // the band's first row in the image

    ATROUS_FORCE_INLINE void operator()(int y0, int y1) const {
        const int w = T.lg.width, h = T.lg.height;
        const size_t stride = size_t(w) + 2;
        const int zw = z.valid() ? z.width : 0;
        std::vector<float> buf(kLearnedBoxQ * stride + size_t(w) +
                               (zw ? size_t(kLearnedHidden) * (size_t(zw) + size_t(w)) : 0));
        float* V[kLearnedBoxQ];
        for (int k = 0; k < kLearnedBoxQ; ++k) V[k] = buf.data() + k * stride;
        float* inv = buf.data() + kLearnedBoxQ * stride;
        float* zr = inv + w;                           // z between its two rows for this row: zr[j * zw + X]
        float* zx = zr + size_t(kLearnedHidden) * zw;  // and between its columns: the row's shift, zx[j * w + x]
        for (int y = y0; y < y1; ++y) {
            const bool top = y > 0, bottom = y + 1 < h;
            const size_t o = size_t(y) * size_t(w);
            // Column sums (rows y - 1, y, y + 1 inside the image, added from 0 in that order), with
            // one zero column either side.
            for (int k = 0; k < kLearnedBoxQ; ++k) {
                const float* s = T.lg.channel(k < 4 ? k : 3) + o;
                float* ATROUS_RESTRICT v = V[k] + 1;
                v[-1] = 0.0f, v[w] = 0.0f;
                if (k < 4) {
                    for (int x = 0; x < w; ++x) v[x] = 0.0f;
                    if (top)
                        for (int x = 0; x < w; ++x) v[x] += s[x - w];
                    for (int x = 0; x < w; ++x) v[x] += s[x];
                    if (bottom)
                        for (int x = 0; x < w; ++x) v[x] += s[x + w];
                } else {
                    for (int x = 0; x < w; ++x) v[x] = 0.0f;
                    if (top)
                        for (int x = 0; x < w; ++x) v[x] += s[x - w] * s[x - w];
                    for (int x = 0; x < w; ++x) v[x] += s[x] * s[x];
                    if (bottom)
                        for (int x = 0; x < w; ++x) v[x] += s[x + w] * s[x + w];
                }
            }
            const int ny = 1 + int(top) + int(bottom);
            for (int x = 0; x < w; ++x) inv[x] = 1.0f / float((1 + int(x > 0) + int(x < w - 1)) * ny);
            if (zw) {  // the rows step of up4 (learnedCtxShift's order: rows first)
                const LearnedUpTap ty = learnedUpTap(rowOffset + y, kLearnedCell, z.height);
                for (int X = 0; X < zw; ++X) {
                    const float *a = z.at(X, ty.i0), *b = z.at(X, ty.i1);
                    for (int j = 0; j < kLearnedHidden; ++j) zr[j * zw + X] = a[j] * (1.0f - ty.t) + b[j] * ty.t;
                }
                for (int j = 0; j < kLearnedHidden; ++j) learnedUp4Row(zr + j * zw, zw, zx + size_t(j) * w, w);
            }
            for (int x0 = 0; x0 < w; x0 += kLanes) {
                const int n = w - x0 < kLanes ? w - x0 : kLanes;
                float in[kLearnedIn][kLanes], out[kLearnedOut][kLanes];
                learnedPointInputs<kLanes>(P, T.lg, o + size_t(x0), n, in, pOffset + o + size_t(x0));
                const float* const Vx[kLearnedBoxQ] = {V[0] + x0, V[1] + x0, V[2] + x0, V[3] + x0, V[4] + x0};
                learnedBoxInputs<kLanes>(Vx, inv + x0, n, in);
                if (zw) {
                    float shift[kLearnedHidden][kLanes];
                    for (int j = 0; j < kLearnedHidden; ++j) {
                        const float* r = zx + size_t(j) * w + x0;
                        for (int l = 0; l < kLanes; ++l) shift[j][l] = l < n ? r[l] : 0.0f;
                    }
                    learnedMlp<kLanes, true>(*net, in, out, shift);
                } else {
                    learnedMlp<kLanes>(*net, in, out);
                }
                learnedWriteOutputs<kLanes>(out, P.color, T, acc, o + size_t(x0), n, pOffset + o + size_t(x0));
            }
        }
    }
};

// Transparent huge pages where the kernel leaves them to madvise: the planes are first touched by
// the passes, and 4 KiB page faults cost ~15% of the cascade at 1080p (perf).
void adviseHugePages(float* p, size_t bytes) {
#ifdef MADV_HUGEPAGE
    const uintptr_t a = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
    const uintptr_t e = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
    if (e > a) madvise(reinterpret_cast<void*>(a), e - a, MADV_HUGEPAGE);
#else
    (void)p, (void)bytes;
#endif
}

// Wall and process CPU time since the last mark.
struct StageClock {
    std::chrono::steady_clock::time_point t = std::chrono::steady_clock::now();
    std::clock_t c = std::clock();
    void mark(double& wall, double& cpu) {
        const auto t1 = std::chrono::steady_clock::now();
        const std::clock_t c1 = std::clock();
        wall = std::chrono::duration<double>(t1 - t).count(), cpu = double(c1 - c) / CLOCKS_PER_SEC;
        t = t1, c = c1;
    }
};

}  // namespace

// The learned filter's temporaries are 42 planes (168 bytes a pixel): at 3840x2160 1.4 GB. Above
// kBandPixels pixels, a call without a cache (the still driver's) runs in bands of rows, each with
// the rows within kBandHalo of it (the five levels reach 62 rows, the network's 3x3 box one more):
// the temporaries are those of a band, ~40% of the image's at 4K. A band's rows get the same
// values as the whole image's (every value's inputs lie within its band's rows), so the output
// is bit-equal; the network runs again on the halo rows (at 4K, three bands: +17% of the network's
// work), the levels on the rows the next level reads only.
constexpr size_t kBandPixels = size_t(4) << 20;
constexpr size_t kBandCorePixels = size_t(2800) << 10;
constexpr int kBandHalo = 2 * ((1 << kLearnedLevels) - 1) + 1;

int& learnedCpuBandRows() {
    static int rows = 0;
    return rows;
}

void runLearned(const CpuExec& exec, const LearnedWeights& weights, const PreparedView& in, const ImageView& out,
                LearnedStageTimes* times, LearnedCache* cache) {
    checkLearnedPlanes(weights, in, out);
    const int w = in.color.width, h = in.color.height;
    StageClock clock;
    double unused = 0;
    const int forced = learnedCpuBandRows();
    const bool banded = !cache && atrousCpuFastPath() &&
                        (forced > 0 ? forced < h : forced == 0 && size_t(w) * size_t(h) > kBandPixels);
    const int core = !banded ? h : forced > 0 ? forced : std::max(64, int(kBandCorePixels / size_t(w)));
    const int regionRows = banded ? std::min(h, core + 2 * kBandHalo) : h;
    // The temporaries from the scalable allocator (not Images: no zero fill), one allocation per
    // view: at 512x512 each is at most 8 MiB, which the allocator's cache hands back on the next
    // call (one 36 MiB block was new memory, first touched, every call). With a cache they are
    // kept there for the next call.
    using Stores = std::vector<std::unique_ptr<float, void (*)(void*)>>;
    LearnedTemps T;
    std::shared_ptr<Stores> stores;
    ImageView bandAcc;
    LearnedCtxPlanes C;
    if (cache && cache->holds(weights, w, h)) {
        T = cache->temps;
        C = cache->ctx;
    } else {
        stores = std::make_shared<Stores>();
        const size_t plane = size_t(w) * size_t(regionRows);
        auto alloc = [&](int channels) {
            const size_t bytes = size_t(channels) * plane * sizeof(float);
            stores->emplace_back(static_cast<float*>(scalable_aligned_malloc(bytes, 64)), scalable_aligned_free);
            float* p = stores->back().get();
            if (!p) throw RuntimeError("out of host memory for the learned filter's planes");
            adviseHugePages(p, bytes);
            return ImageView{p, w, regionRows, channels};
        };
        T.lg = alloc(4), T.feat = alloc(kLearnedFeat), T.a = alloc(kLearnedLevels), T.m = alloc(kLearnedLevels);
        T.bk = alloc(kLearnedLevels), T.c = alloc(kLearnedLevels), T.beta = alloc(kLearnedLevels + 1), T.buf = alloc(3);
        T.v = alloc(1);
        if (banded) bandAcc = alloc(3);
        if (weights.impl->net.context) {  // the whole image's, also when banded (a few floats a pixel)
            const size_t bytes = learnedCtxFloats(w, h) * sizeof(float);
            stores->emplace_back(static_cast<float*>(scalable_aligned_malloc(bytes, 64)), scalable_aligned_free);
            if (!stores->back()) throw RuntimeError("out of host memory for the learned filter's planes");
            C = learnedCtxPlanes(stores->back().get(), w, h);
        }
        if (cache) *cache = LearnedCache{w, h, weights.impl, stores, T, &weights.impl->net, C};
    }
    const LearnedNet* net = &weights.impl->net;
    LearnedStageTimes local;
    LearnedStageTimes& t = times ? *times : local;
    clock.mark(t.allocate, unused);
    if (!atrousCpuFastPath()) {
        runLearnedFunctors(exec, net, in, T, out, C);
        return;
    }
    if (C.valid()) runLearnedContextCpu(exec, net->ctx, in, C);
    clock.mark(t.context, t.cpuContext);
    const bool avx512 = atrousCpuAvx512();
    double logs = 0, network = 0, levels = 0, cpuLogs = 0, cpuNetwork = 0, cpuLevels = 0;
    LearnedStageTimes sum;  // over the bands
    for (int y0 = 0; y0 < h; y0 += core) {
        const int y1 = std::min(h, y0 + core);
        const int r0 = banded ? std::max(0, y0 - kBandHalo) : 0, r1 = banded ? std::min(h, y1 + kBandHalo) : h;
        const int rows = r1 - r0;
        // The band's views: the temporaries from their first row (each view's planes contiguous
        // for `rows` rows), P from the image's row r0.
        auto view = [&](const ImageView& v) { return ImageView{v.data, w, rows, v.channels}; };
        LearnedTemps B = T;
        B.lg = view(T.lg), B.feat = view(T.feat), B.a = view(T.a), B.m = view(T.m), B.bk = view(T.bk), B.c = view(T.c);
        B.beta = view(T.beta), B.buf = view(T.buf), B.v = view(T.v);
        const ImageView acc = banded ? view(bandAcc) : out;
        const size_t pOffset = size_t(r0) * size_t(w);
        cpu::parallelForIsa(cpu::activeIsa(), size_t(0), size_t(rows) * size_t(w), size_t(16384),
                            LogRange{in.color.channel(0) + pOffset, in.color.channel(1) + pOffset, in.color.channel(2) + pOffset,
                                     in.variance.channel(0) + pOffset, in.variance.channel(1) + pOffset,
                                     in.variance.channel(2) + pOffset, B.lg.channel(0), B.lg.channel(1), B.lg.channel(2),
                                     B.lg.channel(3), B.v.channel(0)});
        clock.mark(logs, cpuLogs);
        sum.logs += logs, sum.cpuLogs += cpuLogs;
        cpu::parallelForIsa(cpu::activeIsa(), 0, rows, 2, NetRows{net, in, B, acc, pOffset, C.z, r0});
        clock.mark(network, cpuNetwork);
        sum.network += network, sum.cpuNetwork += cpuNetwork;
        // Level i over the rows the levels after it read: within H_i = 2 (2^5 - 2^(i+1)) of the band.
        for (int i = 0; i < kLearnedLevels; ++i) {
            const int reach = banded ? 2 * ((1 << kLearnedLevels) - (2 << i)) : 0;
            const int a = std::max(r0, y0 - reach) - r0, b = std::min(r1, y1 + reach) - r0;
            if (i + 1 < kLearnedLevels) {
                LearnedStop<false> s = learnedStop<false>(in, B, acc, i);
                s.height_ = rows;
                if (i == 0) s.dInShift = ptrdiff_t(pOffset);
                cpu::runAtrousRows(s, avx512, a, b);
            } else {
                LearnedStop<true> s = learnedStop<true>(in, B, acc, i);
                s.height_ = rows;
                if (i == 0) s.dInShift = ptrdiff_t(pOffset);
                cpu::runAtrousRows(s, avx512, a, b);
            }
        }
        if (banded) {
            // The band's own rows of acc into the output.
            cpu::parallelForIsa(cpu::activeIsa(), y0, y1, 16, [&](int q0, int q1) {
                for (int c = 0; c < 3; ++c)
                    std::memcpy(out.channel(c) + size_t(q0) * w, acc.channel(c) + size_t(q0 - r0) * w,
                                size_t(q1 - q0) * w * sizeof(float));
            });
        }
        clock.mark(levels, cpuLevels);
        sum.levels += levels, sum.cpuLevels += cpuLevels;
    }
    t.logs = sum.logs, t.cpuLogs = sum.cpuLogs, t.network = sum.network, t.cpuNetwork = sum.cpuNetwork;
    t.levels = sum.levels, t.cpuLevels = sum.cpuLevels;
}

}  // namespace atrous::filters

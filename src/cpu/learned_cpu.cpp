// The learned filter v3 on the CPU (filters/learned.h): pass A per pixel (vectorised x loop),
// pass B row-wise (the 3x3 box as column sums once per row, then the MLP on 16 pixels at a time
// with the pixel index innermost: the lane loops of learnedMlp<16> become vector instructions),
// the five levels through the shared row engine (src/cpu/atrous_rows.h) with the LearnedStop
// policy. Every loop body is ISA-dispatched (cpu::parallelForIsa: baseline, AVX2, AVX-512). With
// atrousCpuFastPath() off, the functors of learned.h instead (the reference the tests compare).
#include <sys/mman.h>
#include <tbb/scalable_allocator.h>

#include <chrono>
#include <cstdint>
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

// Pass B over rows [y0, y1).
struct NetRows {
    const LearnedNet* net;
    LearnedPlanes P;
    LearnedTemps T;
    ImageView acc;

    ATROUS_FORCE_INLINE void operator()(int y0, int y1) const {
        const int w = P.d.width, h = P.d.height;
        const size_t stride = size_t(w) + 2;
        std::vector<float> buf(kLearnedBoxQ * stride + size_t(w));
        float* V[kLearnedBoxQ];
        for (int k = 0; k < kLearnedBoxQ; ++k) V[k] = buf.data() + k * stride;
        float* inv = buf.data() + kLearnedBoxQ * stride;
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
            for (int x0 = 0; x0 < w; x0 += kLanes) {
                const int n = w - x0 < kLanes ? w - x0 : kLanes;
                float in[kLearnedIn][kLanes], out[kLearnedOut][kLanes];
                learnedPointInputs<kLanes>(P, T.lg, o + size_t(x0), n, in);
                const float* const Vx[kLearnedBoxQ] = {V[0] + x0, V[1] + x0, V[2] + x0, V[3] + x0, V[4] + x0};
                learnedBoxInputs<kLanes>(Vx, inv + x0, n, in);
                learnedMlp<kLanes>(*net, in, out);
                learnedWriteOutputs<kLanes>(out, P.d, T, acc, o + size_t(x0), n);
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

void runLearned(const CpuExec& exec, const LearnedWeights& weights, const LearnedPlanes& in, const ImageView& out,
                LearnedStageTimes* times, LearnedCache* cache) {
    checkLearnedPlanes(weights, in, out);
    const int w = in.d.width, h = in.d.height;
    StageClock clock;
    double unused = 0;
    // The temporaries from the scalable allocator (not Images: no zero fill), one allocation per
    // view: at 512x512 each is at most 8 MiB, which the allocator's cache hands back on the next
    // call (one 36 MiB block was new memory, first touched, every call). With a cache they are
    // kept there for the next call.
    using Stores = std::vector<std::unique_ptr<float, void (*)(void*)>>;
    LearnedTemps T;
    std::shared_ptr<Stores> stores;
    if (cache && cache->holds(weights, w, h)) {
        T = cache->temps;
    } else {
        stores = std::make_shared<Stores>();
        const size_t plane = size_t(w) * size_t(h);
        auto alloc = [&](int channels) {
            const size_t bytes = size_t(channels) * plane * sizeof(float);
            stores->emplace_back(static_cast<float*>(scalable_aligned_malloc(bytes, 64)), scalable_aligned_free);
            float* p = stores->back().get();
            if (!p) throw RuntimeError("out of host memory for the learned filter's planes");
            adviseHugePages(p, bytes);
            return ImageView{p, w, h, channels};
        };
        T.lg = alloc(4), T.feat = alloc(kLearnedFeat), T.a = alloc(kLearnedLevels), T.m = alloc(kLearnedLevels);
        T.bk = alloc(kLearnedLevels), T.c = alloc(kLearnedLevels), T.beta = alloc(kLearnedLevels + 1), T.buf = alloc(3);
        T.v = alloc(1);
        if (cache) *cache = LearnedCache{w, h, weights.impl, stores, T, &weights.impl->net};
    }
    const LearnedNet* net = &weights.impl->net;
    LearnedStageTimes local;
    LearnedStageTimes& t = times ? *times : local;
    clock.mark(t.allocate, unused);
    if (!atrousCpuFastPath()) {
        runLearnedFunctors(exec, net, in, T, out);
        return;
    }
    cpu::parallelForIsa(cpu::activeIsa(), size_t(0), in.d.plane(), size_t(16384),
                        LogRange{in.d.channel(0), in.d.channel(1), in.d.channel(2), in.var.channel(0),
                                 in.var.channel(1), in.var.channel(2), T.lg.channel(0), T.lg.channel(1),
                                 T.lg.channel(2), T.lg.channel(3), T.v.channel(0)});
    clock.mark(t.logs, t.cpuLogs);
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 2, NetRows{net, in, T, out});
    clock.mark(t.network, t.cpuNetwork);
    const bool avx512 = atrousCpuAvx512();
    for (int i = 0; i + 1 < kLearnedLevels; ++i) cpu::runAtrousRows(learnedStop<false>(in, T, out, i), avx512);
    cpu::runAtrousRows(learnedStop<true>(in, T, out, kLearnedLevels - 1), avx512);
    clock.mark(t.levels, t.cpuLevels);
}

}  // namespace atrous::filters

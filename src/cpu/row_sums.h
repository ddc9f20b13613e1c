// Sums of whole rows for the CPU window passes (src/cpu/sure_cpu.cpp): out[i] = the rows added in
// order from 0 (((0 + rows[0][i]) + rows[1][i]) + ...), so the same value, bit for bit, as a
// per-pixel loop over the window (the functors' order). 128 values at a time are kept in vector
// registers while the rows are added (one store per value): adding one row at a time over a whole
// row buffer stored and reloaded the sums for every row, and GCC neither vectorises an x loop
// around a runtime-length row loop nor keeps a local array in registers. GCC's vector extension
// lowers the 64-byte vectors to what the ISA of the enclosing dispatched body has (one zmm, two
// ymm or four xmm each). Call it from inside an ISA-dispatched body (cpu::parallelForIsa).
#pragma once
#include <cstddef>
#include <cstring>

#include "atrous/platform.h"
#include "filters/atrous_math.h"

namespace atrous::cpu {

typedef float Floats16 __attribute__((vector_size(64)));

// The sums of `count` rows over [i, i + 16·V) in V independent vector accumulators (the adds of
// one accumulator depend on each other: V chains keep the adder busy while the loads come).
template <int V>
ATROUS_FORCE_INLINE inline void sumRowsChunk(const float* const* rows, int count, float* out, size_t i) {
    Floats16 a[V];
    for (int v = 0; v < V; ++v) a[v] = Floats16{};
    for (int k = 0; k < count; ++k) {
        const float* r = rows[k] + i;
        for (int v = 0; v < V; ++v) {
            Floats16 b;
            std::memcpy(&b, r + 16 * v, sizeof b);
            a[v] += b;
        }
    }
    for (int v = 0; v < V; ++v) std::memcpy(out + i + 16 * v, &a[v], sizeof a[v]);
}

ATROUS_FORCE_INLINE inline void sumRows(const float* const* rows, int count, float* out, size_t n) {
    if (n < 32) {
        for (size_t i = 0; i < n; ++i) {
            float s = 0.0f;
            for (int k = 0; k < count; ++k) s += rows[k][i];
            out[i] = s;
        }
        return;
    }
    // Every output depends on its own index only, so the last, overlapping chunk rewrites the
    // values it shares with the one before with the same bits.
    size_t i = 0;
    for (; i + 128 <= n; i += 128) sumRowsChunk<8>(rows, count, out, i);
    for (; i + 32 <= n; i += 32) sumRowsChunk<2>(rows, count, out, i);
    if (i < n) sumRowsChunk<2>(rows, count, out, n - 32);
}

// G sums of row ranges at once: out[j][i] = rows[lo[j]][i] + ... + rows[hi[j]][i], added in order
// from 0, for overlapping ranges (a vertical window sum for G consecutive output rows): each row
// is loaded once for all the outputs it belongs to (a window of 9 rows for one output at a time
// read every row 9 times, from L2), 2 vectors per output in registers.
template <int G>
ATROUS_FORCE_INLINE inline void sumRowRangesChunk(const float* const* rows, const int (&lo)[G], const int (&hi)[G],
                                                  int first, int last, float* const (&out)[G], size_t i) {
    Floats16 a[G][2];
    for (int j = 0; j < G; ++j) a[j][0] = Floats16{}, a[j][1] = Floats16{};
    for (int k = first; k <= last; ++k) {
        Floats16 b0, b1;
        std::memcpy(&b0, rows[k] + i, sizeof b0);
        std::memcpy(&b1, rows[k] + i + 16, sizeof b1);
        for (int j = 0; j < G; ++j)
            if (k >= lo[j] && k <= hi[j]) a[j][0] += b0, a[j][1] += b1;
    }
    for (int j = 0; j < G; ++j) {
        std::memcpy(out[j] + i, &a[j][0], sizeof a[j][0]);
        std::memcpy(out[j] + i + 16, &a[j][1], sizeof a[j][1]);
    }
}

template <int G>
ATROUS_FORCE_INLINE inline void sumRowRanges(const float* const* rows, const int (&lo)[G], const int (&hi)[G],
                                             float* const (&out)[G], size_t n) {
    int first = lo[0], last = hi[0];
    for (int j = 1; j < G; ++j) first = lo[j] < first ? lo[j] : first, last = hi[j] > last ? hi[j] : last;
    if (n < 32) {
        for (int j = 0; j < G; ++j)
            for (size_t i = 0; i < n; ++i) {
                float s = 0.0f;
                for (int k = lo[j]; k <= hi[j]; ++k) s += rows[k][i];
                out[j][i] = s;
            }
        return;
    }
    size_t i = 0;
    for (; i + 32 <= n; i += 32) sumRowRangesChunk<G>(rows, lo, hi, first, last, out, i);
    if (i < n) sumRowRangesChunk<G>(rows, lo, hi, first, last, out, n - 32);
}

// The sum (in double) and count of the finite luminances of one row of planes r, g, b: the
// reports' mean luminance (the input scan of denoise(), the driver's after the firefly pass).
ATROUS_FORCE_INLINE inline void finiteLuminanceRow(const float* ATROUS_RESTRICT r, const float* ATROUS_RESTRICT g,
                                                   const float* ATROUS_RESTRICT b, int w, double& sum, double& count) {
    double s = 0, n = 0;
#pragma omp simd reduction(+ : s, n)
    for (int x = 0; x < w; ++x) {
        const float l = filters::lum(r[x], g[x], b[x]);
        const bool ok = filters::finite(l);
        s += ok ? double(l) : 0.0;
        n += ok ? 1.0 : 0.0;
    }
    sum = s, count = n;
}

}  // namespace atrous::cpu

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

}  // namespace atrous::cpu

// Sums of whole rows for the CPU window passes (src/cpu/sure_cpu.cpp): out[i] = the rows added in
// order from 0 (((0 + rows[0][i]) + rows[1][i]) + ...), so the same value, bit for bit, as a
// per-pixel loop over the window (the functors' order). 32 values at a time are kept in vector
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

ATROUS_FORCE_INLINE inline void sumRows(const float* const* rows, int count, float* out, size_t n) {
    if (n < 32) {
        for (size_t i = 0; i < n; ++i) {
            float s = 0.0f;
            for (int k = 0; k < count; ++k) s += rows[k][i];
            out[i] = s;
        }
        return;
    }
    // 32 values from i: every output depends on its own index only, so the last, overlapping
    // chunk rewrites the values it shares with the one before with the same bits.
    auto chunk = [&](size_t i) {
        Floats16 a0 = {}, a1 = {};
        for (int k = 0; k < count; ++k) {
            Floats16 b0, b1;
            std::memcpy(&b0, rows[k] + i, sizeof b0);
            std::memcpy(&b1, rows[k] + i + 16, sizeof b1);
            a0 += b0;
            a1 += b1;
        }
        std::memcpy(out + i, &a0, sizeof a0);
        std::memcpy(out + i + 16, &a1, sizeof a1);
    };
    size_t i = 0;
    for (; i + 32 <= n; i += 32) chunk(i);
    if (i < n) chunk(n - 32);
}

}  // namespace atrous::cpu

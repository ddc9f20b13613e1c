// Deterministic random numbers. The stream of every sample is a pure function of
// (pixel, sample index, seed, dimension), so the output does not depend on the thread count or
// the order in which tiles run (docs/architecture.md, principle 6).
#pragma once
#include <cstdint>

#include "atrous/platform.h"

namespace atrous {

// A strong 32-bit integer hash (lowbias32, Chris Wellons' hash-prospector).
ATROUS_INLINE uint32_t hash32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

ATROUS_INLINE uint32_t hashCombine(uint32_t a, uint32_t b) { return hash32(a ^ (hash32(b) + 0x9e3779b9U)); }

// PCG32 (O'Neill 2014): small state, good statistics, identical on host and device.
struct Rng {
    uint64_t state = 0;
    uint64_t inc = 1;

    ATROUS_INLINE Rng() = default;
    // One independent stream per (pixel, sample, seed).
    ATROUS_INLINE Rng(uint32_t pixel, uint32_t sample, uint32_t seed) {
        uint64_t initstate = (uint64_t(hashCombine(pixel, seed)) << 32) | hashCombine(sample, seed ^ 0xa511e9b3U);
        uint64_t initseq = (uint64_t(hashCombine(seed, pixel ^ 0x68bc21ebU)) << 32) | hashCombine(pixel, sample);
        state = 0U;
        inc = (initseq << 1u) | 1u;
        nextU32();
        state += initstate;
        nextU32();
    }
    ATROUS_INLINE uint32_t nextU32() {
        uint64_t old = state;
        state = old * 6364136223846793005ULL + inc;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
    }
    // Uniform in [0, 1).
    ATROUS_INLINE float next() { return float(nextU32() >> 8) * (1.0f / 16777216.0f); }
};

}  // namespace atrous

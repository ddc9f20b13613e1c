// Stratified 2D sample points: the Sobol (0,2)-sequence in base 2 with hash-based Owen scrambling
// (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
//
// Why: with independent uniform jitter the fraction f of a pixel covered by a sharp edge (the
// directly visible area light) is estimated with standard deviation sqrt(f(1-f)/n); the first
// n = 2^m points of a (0,2)-sequence put exactly one point in every elementary interval of area
// 1/n (every 2^a x 2^(m-a) grid, a = 0..m, so every sqrt(n) x sqrt(n) grid when m is even), which
// makes that error fall like ~n^-0.75 instead of n^-0.5 for a straight edge. Owen scrambling keeps
// that net property while making every point uniformly distributed over [0,1)^2, so the pixel
// estimate stays unbiased; seeding the scramble per pixel decorrelates neighbouring pixels.
//
// Any n works: a non-power of two just takes the sequence's prefix (still low-discrepancy, only
// the complete 2^m blocks are exact nets). Consecutive indices [k 2^m, (k+1) 2^m) form a net for
// every k, which is what progressive accumulation (index = frame * spp + s) relies on.
//
// Host/device code, no STL: used by the per-pixel path-tracing functor (render/integrator.h).
#pragma once
#include <cstdint>

#include "atrous/platform.h"
#include "atrous/math.h"
#include "core/rng.h"

namespace atrous {

ATROUS_INLINE uint32_t reverseBits32(uint32_t x) {
#if ATROUS_ON_DEVICE
    return __brev(x);
#else
    x = (x << 16) | (x >> 16);
    x = ((x & 0x00ff00ffU) << 8) | ((x & 0xff00ff00U) >> 8);
    x = ((x & 0x0f0f0f0fU) << 4) | ((x & 0xf0f0f0f0U) >> 4);
    x = ((x & 0x33333333U) << 2) | ((x & 0xccccccccU) >> 2);
    x = ((x & 0x55555555U) << 1) | ((x & 0xaaaaaaaaU) >> 1);
    return x;
#endif
}

// Sobol dimension 0 (the van der Corput radical inverse in base 2) as a 0.32 fixed-point number.
ATROUS_INLINE uint32_t sobolDim0(uint32_t index) { return reverseBits32(index); }

// Sobol dimension 1: direction numbers v_0 = 2^31, v_k = v_(k-1) ^ (v_(k-1) >> 1); the generator
// matrix is Pascal's triangle mod 2. With dimension 0 this is a (0,2)-sequence in base 2.
// Reference form (one step per index bit); sobolDim1 below computes the same bits faster.
ATROUS_INLINE uint32_t sobolDim1Reference(uint32_t index) {
    uint32_t r = 0;
    for (uint32_t v = 1u << 31; index != 0; index >>= 1, v ^= v >> 1)
        if (index & 1u) r ^= v;
    return r;
}

// By Lucas' theorem C(k, p) is odd iff the bits of p are a subset of those of k, so bit 31 - p of
// the result is the XOR of the index bits k ⊇ p: a superset (zeta) transform over the 5-bit bit
// positions, five shift/mask/XOR steps instead of a 32-step loop. Returned bit-reversed (the
// scramble below works on reversed numbers anyway): sobolDim1(i) = reverseBits32(supersetXor(i)).
ATROUS_INLINE uint32_t sobolDim1Reversed(uint32_t a) {
    a ^= (a >> 1) & 0x55555555U;
    a ^= (a >> 2) & 0x33333333U;
    a ^= (a >> 4) & 0x0f0f0f0fU;
    a ^= (a >> 8) & 0x00ff00ffU;
    a ^= (a >> 16) & 0x0000ffffU;
    return a;
}
ATROUS_INLINE uint32_t sobolDim1(uint32_t index) { return reverseBits32(sobolDim1Reversed(index)); }

// A Laine-Karras style permutation: every step (add, multiply by an odd number, x ^= x * even) is
// a bijection in which bit k of the output depends only on bits 0..k of the input. Applied to
// bit-reversed numbers that is a nested uniform (Owen) scramble in base 2: each bit is flipped as
// a function of the bits above it only. Constants: N. Vegdahl's improved variant (2021) of
// Burley's hash, which randomises the high bits better; `seed` must already be well mixed.
ATROUS_INLINE uint32_t laineKarrasPermutation(uint32_t x, uint32_t seed) {
    x ^= x * 0x3d20adeaU;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56U;
    x ^= x * 0x53a22864U;
    return x;
}

// Owen scrambling of a 0.32 fixed-point number (Burley 2020, listing 3).
ATROUS_INLINE uint32_t nestedUniformScramble(uint32_t x, uint32_t seed) {
    return reverseBits32(laineKarrasPermutation(reverseBits32(x), seed));
}

// 0.32 fixed point -> float in [0, 1) (24 bits, so the result never rounds up to 1).
ATROUS_INLINE float fixedToUnitFloat(uint32_t x) { return float(x >> 8) * (1.0f / 16777216.0f); }

// Salts that separate the hashes of the index shuffle and of the two dimensions.
constexpr uint32_t kSobolShuffleSalt = 0x1b873593U;
constexpr uint32_t kSobolDim0Salt = 0x85ebca6bU;
constexpr uint32_t kSobolDim1Salt = 0xc2b2ae35U;

// One pixel's shuffled, Owen-scrambled 2D Sobol sequence (Burley 2020, listing 4). The index is
// shuffled by a nested uniform scramble too: it maps every aligned block of 2^m indices onto
// another aligned block, so any n = 2^m consecutive aligned indices are still a (0,m,2)-net, while
// the order inside the block (and which block) is random per seed, which decorrelates a
// sequence's prefixes across pixels. The three hash seeds are derived once per pixel.
struct Sobol02Sequence {
    uint32_t shuffleSeed = 0, xSeed = 0, ySeed = 0;

    ATROUS_INLINE explicit Sobol02Sequence(uint32_t seed)
        : shuffleSeed(hashCombine(seed, kSobolShuffleSalt)),
          xSeed(hashCombine(seed, kSobolDim0Salt)),
          ySeed(hashCombine(seed, kSobolDim1Salt)) {}

    ATROUS_INLINE Vec2 point(uint32_t index) const {
        uint32_t i = nestedUniformScramble(index, shuffleSeed);
        // nestedUniformScramble(v) = reverse(lk(reverse(v))); with sobolDim0(i) = reverse(i) and
        // sobolDim1(i) = reverse(sobolDim1Reversed(i)) the inner reversals cancel.
        uint32_t x = reverseBits32(laineKarrasPermutation(i, xSeed));
        uint32_t y = reverseBits32(laineKarrasPermutation(sobolDim1Reversed(i), ySeed));
        return Vec2(fixedToUnitFloat(x), fixedToUnitFloat(y));
    }
};

// Point `index` of the scrambled sequence of `seed`.
ATROUS_INLINE Vec2 sobol02Scrambled(uint32_t index, uint32_t seed) { return Sobol02Sequence(seed).point(index); }

// The scrambling seed of a pixel: one independent Owen scramble per (pixel, render seed).
ATROUS_INLINE uint32_t pixelSamplerSeed(uint32_t pixel, uint32_t seed) {
    return hashCombine(pixel, seed ^ 0x27d4eb2fU);
}

// Sub-pixel position in [0,1)^2 of sample `index` of pixel `pixel` in a render of `seed`: what the
// path tracer uses (pt::PixelSampler::Sobol), for code that needs to know where a sample landed.
ATROUS_INLINE Vec2 stratifiedPixelJitter(uint32_t pixel, uint32_t index, uint32_t seed) {
    return sobol02Scrambled(index, pixelSamplerSeed(pixel, seed));
}

}  // namespace atrous

// Synthetic denoiser inputs for the filter tests: a small piecewise-smooth scene with features
// (background plane, a box face, a disk) and Gaussian noise of known per-pixel variance.
#pragma once
#include <cmath>
#include <cstring>
#include <random>

#include <string>
#include <utility>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/image.h"

namespace atrous::test {

// denoiseWithReport's image, with its report in `rep` (tests that check both).
template <class In>
Image denoiseReporting(In&& in, const DenoiseOptions& o, DenoiseReport& rep) {
    DenoiseResult r = denoiseWithReport(in, o);
    rep = std::move(r.report);
    return std::move(r.image);
}

// Frame over seven buffers the caller keeps alive (emission unset). Also bench_denoise's.
inline Frame inputsOf(const Image& color, const Image& variance, const Image& albedo, const Image& normal,
                              const Image& position, const Image& depth, const Image& ids) {
    Frame in;
    in.color = &color;
    in.variance = &variance;
    in.albedo = &albedo;
    in.normal = &normal;
    in.position = &position;
    in.depth = &depth;
    in.ids = &ids;
    return in;
}

// The message of the InputError that denoise(in, o) throws, or "" when it returns.
inline std::string inputErrorOf(const Frame& in, const DenoiseOptions& o) {
    try {
        denoise(in, o);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

// Frame of a colour and its variance only (no feature buffers).
inline Frame inputsOf(const Image& color, const Image& variance) {
    Frame in;
    in.color = &color;
    in.variance = &variance;
    return in;
}

struct SyntheticScene {
    Image truth, noisy, variance, albedo, normal, position, depth, ids;
    Frame inputs() const { return inputsOf(noisy, variance, albedo, normal, position, depth, ids); }
};

// Region 0: back wall at z = 5 (normal +z), 1: a box face at z = 3, 2: a disk at z = 2 (normal
// tilted). Shading varies smoothly; noise variance = noiseScale² · (0.02 + truth) per channel.
inline SyntheticScene makeScene(int w, int h, float noiseScale, unsigned seed) {
    SyntheticScene s;
    s.truth = Image(w, h, 3);
    s.noisy = Image(w, h, 3);
    s.variance = Image(w, h, 3);
    s.albedo = Image(w, h, 3);
    s.normal = Image(w, h, 3);
    s.position = Image(w, h, 3);
    s.depth = Image(w, h, 3);
    s.ids = Image(w, h, 3);
    std::mt19937 rng(seed);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
            int region = 0;
            if (u > 0.15f && u < 0.55f && v > 0.2f && v < 0.75f) region = 1;
            if ((u - 0.7f) * (u - 0.7f) + (v - 0.55f) * (v - 0.55f) < 0.04f) region = 2;
            const float z = region == 0 ? 5.0f : (region == 1 ? 3.0f : 2.0f);
            const float n[3][3] = {{0, 0, 1}, {0.6f, 0, 0.8f}, {0, 0.6f, 0.8f}};
            const float alb[3][3] = {{0.7f, 0.7f, 0.7f}, {0.8f, 0.2f, 0.2f}, {0.2f, 0.7f, 0.3f}};
            const float light = region == 0 ? 0.3f + 0.6f * v : (region == 1 ? 1.2f - 0.5f * u : 0.5f + 0.8f * u * v);
            for (int c = 0; c < 3; ++c) {
                const float t = alb[region][c] * light;
                const float var = noiseScale * noiseScale * (0.02f + t);
                s.truth(x, y, c) = t;
                s.variance(x, y, c) = var;
                s.noisy(x, y, c) = t + std::sqrt(var) * gauss(rng);
                s.albedo(x, y, c) = alb[region][c];
                s.normal(x, y, c) = n[region][c];
                s.depth(x, y, c) = z;
                s.ids(x, y, c) = c == 2 ? 0.0f : float(region);
            }
            // Camera at the origin looking down +z with a 1-unit-wide image plane at z = 1.
            s.position(x, y, 0) = (u - 0.5f) * z;
            s.position(x, y, 1) = (v - 0.5f) * z;
            s.position(x, y, 2) = z;
        }
    return s;
}

inline double mse(const Image& a, const Image& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += double(a.data()[i] - b.data()[i]) * (a.data()[i] - b.data()[i]);
    return s / double(a.size());
}

// Max |a - b| over every value; +inf when the two differ in size or channel count.
inline double maxAbsDiff(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels()) return INFINITY;
    double m = 0;
    for (size_t i = 0; i < a.size(); ++i) m = std::max(m, double(std::fabs(a.data()[i] - b.data()[i])));
    return m;
}

// The index of the first float that differs bit for bit (-1: none; 0 when the sizes or channel
// counts differ). NaNs compare by their bits.
inline long firstBitDifference(const Image& a, const Image& b) {
    if (a.size() != b.size() || a.channels() != b.channels()) return 0;
    for (size_t i = 0; i < a.size(); ++i)
        if (std::memcmp(a.data() + i, b.data() + i, sizeof(float)) != 0) return long(i);
    return -1;
}

inline bool allFinite(const Image& a) {
    for (size_t i = 0; i < a.size(); ++i)
        if (!std::isfinite(a.data()[i])) return false;
    return true;
}

// Options with the extras off, for exact property tests.
inline DenoiseOptions plainOptions(DenoiseMethod m) {
    DenoiseOptions o;
    o.method = m;
    o.firefly.enabled = false;
    o.demodulate = false;
    return o;
}

}  // namespace atrous::test

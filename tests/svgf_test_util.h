// The synthetic SVGF sequences of the svgf_*_test.cpp files: a tilted, gently curved textured
// ground plane, a strip of sky, and a textured box that slides right, approaches the camera and
// turns a little each frame (optionally with an emitting top and Gaussian noise), with their
// ground truth; plus the comparisons the tests share.
#pragma once
#include <algorithm>
#include <cmath>
#include <random>

#include "atrous/image.h"
#include "atrous/svgf.h"

namespace atrous::svgf_test {

struct SceneOptions {
    int width = 64, height = 48;
    float boxSpeed = 4.0f;       // pixels per frame, to the right
    float boxApproach = 0.03f;   // depth change per frame (towards the camera)
    float boxTurn = 0.05f;       // radians per frame about the vertical axis
    float noiseSigma = 0.0f;     // Gaussian noise on the colour, same value in R, G, B
    bool withBox = true;
    bool flat = false;           // a fronto-parallel constant plane, albedo 1, illumination 1
    bool emitter = false;        // the box's top 3 rows emit (5), the third one covered at random
    unsigned seed = 1;
};

struct SynthFrame {
    Image color, albedo, normal, depth, ids, motion, truth, emission;
    Frame frame() const {
        Frame f;
        if (!emission.empty()) f.emission = &emission;
        f.color = &color;
        f.albedo = &albedo;
        f.normal = &normal;
        f.depth = &depth;
        f.ids = &ids;
        f.motion = &motion;
        return f;
    }
};

constexpr int kSkyRows = 4;

inline int boxX0(const SceneOptions& o, int t) { return o.width / 4 + int(o.boxSpeed * float(t)); }
inline int boxY0(const SceneOptions& o) { return o.height / 3; }
inline int boxSize(const SceneOptions& o) { return o.width / 4; }

inline SynthFrame makeFrame(const SceneOptions& o, int t) {
    const int w = o.width, h = o.height;
    SynthFrame f{Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image(w, h, 3),
                 Image(w, h, 3), Image(w, h, 3), Image(w, h, 3), Image()};
    if (o.emitter) f.emission = Image(w, h, 3);
    std::bernoulli_distribution cover(0.5);
    std::mt19937 rng(o.seed * 7919u + unsigned(t));
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    const int bx = boxX0(o, t), by = boxY0(o), bs = boxSize(o);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            float a[3], n[3], z, id, mx = 0.0f, e;
            bool inBox = o.withBox && x >= bx && x < bx + bs && y >= by && y < by + bs;
            if (o.flat) {
                a[0] = a[1] = a[2] = 1.0f;
                n[0] = 0, n[1] = 0, n[2] = 1;
                z = 5.0f, id = 0.0f, e = 1.0f;
            } else if (inBox) {
                int lx = x - bx, ly = y - by;  // texture moves with the box
                float c = ((lx / 4 + ly / 4) % 2) ? 0.7f : 0.3f;
                a[0] = c, a[1] = 0.5f, a[2] = 1.0f - c;
                float th = o.boxTurn * float(t);
                n[0] = std::sin(th), n[1] = 0.0f, n[2] = std::cos(th);
                z = 3.0f - o.boxApproach * float(t);
                id = 1.0f;
                mx = -o.boxSpeed;
                e = 2.0f;
            } else if (y < kSkyRows) {
                a[0] = a[1] = a[2] = 1.0f;
                n[0] = n[1] = n[2] = 0.0f;
                z = 1e30f, id = -1.0f, e = 0.5f;
            } else {
                float c = ((x / 8 + y / 8) % 2) ? 0.8f : 0.2f;
                a[0] = c, a[1] = 0.6f, a[2] = 0.5f;
                float nx = 0.3f * std::sin(float(x) / 7.0f);
                float len = std::sqrt(nx * nx + 0.36f + 0.64f);
                n[0] = nx / len, n[1] = 0.6f / len, n[2] = 0.8f / len;
                z = 4.0f + 0.05f * float(y);
                id = 0.0f;
                e = 1.0f + 0.5f * std::sin(float(x) / 10.0f);
            }
            float em = 0.0f, emTruth = 0.0f;  // emission: this frame's sample, and its expectation
            if (o.emitter && inBox && y - by < 3) {
                emTruth = y - by < 2 ? 5.0f : 2.5f;
                em = (y - by < 2 || cover(rng)) ? 5.0f : 0.0f;
            }
            float noise = o.noiseSigma * gauss(rng);
            for (int c = 0; c < 3; ++c) {
                f.albedo(x, y, c) = a[c];
                f.normal(x, y, c) = n[c];
                f.depth(x, y, c) = z;
                f.ids(x, y, c) = id;
                f.truth(x, y, c) = a[c] * e + emTruth;
                f.color(x, y, c) = a[c] * e + noise + em;
                if (o.emitter) f.emission(x, y, c) = em;
            }
            f.motion(x, y, 0) = mx;
        }
    }
    return f;
}

inline double mse(const Image& a, const Image& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += double(a.data()[i] - b.data()[i]) * double(a.data()[i] - b.data()[i]);
    return s / double(a.size());
}

inline bool allFinite(const Image& img) {
    for (size_t i = 0; i < img.size(); ++i)
        if (!std::isfinite(img.data()[i])) return false;
    return true;
}

inline float maxAbsDiff(const Image& a, const Image& b) {
    float m = 0;
    for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::fabs(a.data()[i] - b.data()[i]));
    return m;
}

// Runs `frames` frames of the scene through a fresh denoiser; returns the last output.
inline Image runSequence(const SvgfParams& p, const SceneOptions& o, int frames) {
    SvgfDenoiser d(p);
    Image out;
    for (int t = 0; t < frames; ++t) out = d.denoiseFrame(makeFrame(o, t).frame());
    return out;
}

}  // namespace atrous::svgf_test

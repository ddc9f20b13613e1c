// Buffer views and their host tonemapping (buffer_view.h).
#include "view/buffer_view.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "atrous/error.h"

namespace atrous::view {

BufferView parseBufferView(const std::string& s) {
    for (int i = 0; i < kViewCount; ++i)
        if (s == kViewFlags[i]) return BufferView(i);
    std::string all;
    for (int i = 0; i < kViewCount; ++i) all += std::string(i ? ", " : "") + kViewFlags[i];
    throw InputError("--buffer: unknown view \"" + s + "\" (expected one of " + all + ")");
}

const SrgbLut& lut() {
    static const SrgbLut l;
    return l;
}

namespace {

// 99th percentile of f over the pixels (robust display scale), at least `floor`.
template <class F>
float percentile99(size_t n, F f, float floor) {
    std::vector<float> v;
    v.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        const float x = f(i);
        if (std::isfinite(x)) v.push_back(x);
    }
    if (v.empty()) return floor;
    const size_t k = std::min(v.size() - 1, size_t(0.99 * double(v.size())));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return std::max(v[k], floor);
}

void idColor(float id, unsigned char* px) {
    if (!(id >= 0.0f)) {
        px[0] = px[1] = px[2] = 0;
        return;
    }
    uint32_t h = uint32_t(id) * 2654435761u + 0x9E3779B9u;
    h ^= h >> 15;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    px[0] = (unsigned char)(64 + (h & 0xBF));
    px[1] = (unsigned char)(64 + ((h >> 8) & 0xBF));
    px[2] = (unsigned char)(64 + ((h >> 16) & 0xBF));
}

}  // namespace

std::string tonemap(const ViewPipeline& pl, BufferView view, const Image* result, float exposure,
                    int level, int x0, int x1, std::vector<unsigned char>& rgba) {
    const int w = pl.width(), h = pl.height();
    const size_t plane = size_t(w) * h;
    const SrgbLut& L = lut();
    auto px = [&](int x, int y) { return &rgba[(size_t(y) * w + x) * 4]; };
    auto fill = [&](auto f) {
        for (int y = 0; y < h; ++y)
            for (int x = x0; x < x1; ++x) {
                unsigned char* p = px(x, y);
                f(size_t(y) * w + x, p);
                p[3] = 255;
            }
    };
    auto srgb3 = [&](const Image& img, float scale) {
        const float* d = img.data();
        fill([&](size_t i, unsigned char* p) {
            for (int c = 0; c < 3; ++c) p[c] = L(d[c * plane + i] * scale);
        });
    };
    auto lin3 = [&](const Image& img, float offset, float scale) {  // linear mapping, no sRGB curve
        const float* d = img.data();
        fill([&](size_t i, unsigned char* p) {
            for (int c = 0; c < 3; ++c) {
                const float v = (d[c * plane + i] - offset) * scale;
                p[c] = std::isfinite(v)
                           ? (unsigned char)std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)
                           : 0;
            }
        });
    };
    auto blank = [&](const std::string& why) {
        fill([&](size_t, unsigned char* p) { p[0] = p[1] = p[2] = 24; });
        return why;
    };
    switch (view) {
        case BufferView::Result:
            if (!result || result->empty()) return blank("no result yet");
            srgb3(*result, exposure);
            return "";
        case BufferView::Noisy:
            srgb3(pl.color(), exposure);
            return "";
        case BufferView::Variance: {
            if (!pl.varianceValid())
                return blank("variance: unknown at 1 sample per pixel (accumulate more frames)");
            const float* v = pl.variance().data();
            const float s = percentile99(
                plane,
                [&](size_t i) {
                    return std::sqrt(std::max(0.0f, v[i] + v[plane + i] + v[2 * plane + i]));
                },
                1e-12f);
            fill([&](size_t i, unsigned char* p) {
                for (int c = 0; c < 3; ++c)
                    p[c] = L(std::sqrt(std::max(0.0f, v[c * plane + i])) / s);
            });
            return "";
        }
        case BufferView::Albedo:
            srgb3(pl.albedo(), 1.0f);
            return "";
        case BufferView::Normal:
            lin3(pl.normal(), -1.0f, 0.5f);
            return "";
        case BufferView::Position: {
            const float* d = pl.position().data();
            const float* n = pl.normal().data();
            float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
            for (size_t i = 0; i < plane; ++i)
                if (n[i] != 0 || n[plane + i] != 0 || n[2 * plane + i] != 0)
                    for (int c = 0; c < 3; ++c) {
                        lo[c] = std::min(lo[c], d[c * plane + i]);
                        hi[c] = std::max(hi[c], d[c * plane + i]);
                    }
            fill([&](size_t i, unsigned char* p) {
                for (int c = 0; c < 3; ++c) {
                    const float r =
                        hi[c] > lo[c] ? (d[c * plane + i] - lo[c]) / (hi[c] - lo[c]) : 0.0f;
                    p[c] = (unsigned char)std::lround(std::clamp(r, 0.0f, 1.0f) * 255.0f);
                }
            });
            return "";
        }
        case BufferView::Depth: {
            const float* d = pl.depth().data();
            float lo = 1e30f, hi = 0.0f;
            for (size_t i = 0; i < plane; ++i)
                if (d[i] < 0.1f * kBackgroundDepth) {
                    lo = std::min(lo, d[i]);
                    hi = std::max(hi, d[i]);
                }
            fill([&](size_t i, unsigned char* p) {
                const bool bg = !(d[i] < 0.1f * kBackgroundDepth);
                const float r =
                    bg ? 0.0f : (hi > lo ? 1.0f - 0.85f * (d[i] - lo) / (hi - lo) : 1.0f);
                p[0] = p[1] = p[2] = (unsigned char)std::lround(r * 255.0f);
            });
            return "";
        }
        case BufferView::MeshIds:
        case BufferView::MaterialIds: {
            const float* d = pl.ids().data() + (view == BufferView::MaterialIds ? plane : 0);
            fill([&](size_t i, unsigned char* p) { idColor(d[i], p); });
            return "";
        }
        case BufferView::Motion: {
            const float* m = pl.motion().data();
            // No previous position: NaN, or the renderer's kMotionOffscreen (-1e4 pixels).
            auto none = [&](size_t i) {
                return !(std::fabs(m[i]) < 1e3f) || !(std::fabs(m[plane + i]) < 1e3f);
            };
            const float s = percentile99(
                plane,
                [&](size_t i) {
                    return none(i) ? 0.0f : std::max(std::fabs(m[i]), std::fabs(m[plane + i]));
                },
                0.5f);
            fill([&](size_t i, unsigned char* p) {
                if (none(i)) {
                    p[0] = 255, p[1] = 0, p[2] = 255;  // no history
                    return;
                }
                p[0] = (unsigned char)std::lround(std::clamp(0.5f + 0.5f * m[i] / s, 0.0f, 1.0f) *
                                                  255.0f);
                p[1] = (unsigned char)std::lround(
                    std::clamp(0.5f + 0.5f * m[plane + i] / s, 0.0f, 1.0f) * 255.0f);
                p[2] = 128;
            });
            return "";
        }
        case BufferView::Detail: {
            if (pl.detail().empty())
                return blank("detail: choose a level below the EAW level count");
            const float* d = pl.detail().data();
            const float s = percentile99(
                plane,
                [&](size_t i) {
                    return std::fabs(d[i]) + std::fabs(d[plane + i]) + std::fabs(d[2 * plane + i]);
                },
                1e-12f);
            fill([&](size_t i, unsigned char* p) {  // signed: mid grey = 0
                for (int c = 0; c < 3; ++c)
                    p[c] = (unsigned char)std::lround(
                        std::clamp(0.5f + 0.5f * d[c * plane + i] / s, 0.0f, 1.0f) * 255.0f);
            });
            return "";
        }
        case BufferView::SureFractions: {
            const Image& s = pl.sureFractions();
            if (s.empty() || level >= s.channels())
                return blank("SURE fractions: pick SURE as a method (CPU only)");
            const float* d = s.data() + size_t(level) * plane;
            fill([&](size_t i, unsigned char* p) {
                p[0] = p[1] = p[2] =
                    (unsigned char)std::lround(std::clamp(d[i], 0.0f, 1.0f) * 255.0f);
            });
            return "";
        }
    }
    return "";
}

}  // namespace atrous::view

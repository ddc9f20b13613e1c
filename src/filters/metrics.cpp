// Metrics of docs/eval.md, "What is measured" (MSE, relMSE, tonemapped PSNR, SSIM of tonemapped luminance).
#include "atrous/metrics.h"

#include "atrous/temporal.h"

#include <cmath>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/srgb.h"
#include "core/parallel.h"
#include "filters/flicker.h"
#include "filters/svgf_gbuffer.h"

namespace atrous {

namespace {

float finiteOr0(float v) { return std::isfinite(v) ? v : 0.0f; }

void checkPair(const Image& a, const Image& r) {
    if (a.empty() || r.empty()) throw InputError("cannot compare an empty image");
    if (a.width() != r.width() || a.height() != r.height())
        throw InputError("image is " + std::to_string(a.width()) + "x" + std::to_string(a.height()) +
                         " but the reference is " + std::to_string(r.width()) + "x" + std::to_string(r.height()));
    if (a.channels() < 3 || r.channels() < 3) throw InputError("images to compare need 3 channels");
}

// Separable 11-tap Gaussian (σ = 1.5) blur with clamped borders.
std::vector<double> blur(const std::vector<double>& in, int w, int h) {
    double g[11], s = 0;
    for (int i = 0; i < 11; ++i) {
        g[i] = std::exp(-double((i - 5) * (i - 5)) / (2 * 1.5 * 1.5));
        s += g[i];
    }
    for (double& v : g) v /= s;
    std::vector<double> tmp(in.size()), out(in.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double a = 0;
            for (int i = -5; i <= 5; ++i) a += g[i + 5] * in[size_t(y) * w + std::min(std::max(x + i, 0), w - 1)];
            tmp[size_t(y) * w + x] = a;
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double a = 0;
            for (int i = -5; i <= 5; ++i) a += g[i + 5] * tmp[size_t(std::min(std::max(y + i, 0), h - 1)) * w + x];
            out[size_t(y) * w + x] = a;
        }
    return out;
}

}  // namespace

TemporalMetrics computeTemporalMetrics(const Image& a, const Image& a0, const Image& r, const Image& r0) {
    checkPair(a, r);
    checkPair(a0, r);
    checkPair(r0, r);
    const size_t plane = r.plane();
    double rel = 0, tse = 0;
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < plane; ++i) {
            const size_t k = size_t(c) * plane + i;
            const double x = finiteOr0(a.data()[k]), x0 = finiteOr0(a0.data()[k]);
            const double y = finiteOr0(r.data()[k]), y0 = finiteOr0(r0.data()[k]);
            const double d = (x - x0) - (y - y0);
            rel += d * d / (y * y + 0.01);
            const double td = (double(tonemapForMetrics(float(x))) - tonemapForMetrics(float(x0))) -
                              (double(tonemapForMetrics(float(y))) - tonemapForMetrics(float(y0)));
            tse += td * td;
        }
    const double n = 3.0 * double(plane);
    TemporalMetrics m;
    m.relMse = rel / n;
    m.psnr = tse > 0 ? 10.0 * std::log10(n / tse) : 100.0;  // as computeMetrics: equal differences capped at 100 dB
    return m;
}

namespace {

// A frame's G-buffer as the temporal filter's hop reads it (svgf_gbuffer.h: missing buffers take
// the sanitiser's defaults, which every test passes), owned here.
struct Guide {
    Image depth, normal, ids, motion, grad;
    temporal::FrameViews views(const Image& image) const {
        temporal::FrameViews v;
        v.depth = depth.view(), v.normal = normal.view(), v.ids = ids.view(), v.motion = motion.view(), v.grad = grad.view();
        v.color = image.view();
        return v;
    }
};

ImageView viewOf(const Image* img) { return img && !img->empty() ? img->view() : ImageView{}; }

Guide sanitise(const CpuExec& exec, const Frame& f, int w, int h) {
    for (const Image* b : {f.depth, f.normal, f.ids, f.motion})
        if (b && !b->empty() && (b->width() != w || b->height() != h))
            throw InputError("a buffer of the frames that place the sequence is " + std::to_string(b->width()) + "x" +
                             std::to_string(b->height()) + " but the images are " + std::to_string(w) + "x" + std::to_string(h));
    Guide g;
    g.depth = Image::uninitialized(w, h, 1), g.normal = Image::uninitialized(w, h, 3), g.ids = Image::uninitialized(w, h, 1);
    g.motion = Image::uninitialized(w, h, 2), g.grad = Image::uninitialized(w, h, 2);
    exec.forEachPixel(w, h, svgf::SanitizeGbuffer{viewOf(f.depth), viewOf(f.normal), viewOf(f.ids), viewOf(f.motion),
                                                  g.depth.view(), g.normal.view(), g.ids.view(), g.motion.view()});
    exec.forEachPixel(w, h, svgf::DepthGradient{g.depth.view(), g.grad.view()});
    return g;
}

}  // namespace

FlickerMetrics computeFlicker(const Image& image, const Image& previous, const Frame& guide, const Frame& previousGuide) {
    checkPair(image, previous);
    if (!guide.motion || guide.motion->empty() || guide.motion->channels() < 2)
        throw InputError("the flicker measure needs the frames' motion vectors (2 channels)");
    const int w = image.width(), h = image.height();
    const CpuExec exec;
    const Guide now = sanitise(exec, guide, w, h), before = sanitise(exec, previousGuide, w, h);
    metrics::FlickerStep step;
    step.hop.from = now.views(image);
    step.hop.to = before.views(previous);
    const TemporalParams defaults;  // the offline filter's tolerances
    step.hop.depthTolerance = defaults.depthTolerance, step.hop.normalCos = defaults.normalCos;
    step.image = image.view(), step.previous = previous.view();
    Image out = Image::uninitialized(w, h, 2);
    step.out = out.view();
    exec.forEachPixel(w, h, step);
    double rel = 0, n = 0;
    const size_t plane = out.plane();
    for (size_t i = 0; i < plane; ++i) rel += out.data()[i], n += out.data()[plane + i];
    FlickerMetrics m;
    m.reprojected = n / double(plane);
    m.relMse = n > 0 ? rel / n : 0.0;
    return m;
}

float tonemapForMetrics(float x) {
    x = finiteOr0(x);
    if (x <= 0) return 0.0f;
    float t = std::pow(x / (1.0f + x), 1.0f / 2.2f);
    return t < 0 ? 0 : (t > 1 ? 1 : t);
}

unsigned char tonemap8(float x) { return displayByte(tonemapForMetrics(x)); }

ImageMetrics computeMetrics(const Image& a, const Image& r) {
    checkPair(a, r);
    const int w = a.width(), h = a.height();
    const size_t plane = a.plane();
    ImageMetrics m;
    double se = 0, rel = 0, tse = 0;
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < plane; ++i) {
            const double x = finiteOr0(a.data()[c * plane + i]), ref = finiteOr0(r.data()[c * plane + i]);
            const double d = x - ref;
            se += d * d;
            rel += d * d / (ref * ref + 0.01);
            const double td = double(tonemapForMetrics(float(x))) - tonemapForMetrics(float(ref));
            tse += td * td;
        }
    for (size_t i = 0; i < plane; ++i) {
        auto bad = [&](const Image& img) {
            return !std::isfinite(img.data()[i]) || !std::isfinite(img.data()[plane + i]) ||
                   !std::isfinite(img.data()[2 * plane + i]);
        };
        m.nonFinitePixels += bad(a);
        m.referenceNonFinitePixels += bad(r);
    }
    const double n = 3.0 * double(plane);
    m.mse = se / n;
    m.relMse = rel / n;
    const double tmse = tse / n;
    m.psnr = tmse > 0 ? 10.0 * std::log10(1.0 / tmse) : 100.0;  // identical images: capped at 100 dB
    // SSIM (Wang et al. 2004) on tonemapped luminance, dynamic range L = 1.
    std::vector<double> X(plane), Y(plane), XX(plane), YY(plane), XY(plane);
    for (size_t i = 0; i < plane; ++i) {
        const double lx = 0.2126 * tonemapForMetrics(a.data()[i]) + 0.7152 * tonemapForMetrics(a.data()[plane + i]) +
                          0.0722 * tonemapForMetrics(a.data()[2 * plane + i]);
        const double ly = 0.2126 * tonemapForMetrics(r.data()[i]) + 0.7152 * tonemapForMetrics(r.data()[plane + i]) +
                          0.0722 * tonemapForMetrics(r.data()[2 * plane + i]);
        X[i] = lx;
        Y[i] = ly;
        XX[i] = lx * lx;
        YY[i] = ly * ly;
        XY[i] = lx * ly;
    }
    const auto mx = blur(X, w, h), my = blur(Y, w, h), mxx = blur(XX, w, h), myy = blur(YY, w, h), mxy = blur(XY, w, h);
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    double ssim = 0;
    for (size_t i = 0; i < plane; ++i) {
        const double sx = mxx[i] - mx[i] * mx[i], sy = myy[i] - my[i] * my[i], sxy = mxy[i] - mx[i] * my[i];
        ssim += ((2 * mx[i] * my[i] + c1) * (2 * sxy + c2)) / ((mx[i] * mx[i] + my[i] * my[i] + c1) * (sx + sy + c2));
    }
    m.ssim = ssim / double(plane);
    return m;
}

static Image errorMap(const Image& a, const Image& r, bool relative) {
    checkPair(a, r);
    Image out(a.width(), a.height(), 3, Device::Cpu);
    const size_t plane = a.plane();
    for (size_t i = 0; i < plane; ++i) {
        double e = 0;
        for (int c = 0; c < 3; ++c) {
            const double x = finiteOr0(a.data()[c * plane + i]), ref = finiteOr0(r.data()[c * plane + i]);
            const double d2 = (x - ref) * (x - ref);
            e += relative ? d2 / (ref * ref + 0.01) : d2;
        }
        for (int c = 0; c < 3; ++c) out.data()[c * plane + i] = float(e / 3.0);
    }
    return out;
}

Image squaredErrorMap(const Image& a, const Image& r) { return errorMap(a, r, false); }
Image relativeErrorMap(const Image& a, const Image& r) { return errorMap(a, r, true); }

}  // namespace atrous

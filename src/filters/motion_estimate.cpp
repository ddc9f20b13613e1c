// Motion from the frames themselves (include/atrous/temporal.h, estimateMotion): coarse-to-fine
// block matching on a log-luminance guide, for sequences that carry neither motion vectors nor a
// Position pass. Host images; the blocks of a level are matched in parallel.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "atrous/error.h"
#include "atrous/temporal.h"

namespace atrous {

namespace {

struct Plane {
    int w = 0, h = 0;
    std::vector<float> v;
    float at(int x, int y) const { return v[size_t(y) * size_t(w) + size_t(x)]; }
};

// log(1 + luminance) of a 3x3 box average (the noise of a few samples per pixel averages down; the
// log keeps a bright light from outweighing the rest). Non-finite values count as 0.
Plane guideOf(const Image& img) {
    Plane p;
    p.w = img.width(), p.h = img.height();
    const int c = std::min(img.channels(), 3);
    std::vector<float> lum(size_t(p.w) * size_t(p.h));
    for (int y = 0; y < p.h; ++y)
        for (int x = 0; x < p.w; ++x) {
            float l = 0;
            const float wts[3] = {0.2126f, 0.7152f, 0.0722f};
            for (int k = 0; k < c; ++k) {
                const float v = img(x, y, k);
                l += (c == 1 ? 1.0f : wts[k]) * (std::isfinite(v) ? std::max(v, 0.0f) : 0.0f);
            }
            lum[size_t(y) * size_t(p.w) + size_t(x)] = l;
        }
    // The 3x3 box, separably: along the rows, then the columns (the taps inside the image only).
    auto pass = [&](const std::vector<float>& in, std::vector<float>& out, int sx, int sy) {
        out.resize(in.size());
        for (int y = 0; y < p.h; ++y)
            for (int x = 0; x < p.w; ++x) {
                float s = 0;
                int n = 0;
                for (int d = -1; d <= 1; ++d) {
                    const int xx = x + d * sx, yy = y + d * sy;
                    if (xx >= 0 && yy >= 0 && xx < p.w && yy < p.h) s += in[size_t(yy) * size_t(p.w) + size_t(xx)], ++n;
                }
                out[size_t(y) * size_t(p.w) + size_t(x)] = s / float(n);
            }
    };
    std::vector<float> rows;
    pass(lum, rows, 1, 0);
    pass(rows, p.v, 0, 1);
    for (float& v : p.v) v = std::log1p(v);
    return p;
}

Plane half(const Plane& p) {
    Plane q;
    q.w = std::max(1, p.w / 2), q.h = std::max(1, p.h / 2);
    q.v.resize(size_t(q.w) * size_t(q.h));
    for (int y = 0; y < q.h; ++y)
        for (int x = 0; x < q.w; ++x) {
            const int x0 = std::min(2 * x, p.w - 1), x1 = std::min(2 * x + 1, p.w - 1);
            const int y0 = std::min(2 * y, p.h - 1), y1 = std::min(2 * y + 1, p.h - 1);
            q.v[size_t(y) * size_t(q.w) + size_t(x)] = 0.25f * (p.at(x0, y0) + p.at(x1, y0) + p.at(x0, y1) + p.at(x1, y1));
        }
    return q;
}

// Mean squared difference between cur's window around block (bx, by) and prev's shifted by (dx, dy);
// taps outside either image are left out (infinity when fewer than half remain).
float cost(const Plane& cur, const Plane& prev, int x0, int y0, int size, int dx, int dy) {
    double s = 0;
    int n = 0;
    const int m = size / 2;  // the window: the block and half a block around it
    for (int y = y0 - m; y < y0 + size + m; ++y)
        for (int x = x0 - m; x < x0 + size + m; ++x) {
            const int px = x + dx, py = y + dy;
            if (x < 0 || y < 0 || x >= cur.w || y >= cur.h || px < 0 || py < 0 || px >= prev.w || py >= prev.h) continue;
            const float d = cur.at(x, y) - prev.at(px, py);
            s += double(d) * d, ++n;
        }
    const int full = (size + 2 * m) * (size + 2 * m);
    return 2 * n < full ? std::numeric_limits<float>::infinity() : float(s / n);
}

}  // namespace

Image estimateMotion(const Image& current, const Image* previousFrame, const MotionEstimateParams& p) {
    if (!current.empty() && current.device() == Device::Cpu && !previousFrame) {
        Image none(current.width(), current.height(), 2);
        none.fill(std::nanf(""));  // no history
        return none;
    }
    const Image& previous = previousFrame ? *previousFrame : current;
    if (current.empty() || previous.empty() || current.device() != Device::Cpu || previous.device() != Device::Cpu)
        throw InputError("motion estimate: the frames must be host images");
    if (current.width() != previous.width() || current.height() != previous.height())
        throw InputError("motion estimate: the frames differ in size");
    if (p.block < 2 || p.levels < 1 || p.radius < 1) throw InputError("motion estimate: block >= 2, levels >= 1, radius >= 1");
    std::vector<Plane> cur{guideOf(current)}, prev{guideOf(previous)};
    while (int(cur.size()) < p.levels && std::min(cur.back().w, cur.back().h) >= 4 * p.block)
        cur.push_back(half(cur.back())), prev.push_back(half(prev.back()));
    // Block vectors of the level below (coarser), in that level's pixels; none at the coarsest.
    int bw = 0, bh = 0;
    std::vector<float> vx, vy;
    for (int level = int(cur.size()) - 1; level >= 0; --level) {
        const Plane &c = cur[size_t(level)], &q = prev[size_t(level)];
        const int nbw = (c.w + p.block - 1) / p.block, nbh = (c.h + p.block - 1) / p.block;
        std::vector<float> nx(size_t(nbw) * size_t(nbh)), ny(nx.size());
        const bool coarsest = vx.empty();
        const int r = coarsest ? p.radius : 1;
        tbb::parallel_for(0, nbh, [&](int by) {
            for (int bx = 0; bx < nbw; ++bx) {
                // Candidates: zero, and the coarser level's vectors (doubled) of this block and its
                // four neighbours, each refined by ±r; the cheapest within 2% is taken, nearest the
                // block's own prediction (flat regions keep the prediction instead of noise).
                std::vector<std::pair<int, int>> seeds{{0, 0}};
                int px = 0, py = 0;
                if (!coarsest) {
                    const int cx = std::min(bx / 2, bw - 1), cy = std::min(by / 2, bh - 1);
                    px = int(std::lround(2 * vx[size_t(cy) * bw + cx])), py = int(std::lround(2 * vy[size_t(cy) * bw + cx]));
                    const int nb[5][2] = {{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1}};
                    for (const auto& o : nb) {
                        const int ex = std::clamp(cx + o[0], 0, bw - 1), ey = std::clamp(cy + o[1], 0, bh - 1);
                        seeds.emplace_back(int(std::lround(2 * vx[size_t(ey) * bw + ex])), int(std::lround(2 * vy[size_t(ey) * bw + ex])));
                    }
                }
                std::vector<std::pair<float, std::pair<int, int>>> tried;
                for (const auto& s : seeds)
                    for (int dy = -r; dy <= r; ++dy)
                        for (int dx = -r; dx <= r; ++dx) {
                            const int mx = s.first + dx, my = s.second + dy;
                            bool seen = false;
                            for (const auto& t : tried) seen = seen || (t.second.first == mx && t.second.second == my);
                            if (!seen) tried.push_back({cost(c, q, bx * p.block, by * p.block, p.block, mx, my), {mx, my}});
                        }
                float best = std::numeric_limits<float>::infinity();
                for (const auto& t : tried) best = std::min(best, t.first);
                int bestX = px, bestY = py;
                if (std::isfinite(best)) {
                    long long bestD = -1;
                    for (const auto& t : tried) {
                        if (!(t.first <= best * 1.02f + 1e-7f)) continue;
                        const long long ddx = t.second.first - px, ddy = t.second.second - py, d = ddx * ddx + ddy * ddy;
                        if (bestD < 0 || d < bestD) bestD = d, bestX = t.second.first, bestY = t.second.second;
                    }
                }
                nx[size_t(by) * nbw + bx] = float(bestX), ny[size_t(by) * nbw + bx] = float(bestY);
            }
        });
        vx.swap(nx), vy.swap(ny), bw = nbw, bh = nbh;
    }
    // Per pixel: the block vectors, bilinear between block centres (a camera's smooth field; what
    // moves differently is the temporal tests' to reject).
    const int w = current.width(), h = current.height();
    Image motion = Image::uninitialized(w, h, 2);
    tbb::parallel_for(0, h, [&](int y) {
        const float fy = std::clamp((y + 0.5f) / p.block - 0.5f, 0.0f, float(bh - 1));
        const int y0 = int(fy), y1 = std::min(y0 + 1, bh - 1);
        const float ty = fy - y0;
        for (int x = 0; x < w; ++x) {
            const float fx = std::clamp((x + 0.5f) / p.block - 0.5f, 0.0f, float(bw - 1));
            const int x0 = int(fx), x1 = std::min(x0 + 1, bw - 1);
            const float tx = fx - x0;
            auto lerp = [&](const std::vector<float>& v) {
                const float a = v[size_t(y0) * bw + x0] * (1 - tx) + v[size_t(y0) * bw + x1] * tx;
                const float b = v[size_t(y1) * bw + x0] * (1 - tx) + v[size_t(y1) * bw + x1] * tx;
                return a * (1 - ty) + b * ty;
            };
            motion(x, y, 0) = lerp(vx), motion(x, y, 1) = lerp(vy);
        }
    });
    return motion;
}

}  // namespace atrous

namespace atrous {

Image StreamMotion::next(const Frame& frame, const Frame* previous) {
    if (!frame.color || frame.color->empty()) throw InputError("motion of a frame: its color buffer is missing");
    mFrames = previous ? mFrames + 1 : 1;
    if (frame.position && !frame.position->empty()) {
        mFrom = From::Positions;
        const CameraFit fit = fitCamera(*frame.position);
        mPrevious = previous ? mCamera : CameraFit{};  // a first frame: no previous camera, NaN (no history)
        mCamera = fit;
        return motionFromPositions(*frame.position, fit, mPrevious);
    }
    mFrom = From::Colours;
    const Image* before = previous ? previous->color : nullptr;
    const bool usable = before && !before->empty() && before->view().sameSize(frame.color->view());
    return estimateMotion(*frame.color, usable ? before : nullptr);
}

}  // namespace atrous

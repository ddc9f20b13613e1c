// Motion vectors from the Position pass (include/atrous/temporal.h, docs/temporal.md): each frame's
// camera is fitted to its own pixels and world positions (the direct linear transform, Hartley's
// normalisation), and a pixel's motion is its position's projection in the previous frame's camera
// minus that in its own. For renderers that write positions but no vectors (LuxCore's POSITION); right for a
// static scene seen by a moving pinhole camera, wrong on what moves (which the sequence tests
// leave out).
#include <algorithm>
#include <cmath>
#include <vector>

#include "atrous/error.h"
#include "atrous/temporal.h"

namespace atrous {

namespace {

constexpr int kMaxFitPoints = 4096;  // a regular subset of the hit pixels: plenty for 11 unknowns

bool hit(const Image& p, int x, int y, double P[3]) {
    for (int c = 0; c < 3; ++c) {
        P[c] = double(p(x, y, c));
        if (!std::isfinite(P[c]) || std::fabs(P[c]) > 1e15) return false;
    }
    return !(P[0] == 0.0 && P[1] == 0.0 && P[2] == 0.0);  // renderers write 0 where nothing is hit
}

// Solves the n x n system A x = b in place (Gaussian elimination, partial pivoting); false when singular.
bool solve(std::vector<double>& A, std::vector<double>& b, int n) {
    for (int k = 0; k < n; ++k) {
        int piv = k;
        for (int i = k + 1; i < n; ++i)
            if (std::fabs(A[size_t(i * n + k)]) > std::fabs(A[size_t(piv * n + k)])) piv = i;
        if (!(std::fabs(A[size_t(piv * n + k)]) > 1e-12)) return false;
        if (piv != k) {
            for (int j = 0; j < n; ++j) std::swap(A[size_t(k * n + j)], A[size_t(piv * n + j)]);
            std::swap(b[size_t(k)], b[size_t(piv)]);
        }
        for (int i = k + 1; i < n; ++i) {
            const double f = A[size_t(i * n + k)] / A[size_t(k * n + k)];
            for (int j = k; j < n; ++j) A[size_t(i * n + j)] -= f * A[size_t(k * n + j)];
            b[size_t(i)] -= f * b[size_t(k)];
        }
    }
    for (int i = n - 1; i >= 0; --i) {
        double s = b[size_t(i)];
        for (int j = i + 1; j < n; ++j) s -= A[size_t(i * n + j)] * b[size_t(j)];
        b[size_t(i)] = s / A[size_t(i * n + i)];
    }
    return true;
}

}  // namespace

bool CameraFit::project(const double P[3], double& u, double& v) const {
    const double w = m[8] * P[0] + m[9] * P[1] + m[10] * P[2] + m[11];
    if (!(w > 0.0)) return false;  // behind the camera
    u = (m[0] * P[0] + m[1] * P[1] + m[2] * P[2] + m[3]) / w;
    v = (m[4] * P[0] + m[5] * P[1] + m[6] * P[2] + m[7]) / w;
    return std::isfinite(u) && std::isfinite(v);
}

namespace {

struct Pt {
    double P[3], u, v;
};

// The least-squares camera of `pts` (normalised DLT); false when the system is singular.
bool fitOnce(const std::vector<Pt>& pts, double m[12]) {
    // Hartley: pixels to mean 0, mean distance √2; points to mean 0, mean distance √3.
    double cu = 0, cv = 0, cP[3] = {0, 0, 0};
    for (const Pt& p : pts) cu += p.u, cv += p.v, cP[0] += p.P[0], cP[1] += p.P[1], cP[2] += p.P[2];
    const double n = double(pts.size());
    cu /= n, cv /= n;
    for (double& c : cP) c /= n;
    double du = 0, dP = 0;
    for (const Pt& p : pts) {
        du += std::hypot(p.u - cu, p.v - cv);
        dP += std::sqrt((p.P[0] - cP[0]) * (p.P[0] - cP[0]) + (p.P[1] - cP[1]) * (p.P[1] - cP[1]) +
                        (p.P[2] - cP[2]) * (p.P[2] - cP[2]));
    }
    if (!(du > 0) || !(dP > 0)) return false;
    const double su = std::sqrt(2.0) * n / du, sP = std::sqrt(3.0) * n / dP;
    // Normalised DLT with the last entry fixed to 1 (the points' centroid, now the origin, is in
    // front of the camera, so it is not 0): 11 unknowns, normal equations.
    std::vector<double> AtA(121, 0.0), Atb(11, 0.0);
    for (const Pt& p : pts) {
        const double X = (p.P[0] - cP[0]) * sP, Y = (p.P[1] - cP[1]) * sP, Z = (p.P[2] - cP[2]) * sP;
        const double u = (p.u - cu) * su, v = (p.v - cv) * su;
        const double r1[11] = {X, Y, Z, 1, 0, 0, 0, 0, -u * X, -u * Y, -u * Z};
        const double r2[11] = {0, 0, 0, 0, X, Y, Z, 1, -v * X, -v * Y, -v * Z};
        for (int a = 0; a < 11; ++a) {
            for (int b = 0; b < 11; ++b) AtA[size_t(a * 11 + b)] += r1[a] * r1[b] + r2[a] * r2[b];
            Atb[size_t(a)] += r1[a] * u + r2[a] * v;
        }
    }
    if (!solve(AtA, Atb, 11)) return false;
    // Undo the normalisations: M = T_uv^-1 · Mn · T_P.
    double Mn[12];
    for (int k = 0; k < 11; ++k) Mn[k] = Atb[size_t(k)];
    Mn[11] = 1.0;
    const double Tp[16] = {sP, 0, 0, -sP * cP[0], 0, sP, 0, -sP * cP[1], 0, 0, sP, -sP * cP[2], 0, 0, 0, 1};
    const double Ti[9] = {1 / su, 0, cu, 0, 1 / su, cv, 0, 0, 1};
    double MT[12];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += Mn[r * 4 + k] * Tp[k * 4 + c];
            MT[r * 4 + c] = s;
        }
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) {
            double s = 0;
            for (int k = 0; k < 3; ++k) s += Ti[r * 3 + k] * MT[k * 4 + c];
            m[r * 4 + c] = s;
        }
    return true;
}

}  // namespace

CameraFit fitCamera(const Image& position) {
    CameraFit fit;
    if (position.empty() || position.channels() < 3 || position.device() != Device::Cpu)
        throw InputError("camera fit: the position buffer must be a host image with 3 channels");
    const int w = position.width(), h = position.height();
    size_t hits = 0;
    double P[3];
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) hits += hit(position, x, y, P);
    if (hits < 64) return fit;  // not enough of the frame is geometry
    const size_t stride = std::max<size_t>(1, hits / kMaxFitPoints);
    std::vector<Pt> pts;
    size_t i = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (hit(position, x, y, P) && i++ % stride == 0) pts.push_back({{P[0], P[1], P[2]}, double(x), double(y)});
    // Trimmed least squares: a renderer whose positions follow mirrors and glass (atrous's, OIDN's
    // convention for the features) puts those pixels far off any pinhole; each round drops the
    // points more than max(3 median, 1.5 px) off the last fit and fits again.
    std::vector<Pt> kept = pts;
    std::vector<double> err;
    for (int round = 0; round < 4; ++round) {
        if (kept.size() < 32 || !fitOnce(kept, fit.m)) return CameraFit{};
        // Points in front of the camera have w > 0: flip the sign of M if the fit came out the other way.
        double u, v;
        size_t front = 0;
        for (const Pt& p : kept) front += fit.project(p.P, u, v);
        if (2 * front < kept.size())
            for (double& x : fit.m) x = -x;
        err.clear();
        for (const Pt& p : pts) err.push_back(fit.project(p.P, u, v) ? std::hypot(u - p.u, v - p.v) : 1e30);
        std::vector<double> sorted = err;
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        fit.medianErrorPx = sorted[sorted.size() / 2];
        const double cut = std::max(3.0 * fit.medianErrorPx, 1.5);
        kept.clear();
        for (size_t k = 0; k < pts.size(); ++k)
            if (err[k] <= cut) kept.push_back(pts[k]);
    }
    fit.ok = std::isfinite(fit.medianErrorPx) && fit.medianErrorPx <= kCameraFitMaxErrorPx;
    return fit;
}

Image motionFromPositions(const Image& position, const CameraFit& current, const CameraFit& previous) {
    if (position.empty() || position.channels() < 3 || position.device() != Device::Cpu)
        throw InputError("motion from positions: the position buffer must be a host image with 3 channels");
    const int w = position.width(), h = position.height();
    // Where nothing is hit (the sky), the pixel's direction: the infinite homography
    // H = A_prev · A_cur^-1 of the cameras' left 3x3 blocks maps it to the previous frame.
    double H[9] = {};
    bool haveH = false;
    if (current.ok && previous.ok) {
        const double* a = current.m;  // rows 0..2, columns 0..2 of the 3x4
        const double A[9] = {a[0], a[1], a[2], a[4], a[5], a[6], a[8], a[9], a[10]};
        const double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
                           A[2] * (A[3] * A[7] - A[4] * A[6]);
        if (std::fabs(det) > 1e-300) {
            const double inv[9] = {(A[4] * A[8] - A[5] * A[7]) / det, (A[2] * A[7] - A[1] * A[8]) / det,
                                   (A[1] * A[5] - A[2] * A[4]) / det, (A[5] * A[6] - A[3] * A[8]) / det,
                                   (A[0] * A[8] - A[2] * A[6]) / det, (A[2] * A[3] - A[0] * A[5]) / det,
                                   (A[3] * A[7] - A[4] * A[6]) / det, (A[1] * A[6] - A[0] * A[7]) / det,
                                   (A[0] * A[4] - A[1] * A[3]) / det};
            const double* b = previous.m;
            const double B[9] = {b[0], b[1], b[2], b[4], b[5], b[6], b[8], b[9], b[10]};
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) H[r * 3 + c] = B[r * 3] * inv[c] + B[r * 3 + 1] * inv[3 + c] + B[r * 3 + 2] * inv[6 + c];
            haveH = true;
        }
    }
    Image motion = Image::uninitialized(w, h, 2);
    double P[3], u, v;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool ok = false;
            double cu, cv;
            if (hit(position, x, y, P)) {
                // The point's own motion, project(prev) - project(current): a 1-spp position is one
                // sample's, up to half a pixel off the pixel's centre, and that offset cancels here.
                ok = previous.ok && current.ok && previous.project(P, u, v) && current.project(P, cu, cv);
                if (ok) u += x - cu, v += y - cv;
            } else if (haveH) {
                const double q = H[6] * x + H[7] * y + H[8];
                u = (H[0] * x + H[1] * y + H[2]) / q, v = (H[3] * x + H[4] * y + H[5]) / q;
                ok = q > 0.0 && std::isfinite(u) && std::isfinite(v);
            }
            motion(x, y, 0) = ok ? float(u - x) : NAN;  // NaN: no history
            motion(x, y, 1) = ok ? float(v - y) : NAN;
        }
    return motion;
}

}  // namespace atrous

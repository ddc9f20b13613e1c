// CPU fast path of the firefly pass (filters::FireflyClamp). The generic functor gathers its 3×3
// neighbourhood with clamped indices and did not vectorise (the per-pixel call stayed a call);
// here each task computes the luminance and luminance variance of the three rows once, and an x
// loop over the interior columns reads the 8 neighbours from those rows and runs the shared
// FireflyClamp::apply. Rows clamp as in the functor (row pointers of y±1 clamped); the two border
// columns go through the functor itself.
// FP exceptions are never unmasked or tested here; without -ftrapping-math GCC if-converts the
// selects of the firefly rule, which it otherwise keeps as branches (no vectorisation). Results
// are the same: no reassociation or contraction is allowed by this.
#include "atrous/platform.h"
ATROUS_NO_TRAPPING_MATH

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <vector>

#include "core/parallel.h"
#include "core/isa_dispatch.h"
#include "filters/prepass.h"

namespace atrous::filters {

void runFireflyClamp(const CpuExec& exec, const FireflyClamp& f, int* clamped) {
    const int w = f.cIn.width, h = f.cIn.height;
    if (w < 3) {
        exec.forEachPixel(w, h, f);
        if (clamped) {
            // The decisions again, for the count (tiny images only).
            int n = 0;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    float l[8], lv[8];
                    int k = 0;
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            if (dx == 0 && dy == 0) continue;
                            const int xx = clampIdx(x + dx, w - 1), yy = clampIdx(y + dy, h - 1);
                            l[k] = lum(f.cIn(xx, yy, 0), f.cIn(xx, yy, 1), f.cIn(xx, yy, 2));
                            lv[k] = lumVarianceIndependent(f.vIn(xx, yy, 0), f.vIn(xx, yy, 1), f.vIn(xx, yy, 2));
                            ++k;
                        }
                    bool c;
                    f.scaleOf(x, y, l, lv, c);
                    n += c;
                }
            *clamped = n;
        }
        return;
    }
    std::vector<int> rowCount(size_t(h), 0);
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 8, [&](int r0, int r1) {
        const FireflyClamp g = f;  // a local copy: its views cannot alias the stores
        std::vector<float> rowsL(size_t(3) * w), rowsV(size_t(3) * w);
        std::vector<float> scratch(w);  // flag row when no flag view was given
        for (int y = r0; y < r1; ++y) {
            for (int k = 0; k < 3; ++k) {
                const int yy = clampIdx(y + k - 1, h - 1);
                const size_t o = size_t(yy) * w;
                const float* ATROUS_RESTRICT cr = g.cIn.channel(0) + o;
                const float* ATROUS_RESTRICT cg = g.cIn.channel(1) + o;
                const float* ATROUS_RESTRICT cb = g.cIn.channel(2) + o;
                const float* ATROUS_RESTRICT vr = g.vIn.channel(0) + o;
                const float* ATROUS_RESTRICT vg = g.vIn.channel(1) + o;
                const float* ATROUS_RESTRICT vb = g.vIn.channel(2) + o;
                float* ATROUS_RESTRICT L = rowsL.data() + size_t(k) * w;
                float* ATROUS_RESTRICT V = rowsV.data() + size_t(k) * w;
#pragma omp simd
                for (int x = 0; x < w; ++x) {
                    L[x] = lum(cr[x], cg[x], cb[x]);
                    V[x] = lumVarianceIndependent(vr[x], vg[x], vb[x]);
                }
            }
            const float* ATROUS_RESTRICT L0 = rowsL.data();
            const float* ATROUS_RESTRICT L1 = L0 + w;
            const float* ATROUS_RESTRICT L2 = L1 + w;
            const float* ATROUS_RESTRICT V0 = rowsV.data();
            const float* ATROUS_RESTRICT V1 = V0 + w;
            const float* ATROUS_RESTRICT V2 = V1 + w;
            g(0, y);
            float* ATROUS_RESTRICT flag = g.flag.valid() ? g.flag.channel(0) + size_t(y) * w : scratch.data();
#pragma omp simd
            for (int x = 1; x < w - 1; ++x) {
                const float l[8] = {L0[x - 1], L0[x], L0[x + 1], L1[x - 1], L1[x + 1], L2[x - 1], L2[x], L2[x + 1]};
                const float lv[8] = {V0[x - 1], V0[x], V0[x + 1], V1[x - 1], V1[x + 1], V2[x - 1], V2[x], V2[x + 1]};
                flag[x] = g.apply(x, y, l, lv);
            }
            g(w - 1, y);
            if (clamped) {
                int n = 0;
                for (int x = 1; x < w - 1; ++x) n += flag[x] > 0.5f;
                // The border pixels' decisions (the functor wrote them to the flag view, if any).
                for (int x : {0, w - 1}) {
                    if (g.flag.valid()) {
                        n += g.flag(x, y, 0) > 0.5f;
                        continue;
                    }
                    const int xm = clampIdx(x - 1, w - 1), xp = clampIdx(x + 1, w - 1);
                    const float l[8] = {L0[xm], L0[x], L0[xp], L1[xm], L1[xp], L2[xm], L2[x], L2[xp]};
                    const float lv[8] = {V0[xm], V0[x], V0[xp], V1[xm], V1[xp], V2[xm], V2[x], V2[xp]};
                    bool c;
                    g.scaleOf(x, y, l, lv, c);
                    n += c;
                }
                rowCount[size_t(y)] = n;
            }
        }
    });
    if (clamped) {
        int n = 0;
        for (int c : rowCount) n += c;
        *clamped = n;
    }
}

// The dense-firefly step: each row's window sums of the flags along x by a sliding sum (into tmp),
// then per band of rows the column sums of those slid down y, and the functor's decision
// (FireflyDense::decide) for the clamped pixels whose window may be dense. The flags are 0 or 1, so every partial sum is an exact integer below 2^24 and
// the sliding sums equal BoxSum's tap-order sums bit for bit. Only clamped pixels are decided again.
void runFireflyDense(const CpuExec&, const FireflyClamp& f, const ImageView& tmp, const ImageView&) {
    const int w = f.cIn.width, h = f.cIn.height, r = kFireflyDenseRadius;
    // Row j's window sums along x into `out`, by a sliding sum in three stretches without tests:
    // x < r (nothing leaves the window yet), both ends inside, x + r + 1 >= w (nothing enters).
    auto rowSums = [&](int j, float* ATROUS_RESTRICT out) {
        // In integers: the float form's add-subtract chain cost 8 cycles a pixel of latency.
        const float* ATROUS_RESTRICT in = f.flag.channel(0) + size_t(j) * w;
        int s = 0;
        for (int x = 0; x <= std::min(r, w - 1); ++x) s += in[x] > 0.5f;
        const int a = std::min(r, w), b = std::max(w - r - 1, a);
        int x = 0;
        for (; x < a; ++x) {
            out[x] = float(s);
            if (x + r + 1 < w) s += in[x + r + 1] > 0.5f;
        }
        for (; x < b; ++x) {
            out[x] = float(s);
            s += int(in[x + r + 1] > 0.5f) - int(in[x - r] > 0.5f);
        }
        for (; x < w; ++x) {
            out[x] = float(s);
            s -= in[x - r] > 0.5f;
        }
    };
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 16, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) rowSums(y, tmp.channel(0) + size_t(y) * w);
    });
    // Then per band of rows the column sums of those, slid down y (the flags of other rows are
    // not read any more, so the decisions below may rewrite them).
    const FireflyDense dense{f, ImageView{}};
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 32, [&](int y0, int y1) {
        std::vector<float> colStore(size_t(w), 0.0f);
        std::vector<unsigned char> candStore(size_t(w) + 8, 0);
        float* ATROUS_RESTRICT col = colStore.data();
        for (int j = std::max(y0 - r, 0); j <= std::min(y0 + r, h - 1); ++j) {
            const float* ATROUS_RESTRICT row = tmp.channel(0) + size_t(j) * w;
            for (int x = 0; x < w; ++x) col[x] += row[x];
        }
        for (int y = y0; y < y1; ++y) {
            const float ny = float(std::min(y + r, h - 1) - std::max(y - r, 0) + 1);
            const float* flag = f.flag.channel(0) + size_t(y) * w;  // rewritten below: no restrict
            // Candidates without branches (clamped, and the window nearly dense: a margin below the
            // threshold, so that the functor's exact test decides), then a scan of them.
            unsigned char* ATROUS_RESTRICT cand = candStore.data();
            const float lo = kFireflyDenseLo * (1.0f - 1e-5f) * ny;
            for (int x = 0; x < w; ++x) {
                const float nx = float(std::min(x + r, w - 1) - std::max(x - r, 0) + 1);
                cand[x] = (flag[x] > 0.5f) & (col[x] > lo * nx);
            }
            for (int x0 = 0; x0 < w; x0 += 8) {
                std::uint64_t word = 0;
                std::memcpy(&word, cand + x0, 8);  // candStore has 8 bytes of slack
                if (word == 0) continue;
                for (int x = x0; x < std::min(x0 + 8, w); ++x)
                    if (cand[x]) dense.decide(x, y, col[x]);
            }
            if (y + 1 < y1) {  // slide the column sums to row y + 1
                if (y + r + 1 < h) {
                    const float* ATROUS_RESTRICT add = tmp.channel(0) + size_t(y + r + 1) * w;
                    for (int x = 0; x < w; ++x) col[x] += add[x];
                }
                if (y - r >= 0) {
                    const float* ATROUS_RESTRICT sub = tmp.channel(0) + size_t(y - r) * w;
                    for (int x = 0; x < w; ++x) col[x] -= sub[x];
                }
            }
        }
    });
}

}  // namespace atrous::filters

namespace atrous::filters {

void runSanitizeColor(const CpuExec&, const SanitizeColor& f) {
    const int w = f.colorIn.width, h = f.colorIn.height;
    // Rows of an in-place plane (out = in) that hold a non-finite value: repaired after the scan,
    // from the values as given (a repair reads its 5x5 neighbours, which may be repaired too).
    struct Bad {
        int k, c, y;
    };
    std::vector<Bad> bad;
    std::mutex badMutex;
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 8, [&](int r0, int r1) {
        const SanitizeColor g = f;
        for (int y = r0; y < r1; ++y)
            for (int c = 0; c < 3; ++c)
                for (int k = 0; k < (g.varIn.valid() ? 2 : 1); ++k) {
                    const ImageView& in = k == 0 ? g.colorIn : g.varIn;
                    const ImageView& out = k == 0 ? g.colorOut : g.varOut;
                    const float* a = in.channel(c) + size_t(y) * w;
                    float* o = out.channel(c) + size_t(y) * w;
                    int nonFinite = 0;
                    if (a == o) {
#pragma omp simd reduction(| : nonFinite)
                        for (int x = 0; x < w; ++x) nonFinite |= finite(a[x]) ? 0 : 1;
                        if (nonFinite) {
                            std::lock_guard<std::mutex> lock(badMutex);
                            bad.push_back({k, c, y});
                        }
                        continue;
                    }
                    const float* ATROUS_RESTRICT ar = a;
                    float* ATROUS_RESTRICT orow = o;
#pragma omp simd reduction(| : nonFinite)
                    for (int x = 0; x < w; ++x) {
                        orow[x] = ar[x];
                        nonFinite |= finite(ar[x]) ? 0 : 1;
                    }
                    if (!nonFinite) continue;
                    // Rare: the functor's repair (mean of the finite 5×5 neighbours).
                    for (int x = 0; x < w; ++x)
                        if (!finite(a[x])) o[x] = SanitizeColor::fix(in, x, y, c);
                }
    });
    if (bad.empty()) return;
    std::vector<std::pair<float*, float>> repairs;
    for (const Bad& b : bad) {
        const ImageView& in = b.k == 0 ? f.colorIn : f.varIn;
        float* row = in.channel(b.c) + size_t(b.y) * w;
        for (int x = 0; x < w; ++x)
            if (!finite(row[x])) repairs.emplace_back(row + x, SanitizeColor::fix(in, x, b.y, b.c));
    }
    for (const auto& r : repairs) *r.first = r.second;
}

void runCopy3(const CpuExec&, const ImageView& in, const ImageView& out) {
    const int w = in.width, h = in.height;
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 32, [&](int r0, int r1) {
        for (int c = 0; c < 3; ++c)
            std::memcpy(out.channel(c) + size_t(r0) * w, in.channel(c) + size_t(r0) * w, size_t(r1 - r0) * w * sizeof(float));
    });
}

ImageView sanitizedFeature(const CpuExec& exec, ImageView in, int width, int height, int channels, Image& storage) {
    if (in.valid()) {
        // sanitizeFeature(a) == a exactly where a is finite and |a| <= kFeatureClamp.
        std::atomic<bool> clean{true};
        cpu::parallelForIsa(cpu::activeIsa(), 0, height, 16, [&](int r0, int r1) {
            for (int c = 0; c < channels && clean.load(std::memory_order_relaxed); ++c) {
                int bad = 0;
                for (int y = r0; y < r1; ++y) {
                    const float* ATROUS_RESTRICT a = in.channel(c) + size_t(y) * width;
#pragma omp simd reduction(| : bad)
                    for (int x = 0; x < width; ++x) bad |= (a[x] >= -kFeatureClamp) & (a[x] <= kFeatureClamp) ? 0 : 1;
                }
                if (bad) clean.store(false, std::memory_order_relaxed);
            }
        });
        if (clean.load()) {
            storage = Image();
            return in;
        }
    }
    storage = Image(width, height, channels, Device::Cpu);
    if (in.valid()) {
        // The functor's copy as plain row loops (the functor through forEachPixel stayed scalar).
        const ImageView out = storage.view();
        cpu::parallelForIsa(cpu::activeIsa(), 0, height, 16, [&](int r0, int r1) {
            for (int c = 0; c < channels; ++c)
                for (int y = r0; y < r1; ++y) {
                    const float* ATROUS_RESTRICT a = in.channel(c) + size_t(y) * width;
                    float* ATROUS_RESTRICT o = out.channel(c) + size_t(y) * width;
#pragma omp simd
                    for (int x = 0; x < width; ++x) o[x] = sanitizeFeature(a[x]);
                }
        });
    }
    (void)exec;
    return storage.view();
}

void runColorScale(const CpuExec& exec, const ColorScale& f) {
    const int w = f.var.width, h = f.var.height;
    if (w < 3 || f.rawSigma > 0) {
        exec.forEachPixel(w, h, f);
        return;
    }
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 8, [&](int r0, int r1) {
        const ColorScale g = f;  // a local copy: its views cannot alias the stores
        std::vector<float> rows(size_t(3) * w);
        for (int y = r0; y < r1; ++y) {
            // Channel-summed variance of rows y-1, y, y+1 (clamped as in the functor).
            for (int k = 0; k < 3; ++k) {
                const size_t o = size_t(clampIdx(y + k - 1, h - 1)) * w;
                const float* ATROUS_RESTRICT vr = g.var.channel(0) + o;
                const float* ATROUS_RESTRICT vg = g.var.channel(1) + o;
                const float* ATROUS_RESTRICT vb = g.var.channel(2) + o;
                float* ATROUS_RESTRICT V = rows.data() + size_t(k) * w;
#pragma omp simd
                for (int x = 0; x < w; ++x) V[x] = vr[x] + vg[x] + vb[x];
            }
            const float* ATROUS_RESTRICT V0 = rows.data();
            const float* ATROUS_RESTRICT V1 = V0 + w;
            const float* ATROUS_RESTRICT V2 = V1 + w;
            float* ATROUS_RESTRICT S = g.S.channel(0) + size_t(y) * w;
            g(0, y);
#pragma omp simd
            for (int x = 1; x < w - 1; ++x) {
                const float v[9] = {V0[x - 1], V0[x], V0[x + 1], V1[x - 1], V1[x], V1[x + 1], V2[x - 1], V2[x], V2[x + 1]};
                S[x] = g.scale(v);
            }
            g(w - 1, y);
        }
    });
}

void runFootprint(const CpuExec& exec, const Footprint& f) {
    const int w = f.invX.width, h = f.invX.height;
    if (w < 3 || !f.hasPosition || f.rawSigma > 0) {
        exec.forEachPixel(w, h, f);
        return;
    }
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 8, [&](int r0, int r1) {
        const Footprint g = f;  // a local copy: its views cannot alias the stores
        for (int y = r0; y < r1; ++y) {
            const size_t o = size_t(y) * w;
            // Rows above and below; at the top/bottom border the functor's neighbour is the pixel
            // itself (kFootprintBorder): the row pointer then stays valid and the select drops it.
            const int yUp = clampIdx(y - 1, h - 1), yDown = clampIdx(y + 1, h - 1);
            const bool hasUp = yUp != y, hasDown = yDown != y;
            const size_t oUp = size_t(yUp) * w, oDown = size_t(yDown) * w;
            const float* ATROUS_RESTRICT px = g.position.channel(0);
            const float* ATROUS_RESTRICT py = g.position.channel(1);
            const float* ATROUS_RESTRICT pz = g.position.channel(2);
            float* ATROUS_RESTRICT invX = g.invX.channel(0) + o;
            g(0, y);
#pragma omp simd
            for (int x = 1; x < w - 1; ++x) {
                const float cx = px[o + x], cy = py[o + x], cz = pz[o + x];
                const float dR = sq(cx - px[o + x + 1]) + sq(cy - py[o + x + 1]) + sq(cz - pz[o + x + 1]);
                const float dL = sq(cx - px[o + x - 1]) + sq(cy - py[o + x - 1]) + sq(cz - pz[o + x - 1]);
                const float dD = sq(cx - px[oDown + x]) + sq(cy - py[oDown + x]) + sq(cz - pz[oDown + x]);
                const float dU = sq(cx - px[oUp + x]) + sq(cy - py[oUp + x]) + sq(cz - pz[oUp + x]);
                invX[x] = g.invXOf(dR, dL, hasDown ? dD : kFootprintBorder, hasUp ? dU : kFootprintBorder);
            }
            if (g.invZ.valid()) {
                const float* ATROUS_RESTRICT z = g.depth.channel(0) + o;
                float* ATROUS_RESTRICT invZ = g.invZ.channel(0) + o;
#pragma omp simd
                for (int x = 1; x < w - 1; ++x) invZ[x] = 1.0f / maxSel(fabsf(z[x]), 1e-6f);
            }
            g(w - 1, y);
        }
    });
}

// RimAlbedo row by row: the 3x3 minimum and maximum of the largest channel, and the brightest
// black neighbour's reflected colour, as a vertical then a horizontal pass (exact: minima and
// maxima do not round), then the functor's arithmetic (rimAdd). A first pass finds the rows
// whose added term is not all zero (none without a black pixel within one row; none where every
// black neighbour is dark, as a light whose radiance the emission buffer holds); without any,
// `in` itself, with no copy (cornell at 1080p: the pass costs 1-2 ms instead of the plane's 14).
namespace {
struct RimRows {
    const RimAlbedo& f;
    int w, h;
    std::vector<float> buf;
    float *vm, *vx, *vb, *mn, *mx, *lb, *add;
    float* mSlot[3];  // the largest channel and the reflected colour of rows y-1..y+1, kept in
    float* lSlot[3];  // slot row % 3 as the rows go down (each row computed once per task)
    int mRow[3] = {-1, -1, -1}, lRow[3] = {-1, -1, -1};
    RimRows(const RimAlbedo& f_) : f(f_), w(f_.in.width), h(f_.in.height), buf(13 * size_t(f_.in.width)) {
        float* p = buf.data();
        for (float** q : {&vm, &vx, &vb, &mn, &mx, &lb, &add, &mSlot[0], &mSlot[1], &mSlot[2], &lSlot[0], &lSlot[1],
                          &lSlot[2]})
            *q = p, p += w;
    }
    const float* mOf(int y) {
        const int i = y % 3;
        if (mRow[i] != y) maxRow(y, mSlot[i]), mRow[i] = y;
        return mSlot[i];
    }
    const float* lOf(int y) {
        const int i = y % 3;
        if (lRow[i] != y) reflectedRow(y, lSlot[i]), lRow[i] = y;
        return lSlot[i];
    }
    void maxRow(int y, float* ATROUS_RESTRICT o) const {
        const size_t off = size_t(y) * size_t(w);
        const float* ATROUS_RESTRICT r = f.in.channel(0) + off;
        const float* ATROUS_RESTRICT g = f.in.channel(1) + off;
        const float* ATROUS_RESTRICT b = f.in.channel(2) + off;
#pragma omp simd
        for (int x = 0; x < w; ++x) o[x] = maxChannel(r[x], g[x], b[x]);
    }
    // rimReflected of row y, vectorised: the same sums in the same order (c - 0 is c, bit for bit).
    void reflectedRow(int y, float* ATROUS_RESTRICT o) const {
        const size_t off = size_t(y) * size_t(w);
        const float* ATROUS_RESTRICT c0 = f.color.channel(0) + off;
        const float* ATROUS_RESTRICT c1 = f.color.channel(1) + off;
        const float* ATROUS_RESTRICT c2 = f.color.channel(2) + off;
        if (!f.emission.valid()) {
#pragma omp simd
            for (int x = 0; x < w; ++x) o[x] = maxSel((((0.0f + c0[x]) + c1[x]) + c2[x]) * (1.0f / 3.0f), 0.0f);
            return;
        }
        const float* ATROUS_RESTRICT e0 = f.emission.channel(0) + off;
        const float* ATROUS_RESTRICT e1 = f.emission.channel(1) + off;
        const float* ATROUS_RESTRICT e2 = f.emission.channel(2) + off;
#pragma omp simd
        for (int x = 0; x < w; ++x) {
            const float a = finite(e0[x]) ? e0[x] : 0.0f, b = finite(e1[x]) ? e1[x] : 0.0f, c = finite(e2[x]) ? e2[x] : 0.0f;
            o[x] = maxSel((((0.0f + (c0[x] - a)) + (c1[x] - b)) + (c2[x] - c)) * (1.0f / 3.0f), 0.0f);
        }
    }
    // add[] of row y; false (add[] not written) when it is all zero.
    bool row(int y) {
        const float black = f.black;
        const int ya = clampIdx(y - 1, h - 1), yb = clampIdx(y + 1, h - 1);
        {
            const float* ATROUS_RESTRICT a = mOf(ya);
            const float* ATROUS_RESTRICT b = mOf(y);
            const float* ATROUS_RESTRICT c = mOf(yb);
#pragma omp simd
            for (int x = 0; x < w; ++x) {
                vm[x] = minSel(minSel(a[x], b[x]), c[x]);
                vx[x] = maxSel(maxSel(a[x], b[x]), c[x]);
            }
        }
        int found = 0;
#pragma omp simd reduction(| : found)
        for (int x = 0; x < w; ++x) found |= vm[x] < black ? 1 : 0;
        if (!found) return false;
        // The brightest black pixel's reflected colour over rows y-1..y+1, then over x-1..x+1.
        for (int k = 0; k < 3; ++k) {
            const int yy = k == 0 ? ya : (k == 1 ? y : yb);
            const float* ATROUS_RESTRICT m = mOf(yy);
            const float* ATROUS_RESTRICT l = lOf(yy);
#pragma omp simd
            for (int x = 0; x < w; ++x) {
                const float q = m[x] < black ? l[x] : 0.0f;
                vb[x] = k == 0 ? maxSel(0.0f, q) : maxSel(vb[x], q);
            }
        }
        if (w == 1) {
            mn[0] = vm[0], mx[0] = vx[0], lb[0] = vb[0];
        } else {
            mn[0] = minSel(vm[0], vm[1]), mx[0] = maxSel(vx[0], vx[1]), lb[0] = maxSel(vb[0], vb[1]);
#pragma omp simd
            for (int x = 1; x < w - 1; ++x) {
                mn[x] = minSel(minSel(vm[x - 1], vm[x]), vm[x + 1]);
                mx[x] = maxSel(maxSel(vx[x - 1], vx[x]), vx[x + 1]);
                lb[x] = maxSel(maxSel(vb[x - 1], vb[x]), vb[x + 1]);
            }
            mn[w - 1] = minSel(vm[w - 2], vm[w - 1]), mx[w - 1] = maxSel(vx[w - 2], vx[w - 1]);
            lb[w - 1] = maxSel(vb[w - 2], vb[w - 1]);
        }
        const float* ATROUS_RESTRICT m = mOf(y);
        const float* ATROUS_RESTRICT lp = lOf(y);
        int nonzero = 0;
        for (int x = 0; x < w; ++x) {
            add[x] = rimAdd(m[x], mn[x], mx[x], lp[x], lb[x], black);
            nonzero |= add[x] != 0.0f ? 1 : 0;
        }
        return nonzero != 0;
    }
};
}  // namespace

ImageView rimAlbedo(const CpuExec& exec, const RimAlbedo& f, Image& storage) {
    const ImageView in = f.in;
    const int w = in.width, h = in.height;
    std::vector<unsigned char> changed(size_t(h), 0);
    std::atomic<bool> any{false};
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 8, [&](int y0, int y1) {
        RimRows r(f);
        for (int y = y0; y < y1; ++y)
            if (r.row(y)) changed[size_t(y)] = 1, any.store(true, std::memory_order_relaxed);
    });
    if (!any.load()) {
        storage = Image();
        return in;
    }
    storage = Image::uninitialized(w, h, 3, exec.device());
    const ImageView out = storage.view();
    cpu::parallelForIsa(cpu::activeIsa(), 0, h, 8, [&](int y0, int y1) {
        RimRows r(f);
        for (int y = y0; y < y1; ++y) {
            const size_t o = size_t(y) * size_t(w);
            if (!changed[size_t(y)]) {
                for (int c = 0; c < 3; ++c) std::memcpy(out.channel(c) + o, in.channel(c) + o, size_t(w) * sizeof(float));
                continue;
            }
            r.row(y);
            // The added term has its own row (add[]), then the adds: a multiply and an add in one
            // loop would be contracted into a multiply-add in the FMA bodies, one rounding fewer
            // than the functor's.
            for (int c = 0; c < 3; ++c) {
                const float* ATROUS_RESTRICT a = in.channel(c) + o;
                float* ATROUS_RESTRICT d = out.channel(c) + o;
                const float* ATROUS_RESTRICT ad = r.add;
#pragma omp simd
                for (int x = 0; x < w; ++x) d[x] = a[x] + ad[x];
            }
        }
    });
    return out;
}

}  // namespace atrous::filters

// Putting back what the firefly pass removed (docs/algorithms-eaw-sure.md, "The firefly pass";
// issue 47). The pass scales a pixel down to its neighbourhood's bound; at 1-4 spp in a room lit
// through a window most of the light arrives as such rare bright samples (a diffuse bounce that
// finds the sun patch), and dropping them darkened the room by a fifth at 1 spp and a tenth at 4
// (docs/quality.md, "Firefly energy loss"). A clamped sample is not wrong, only too concentrated:
// its excess is an unbiased part of the neighbourhood's light. So the excess E(q) of each clamped
// pixel q is spread evenly over the smallest window around q (radius 1, 2, 4, ..., 32 pixels)
// that holds at least kRestoreCount clamped pixels, the way a photon map's density estimate takes
// its k nearest photons: where clamped samples are dense (the room's walls at 1 spp, a caustic)
// the window is small and the light stays where it fell; a lone firefly, with no such window
// up to the largest radius, is dropped as before (sun glints that no neighbour confirms, spread up
// to radius 64, were a haze on dark ground: docs/quality.md). The spread is a scatter (each
// source's in-image window gets E / taps, so the energy put back equals the energy taken, to
// float rounding), computed in O(1) a pixel as a difference image and two prefix sums: the
// difference image is gathered per pixel (each window adds +-E/taps at its four corners; a pixel
// reads the corners that fall on it, at most 24 taps inside the image) and is then summed along
// rows and along columns.
#pragma once
#include "atrous/image.h"
#include "filters/filter_math.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::filters {

constexpr int kRestoreCount = 32;  // clamped pixels a window must hold (docs/decisions.md, "Fireflies put back")
constexpr int kRestoreLevels = 6;  // windows of radius 1, 2, 4, 8, 16, 32
ATROUS_INLINE int restoreRadius(int level) { return 1 << level; }

// 1. Per pixel: 0 where not clamped or no window holds kRestoreCount clamped pixels; else its excess
// over the pass's output divided by its window's in-image taps (`share`, 3 channels) and the
// window's radius (`radius`, 1 channel, as a float). cIn/cOut: the colour before and after the
// pass; flag: 1 where clamped.
struct RestoreSource {
    ImageView cIn, cOut, flag, share, radius;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        write(x, y, flag(x, y, 0) > 0.5f ? windowRadius(x, y) : 0);
    }
    // Pixel (x, y)'s outputs for window radius r (0: none).
    ATROUS_HOST_DEVICE void write(int x, int y, int r) const {
        radius(x, y, 0) = float(r);
        const float inv = r > 0 ? 1.0f / boxTaps(r, x, y, cIn.width, cIn.height) : 0.0f;
        for (int c = 0; c < 3; ++c) share(x, y, c) = shareOf(cIn(x, y, c), cOut(x, y, c), inv);
    }
    // A channel's share: its excess over the pass's output (never negative) over the window's taps.
    ATROUS_HOST_DEVICE static float shareOf(float in, float out, float invTaps) {
        const float e = in - out;
        return e > 0.0f ? e * invTaps : 0.0f;
    }
    // The smallest radius whose window holds kRestoreCount clamped pixels (0: none does). Counts
    // ring by ring, each window's count the previous one's plus its new ring.
    ATROUS_HOST_DEVICE int windowRadius(int x, int y) const {
        const int w = flag.width, h = flag.height;
        int count = 0, inner = -1;  // the window counted so far: |dx|, |dy| <= inner
        for (int level = 0; level < kRestoreLevels; ++level) {
            const int r = restoreRadius(level);
            const int y0 = y - r < 0 ? 0 : y - r, y1 = y + r > h - 1 ? h - 1 : y + r;
            const int x0 = x - r < 0 ? 0 : x - r, x1 = x + r > w - 1 ? w - 1 : x + r;
            for (int yy = y0; yy <= y1; ++yy) {
                const bool innerRow = yy >= y - inner && yy <= y + inner;
                for (int xx = x0; xx <= x1; ++xx) {
                    if (innerRow && xx >= x - inner && xx <= x + inner) {
                        xx = x + inner;  // skip the counted part of this row
                        continue;
                    }
                    count += flag(xx, yy, 0) > 0.5f;
                }
            }
            if (count >= kRestoreCount) return r;
            inner = r;
        }
        return 0;
    }
};

// The sources q (along one axis) whose window of radius r starts at i (sign +1) or ends at i - 1
// (sign -1) in an axis of n pixels: windows are clipped to [0, n - 1], so every source within r of
// the start begins at 0, and a window that ends at n - 1 has no end mark.
struct RestoreSpan {
    int lo = 0, hi = -1;
};
ATROUS_INLINE RestoreSpan restoreStarts(int i, int r, int n) {
    if (i == 0) return {0, r < n - 1 ? r : n - 1};
    return i + r < n ? RestoreSpan{i + r, i + r} : RestoreSpan{};
}
ATROUS_INLINE RestoreSpan restoreEnds(int i, int r) {
    return i >= 1 && i - 1 - r >= 0 ? RestoreSpan{i - 1 - r, i - 1 - r} : RestoreSpan{};
}

// 2. The difference image: each source's window adds +v at its top-left corner, -v right of its
// right edge and below its bottom edge, +v at the corner beyond both (v = share); summed along rows
// and then columns it is the spread itself. Gathered: pixel (x, y) reads the sources whose corners
// fall on it.
struct RestoreCorners {
    ImageView share, radius, diff;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        const int w = share.width, h = share.height;
        float d[3] = {0.0f, 0.0f, 0.0f};
        for (int level = 0; level < kRestoreLevels; ++level) {
            const int r = restoreRadius(level);
            const RestoreSpan sx = restoreStarts(x, r, w), ex = restoreEnds(x, r);
            const RestoreSpan sy = restoreStarts(y, r, h), ey = restoreEnds(y, r);
            add(d, sx, sy, r, 1.0f);
            add(d, ex, sy, r, -1.0f);
            add(d, sx, ey, r, -1.0f);
            add(d, ex, ey, r, 1.0f);
        }
        for (int c = 0; c < 3; ++c) diff(x, y, c) = d[c];
    }
    ATROUS_HOST_DEVICE void add(float (&d)[3], RestoreSpan xs, RestoreSpan ys, int r, float sign) const {
        for (int qy = ys.lo; qy <= ys.hi; ++qy)
            for (int qx = xs.lo; qx <= xs.hi; ++qx) {
                if (radius(qx, qy, 0) != float(r)) continue;
                for (int c = 0; c < 3; ++c) d[c] += sign * share(qx, qy, c);
            }
    }
};

// 3. Prefix sums of the difference image in place, along each row (x = 0 of a width-1 grid, one
// row per y), then along each column (one column per x of a height-1 grid); in double, so that a
// bright window's +v and -v cancel to the last bit of float.
struct RestoreRowSum {
    ImageView plane;
    ATROUS_HOST_DEVICE void operator()(int, int y) const {
        for (int c = 0; c < plane.channels; ++c) {
            double s = 0.0;
            for (int x = 0; x < plane.width; ++x) s += plane(x, y, c), plane(x, y, c) = float(s);
        }
    }
};
struct RestoreColumnSum {
    ImageView plane;
    ATROUS_HOST_DEVICE void operator()(int x, int) const {
        for (int c = 0; c < plane.channels; ++c) {
            double s = 0.0;
            for (int y = 0; y < plane.height; ++y) s += plane(x, y, c), plane(x, y, c) = float(s);
        }
    }
};

// 4. out += the spread (negative rounding residue of the prefix sums clamped to 0).
struct RestoreAdd {
    ImageView spread, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        for (int c = 0; c < 3; ++c) {
            const float s = spread(x, y, c);
            out(x, y, c) += s > 0.0f ? s : 0.0f;
        }
    }
};

struct FireflyRestore {
    ImageView cIn, cOut, flag;  // the pass's input, its output (added to in place) and its flags
    // 3-channel scratch planes of the image's size; diff may be cIn's planes (cIn is not read
    // once the sources are found).
    ImageView share, diff;
    ImageView radius;           // a 1-channel scratch plane
    ImageView addTo;            // where the spread is added (invalid: cOut)
};

// Adds what the firefly pass removed back into r.cOut (the steps above).
template <class Exec>
void runFireflyRestore(const Exec& exec, const FireflyRestore& r) {
    const int w = r.cIn.width, h = r.cIn.height;
    exec.forEachPixel(w, h, RestoreSource{r.cIn, r.cOut, r.flag, r.share, r.radius});
    exec.forEachPixel(w, h, RestoreCorners{r.share, r.radius, r.diff});
    exec.forEachPixel(1, h, RestoreRowSum{r.diff});
    exec.forEachPixel(w, 1, RestoreColumnSum{r.diff});
    exec.forEachPixel(w, h, RestoreAdd{r.diff, r.addTo.valid() ? r.addTo : r.cOut});
}
// The CPU's (src/cpu/restore_cpu.cpp): the same values from row loops, without the share and
// radius planes (the generic loop's `omp simd` ran every lane's window count and corner spans
// masked: 4x slower at 1080p).
void runFireflyRestore(const CpuExec& exec, const FireflyRestore& r);

}  // namespace atrous::filters

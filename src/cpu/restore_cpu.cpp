// The CPU path of the firefly restore (src/filters/firefly_restore.h), the same values as the
// functors (tests/firefly_restore_test.cpp holds them bit for bit): the window counts from a
// summed-area table of the flags (integers: exact) at the clamped pixels only; the difference image
// built a row at a time from lists of each row's sources (the functor gathers 24 taps at every
// pixel), its row sums taken while the row is in cache; the column sums in bands of columns added a
// row at a time into double accumulators (the functor walks one column at a time, serial and
// strided here), added to the output in the same pass. Nothing to do without a source. The generic
// per-pixel loop vectorised the window counts and corner spans as masked lanes: 4x slower at 1080p.
#include <algorithm>
#include <memory>
#include <vector>

#include "core/parallel.h"
#include "filters/firefly_restore.h"

namespace atrous::filters {

namespace {

constexpr int kBand = 256;  // columns per task of the column sums

// The column sums of `plane` channel by channel in bands of columns: each (channel, band) task
// adds the rows in order into double accumulators and hands each pixel's sum to emit(c, x, y, sum).
template <class Emit>
void columnSums(const ImageView& plane, const Emit& emit) {
    const int w = plane.width, h = plane.height, bands = (w + kBand - 1) / kBand;
    parallelForRowsCpu(
        bands * plane.channels,
        [&](int job) {
            const int c = job / bands, x0 = (job % bands) * kBand, x1 = std::min(x0 + kBand, w);
            double acc[kBand] = {};
            for (int y = 0; y < h; ++y) {
                const float* row = plane.channel(c) + size_t(y) * size_t(w);
                for (int x = x0; x < x1; ++x) acc[x - x0] += row[x], emit(c, x, y, float(acc[x - x0]));
            }
        },
        1);
}

// The summed-area table of the flags, (w + 1) x (h + 1) with a zero first row and column.
struct FlagTable {
    int w, h;
    std::unique_ptr<int[]> t;
    FlagTable(const ImageView& flag) : w(flag.width), h(flag.height), t(new int[size_t(w + 1) * size_t(h + 1)]) {
        std::fill(t.get(), t.get() + w + 1, 0);
        parallelForRowsCpu(h, [&](int y) {
            const float* f = flag.channel(0) + size_t(y) * size_t(w);
            int* row = t.get() + size_t(y + 1) * size_t(w + 1);
            int s = 0;
            row[0] = 0;
            for (int x = 0; x < w; ++x) s += f[x] > 0.5f, row[x + 1] = s;
        });
        // Then down the columns, in bands of columns.
        const int bands = (w + 1 + kBand - 1) / kBand;
        parallelForRowsCpu(
            bands,
            [&](int b) {
                const int x0 = b * kBand, x1 = std::min(x0 + kBand, w + 1);
                for (int y = 2; y <= h; ++y) {
                    const int* above = t.get() + size_t(y - 1) * size_t(w + 1);
                    int* row = t.get() + size_t(y) * size_t(w + 1);
                    for (int x = x0; x < x1; ++x) row[x] += above[x];
                }
            },
            1);
    }
    // Clamped pixels in the in-image part of (x, y)'s window of radius r.
    int count(int x, int y, int r) const {
        const int x0 = std::max(x - r, 0), x1 = std::min(x + r, w - 1) + 1;
        const int y0 = std::max(y - r, 0), y1 = std::min(y + r, h - 1) + 1;
        const int* a = t.get() + size_t(y0) * size_t(w + 1);
        const int* b = t.get() + size_t(y1) * size_t(w + 1);
        return b[x1] - b[x0] - a[x1] + a[x0];
    }
};

}  // namespace

void runFireflyRestore(const CpuExec&, const FireflyRestore& r) {
    const int w = r.cIn.width, h = r.cIn.height;
    // 1. The sources, listed per row with their radius and share (RestoreSource's values; the
    //    share and radius planes are the GPU's way of listing them and are not written here).
    struct Source {
        int x, radius;
        float share[3];
    };
    const FlagTable table(r.flag);
    std::vector<std::vector<Source>> rowSources(static_cast<size_t>(h));
    parallelForRowsCpu(h, [&](int y) {
        const float* flag = r.flag.channel(0) + size_t(y) * size_t(w);
        for (int x = 0; x < w; ++x) {
            if (!(flag[x] > 0.5f)) continue;
            int rad = 0;
            for (int level = 0; level < kRestoreLevels && rad == 0; ++level)
                if (table.count(x, y, restoreRadius(level)) >= kRestoreCount) rad = restoreRadius(level);
            if (rad == 0) continue;
            Source s{x, rad, {}};
            const float inv = 1.0f / boxTaps(rad, x, y, w, h);
            for (int c = 0; c < 3; ++c) s.share[c] = RestoreSource::shareOf(r.cIn(x, y, c), r.cOut(x, y, c), inv);
            rowSources[size_t(y)].push_back(s);
        }
    });
    if (std::all_of(rowSources.begin(), rowSources.end(), [](const std::vector<Source>& v) { return v.empty(); })) return;

    // 2. Row y of the difference image: the marks of the source rows whose windows start at y or
    //    end at y - 1 (restoreStarts / restoreEnds), scattered along the row in the functor's order
    //    (per radius: starts of starting rows, ends of starting rows, starts of ending rows, ends of
    //    ending rows; sources in row order), then summed along the row in double (RestoreRowSum).
    const RestoreRowSum rowSum{r.diff};
    parallelForRowsCpu(h, [&](int y) {
        float* d[3];
        for (int c = 0; c < 3; ++c) d[c] = r.diff.channel(c) + size_t(y) * size_t(w), std::fill(d[c], d[c] + w, 0.0f);
        auto marks = [&](RestoreSpan rows, int rad, bool starts, float sign) {
            for (int qy = rows.lo; qy <= rows.hi; ++qy)
                for (const Source& s : rowSources[size_t(qy)]) {
                    if (s.radius != rad) continue;
                    const int x = starts ? std::max(s.x - rad, 0) : s.x + rad + 1;
                    if (x >= w) continue;
                    for (int c = 0; c < 3; ++c) d[c][x] += (starts ? sign : -sign) * s.share[c];
                }
        };
        for (int level = 0; level < kRestoreLevels; ++level) {
            const int rad = restoreRadius(level);
            const RestoreSpan sy = restoreStarts(y, rad, h), ey = restoreEnds(y, rad);
            marks(sy, rad, true, 1.0f);
            marks(sy, rad, false, 1.0f);
            marks(ey, rad, true, -1.0f);
            marks(ey, rad, false, -1.0f);
        }
        rowSum(0, y);
    });

    // 3. The column sums, added to the output as they come (RestoreColumnSum, then RestoreAdd).
    const ImageView out = r.addTo.valid() ? r.addTo : r.cOut;
    columnSums(r.diff, [&](int c, int x, int y, float s) { out(x, y, c) += s > 0.0f ? s : 0.0f; });
}

}  // namespace atrous::filters

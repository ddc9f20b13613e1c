// Putting back what the firefly pass removed (src/filters/firefly_restore.h, issue 47): the spread
// equals a brute-force scatter, keeps the energy, drops a lone firefly, and a room lit through a
// window keeps its light at 1 and 4 spp (it lost a fifth and a tenth without it).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/render.h"
#include "atrous/temporal.h"
#include "core/parallel.h"
#include "denoise_test_util.h"
#include "filters/firefly_restore.h"
#include "render_test_util.h"

using namespace atrous;
using namespace atrous::filters;

namespace {

// The generic (functor) path, run serially: what the GPU runs, for the CPU overload to equal.
struct SerialExec {
    Device device() const { return Device::Cpu; }
    template <class F>
    void forEachPixel(int w, int h, const F& f) const {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) f(x, y);
    }
};

// A pass's input and output: `after` is `before` scaled down where flagged.
struct Clamped {
    Image before, after, flag;
    Clamped(int w, int h, double density, unsigned seed) : before(w, h, 3), after(w, h, 3), flag(w, h, 1) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool clamped = u(rng) < density;
                flag(x, y, 0) = clamped ? 1.0f : 0.0f;
                for (int c = 0; c < 3; ++c) {
                    before(x, y, c) = clamped ? 5.0f + 50.0f * u(rng) : 0.5f * u(rng);
                    after(x, y, c) = clamped ? 0.8f : before(x, y, c);
                }
            }
    }
    // The added light per pixel (after the restore minus before it).
    template <class Exec>
    Image restored(const Exec& exec) const {
        const int w = before.width(), h = before.height();
        Image out = after.clone(), share(w, h, 3), diff(w, h, 3), radius(w, h, 1);
        runFireflyRestore(exec, FireflyRestore{before.view(), out.view(), flag.view(), share.view(), diff.view(),
                                               radius.view(), {}});
        for (size_t i = 0; i < out.size(); ++i) out.data()[i] -= after.data()[i];
        return out;
    }
    // The same by brute force: each clamped pixel's smallest window (radius 1, 2, 4, ..., 32) with
    // 32 clamped pixels gets its excess over the window's in-image pixels, in double.
    std::vector<double> scattered(double* total) const {
        const int w = before.width(), h = before.height();
        std::vector<double> s(size_t(w) * h * 3, 0.0);
        *total = 0.0;
        for (int qy = 0; qy < h; ++qy)
            for (int qx = 0; qx < w; ++qx) {
                if (flag(qx, qy, 0) < 0.5f) continue;
                for (int r = 1; r <= 32; r *= 2) {
                    const int x0 = std::max(qx - r, 0), x1 = std::min(qx + r, w - 1);
                    const int y0 = std::max(qy - r, 0), y1 = std::min(qy + r, h - 1);
                    int n = 0;
                    for (int y = y0; y <= y1; ++y)
                        for (int x = x0; x <= x1; ++x) n += flag(x, y, 0) > 0.5f;
                    if (n < 32) continue;
                    const double taps = double(x1 - x0 + 1) * (y1 - y0 + 1);
                    for (int c = 0; c < 3; ++c) {
                        const double e = double(before(qx, qy, c)) - after(qx, qy, c);
                        *total += e;
                        for (int y = y0; y <= y1; ++y)
                            for (int x = x0; x <= x1; ++x) s[(size_t(c) * h + y) * w + x] += e / taps;
                    }
                    break;
                }
            }
        return s;
    }
};

double sum(const Image& img) {
    double s = 0.0;
    for (size_t i = 0; i < img.size(); ++i) s += img.data()[i];
    return s;
}

}  // namespace

// The gathered corners and prefix sums equal a plain scatter, at every density (windows of every
// radius, and windows clipped at all four borders: 97 x 61 pixels).
TEST(FireflyRestore, EqualsBruteForceScatter) {
    for (double density : {0.004, 0.02, 0.08, 0.3}) {
        Clamped c(97, 61, density, unsigned(density * 1000));
        double total = 0.0;
        const std::vector<double> want = c.scattered(&total);
        const Image got = c.restored(CpuExec{});
        double maxErr = 0.0, maxVal = 0.0;
        for (size_t i = 0; i < want.size(); ++i) {
            maxErr = std::max(maxErr, std::fabs(got.data()[i] - want[i]));
            maxVal = std::max(maxVal, std::fabs(want[i]));
        }
        // float rounding of the prefix sums' inputs (each ~1e-7 of the values summed)
        EXPECT_LE(maxErr, 1e-5 * std::max(maxVal, 1.0)) << "density " << density;
        // The energy put back is the energy of the sources that found a window.
        EXPECT_NEAR(sum(got), total, 1e-5 * std::max(total, 1.0)) << "density " << density;
        if (density >= 0.02) EXPECT_GT(total, 0.0);
    }
}

// The CPU path (window counts from a table, rows of marks, bands of columns) gives the functors' values bit for bit.
TEST(FireflyRestore, CpuPathEqualsFunctors) {
    Clamped c(300, 70, 0.05, 7);
    const Image cpu = c.restored(CpuExec{});
    const Image generic = c.restored(SerialExec{});
    ASSERT_EQ(cpu.size(), generic.size());
    for (size_t i = 0; i < cpu.size(); ++i) ASSERT_EQ(cpu.data()[i], generic.data()[i]) << i;
}

// A lone firefly has no window of 32 clamped pixels: its excess is dropped, nothing is added.
TEST(FireflyRestore, LoneFireflyIsDropped) {
    Clamped c(64, 64, 0.0, 1);
    c.flag(30, 30, 0) = 1.0f;
    for (int ch = 0; ch < 3; ++ch) c.before(30, 30, ch) = 500.0f, c.after(30, 30, ch) = 0.8f;
    const Image got = c.restored(CpuExec{});
    EXPECT_EQ(sum(got), 0.0);
}

// Through denoise(): a flat wall with one firefly comes out flat (the firefly is removed, not
// spread); a wall whose light arrives as rare bright samples (2% of pixels at 25x, the rest dark)
// keeps its mean, which the pass alone takes most of.
TEST(FireflyRestore, DenoiseKeepsRareLightAndRemovesALoneFirefly) {
    const int w = 64, h = 64;
    Image color(w, h, 3), var(w, h, 3);
    std::mt19937 rng(3);
    std::normal_distribution<float> g(0.0f, 0.02f);
    for (size_t i = 0; i < color.size(); ++i) color.data()[i] = 0.5f + g(rng);
    var.fill(0.02f * 0.02f);
    for (int c = 0; c < 3; ++c) color(20, 40, c) = 300.0f, var(20, 40, c) = 300.0f * 300.0f;
    DenoiseOptions o;
    const Image out = denoise(test::inputsOf(color, var), o);
    EXPECT_NEAR(out(20, 40, 1), 0.5f, 0.05f);
    EXPECT_NEAR(sum(out) / double(out.size()), 0.5, 0.01);  // 300 spread over the wall would add 0.07

    // Rare light: the mean of n samples of which one in 50 is 25, the rest 0.01 (1 spp).
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    double truth = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float v = u(rng) < 0.02f ? 25.0f : 0.01f;
            for (int c = 0; c < 3; ++c) color(x, y, c) = v, var(x, y, c) = v * v;
        }
    truth = 0.02 * 25.0 + 0.98 * 0.01;
    const double kept = sum(denoise(test::inputsOf(color, var), o)) / double(color.size()) / truth;
    o.firefly.restore = false;
    const double keptWithout = sum(denoise(test::inputsOf(color, var), o)) / double(color.size()) / truth;
    EXPECT_GT(kept, 0.9);          // the sample draw's own spread: ~2.5% (82 bright pixels)
    EXPECT_LT(keptWithout, 0.5);   // what the pass alone leaves: the bright samples clamped
}

// A room lit through a window (scenes/window-room.json: sun and sky through an opening in one
// wall, the camera facing away from the sun patch, so most light arrives after a bounce off it),
// 64x64: a 1024-spp reference and five renders per sample count (seeds 3..7), made once.
struct Room {
    Scene scene = Scene::load(std::string(ATROUS_SOURCE_DIR) + "/scenes/window-room.json");
    double refMean = 0.0;
    std::map<int, std::vector<RenderBuffers>> renders;
    Room() {
        const RenderBuffers ref = render(scene, test::smallRender(64, 64, 1024, 999));
        refMean = sum(ref.color) / double(ref.color.size());
        for (int spp : {1, 4})
            for (unsigned s = 0; s < 5; ++s) renders[spp].push_back(render(scene, test::smallRender(64, 64, spp, 3 + s)));
    }
    static const Room& get() {
        static const Room room;
        return room;
    }
};

// The still default's mean within 10% of the reference's at 1 spp and within 3% at 4 spp (issue
// 47), averaged over three renders (one 64^2 render's own mean varies by ~2% at 1 spp). Without
// the restore it keeps 78% and 90% (128^2; docs/quality.md): checked too, so the test can fail.
TEST(FireflyRestore, WindowLitRoomKeepsItsLight) {
    const Room& room = Room::get();
    for (auto [spp, tolerance] : {std::pair{1, 0.10}, std::pair{4, 0.03}}) {
        for (bool restore : {true, false}) {
            double ratio = 0.0;
            for (int s = 0; s < 3; ++s) {
                const RenderBuffers& b = room.renders.at(spp)[size_t(s)];
                DenoiseOptions o;
                o.firefly.restore = restore;
                ratio += sum(denoise(b.frame(), o)) / double(b.color.size()) / room.refMean / 3;
            }
            if (restore)
                EXPECT_NEAR(ratio, 1.0, tolerance) << spp << " spp";
            else
                EXPECT_LT(ratio, 1.0 - tolerance) << spp << " spp, without the restore: the test would not fail";
        }
    }
}

// The sequence default (the temporal window, then the still default) on five frames of the same
// room with a still camera: the same bounds for the centre frame.
TEST(FireflyRestore, WindowLitRoomSequenceKeepsItsLight) {
    const Room& room = Room::get();
    for (auto [spp, tolerance] : {std::pair{1, 0.10}, std::pair{4, 0.03}}) {
        std::vector<Frame> frames;
        for (const RenderBuffers& b : room.renders.at(spp)) frames.push_back(b.frame());
        const Image out = denoiseTemporal(frames, 2, TemporalParams{}, DenoiseOptions{});
        EXPECT_NEAR(sum(out) / double(out.size()) / room.refMean, 1.0, tolerance) << spp << " spp";
    }
}

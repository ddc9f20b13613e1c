// The offline sequence denoiser (include/atrous/temporal.h): the gather's reprojection both ways,
// its noise reduction, its rejections, its handling of bad values and bad windows; and the CLI's
// `denoise --sequence` default.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "atrous/sequence_methods.h"
#include "atrous/error.h"
#include "atrous/metrics.h"
#include "atrous/params.h"
#include "atrous/temporal.h"
#include "atrous/io/image_io.h"
#include "svgf_test_util.h"
#include "test_util.h"

using namespace atrous;
using svgf_test::makeFrame;
using svgf_test::SceneOptions;
using svgf_test::SynthFrame;
using test::runCli;
using test::sameImages;
using test::renderSequence;
using test::TempDir;
namespace fs = std::filesystem;

namespace {

std::vector<SynthFrame> makeFrames(const SceneOptions& o, int n) {
    std::vector<SynthFrame> f;
    for (int t = 0; t < n; ++t) f.push_back(makeFrame(o, t));
    return f;
}

std::vector<Frame> framesOf(const std::vector<SynthFrame>& s) {
    std::vector<Frame> f;
    for (const SynthFrame& x : s) f.push_back(x.frame());
    return f;
}

// Variance of (img - truth) over all values.
double errorVariance(const Image& img, const Image& truth) {
    double s = 0, s2 = 0;
    for (size_t i = 0; i < img.size(); ++i) {
        const double d = double(img.data()[i]) - double(truth.data()[i]);
        s += d, s2 += d * d;
    }
    const double n = double(img.size());
    return s2 / n - (s / n) * (s / n);
}

double meanOf(const Image& img, int channel) {
    double s = 0;
    for (size_t i = 0; i < img.plane(); ++i) s += img.data()[size_t(channel) * img.plane() + i];
    return s / double(img.plane());
}

}  // namespace

// A textured box slides 4 pixels a frame across a static textured ground; noise-free frames with
// exact motion. Every pixel inside the box is tracked through the three frames before the centre
// (the motion) and the three after it (the inverse of their motion) onto the same texel: 7 frames
// averaged, and the average is the centre's colour. Without the motion vectors the same pixels
// land on the ground or on another texel and are left out: the test sees the reprojection.
TEST(TemporalGather, TracksAMovingBoxThroughFramesOnBothSides) {
    SceneOptions o;
    o.boxApproach = 0.0f, o.boxTurn = 0.0f;  // the box only slides: its texels keep their colour
    const auto synth = makeFrames(o, 7);
    TemporalParams p;
    p.falloff = 0.0f;  // equal weights: channel 0 of `frames` counts frames
    const int bx = svgf_test::boxX0(o, 3), by = svgf_test::boxY0(o), bs = svgf_test::boxSize(o);
    auto boxFullCount = [&](const TemporalGather& g, bool checkColour) {
        int full = 0, n = 0;
        for (int y = by + 1; y < by + bs - 1; ++y)
            for (int x = bx + 1; x < bx + bs - 1; ++x, ++n) {
                if (g.frames(x, y, 0) != 7.0f) continue;
                ++full;
                if (checkColour)
                    for (int c = 0; c < 3; ++c) EXPECT_NEAR(g.color(x, y, c), synth[3].truth(x, y, c), 1e-5f) << x << "," << y;
            }
        return double(full) / double(n);
    };
    TemporalGather g = gatherTemporal(framesOf(synth), 3, p);
    EXPECT_EQ(boxFullCount(g, true), 1.0);

    std::vector<Frame> still = framesOf(synth);
    for (Frame& f : still) f.motion = nullptr;
    EXPECT_LT(boxFullCount(gatherTemporal(still, 3, p), false), 0.2);
}

// A static flat scene with Gaussian noise: the average of 2r + 1 frames has 1/(2r + 1) of the
// noise's variance (equal weights), or Σw²/(Σw)² of it with the falloff, and `frames` reports that
// effective count. 3072 independent noise values (R, G, B share theirs): the variance is measured
// to about 3% (one standard error); 10% is allowed.
TEST(TemporalGather, AveragingCutsTheNoiseByTheEffectiveFrameCount) {
    SceneOptions o;
    o.flat = true, o.withBox = false, o.noiseSigma = 0.1f;
    const auto synth = makeFrames(o, 7);
    const double v1 = errorVariance(synth[3].color, synth[3].truth);
    for (float falloff : {0.0f, 2.0f}) {
        TemporalParams p;
        p.falloff = falloff;
        p.staticRadius = 0;  // the scene is static: its pixels would all take the static window
        double sw = 0, sw2 = 0;
        for (int k = -3; k <= 3; ++k) {
            const double w = falloff > 0 ? std::exp(-double(k * k) / (2.0 * falloff * falloff)) : 1.0;
            sw += w, sw2 += w * w;
        }
        const double nEff = sw * sw / sw2;
        TemporalGather g = gatherTemporal(framesOf(synth), 3, p);
        EXPECT_NEAR(meanOf(g.frames, 0), nEff, 0.05 * nEff) << "falloff " << falloff;  // a few 3-sigma rejections
        EXPECT_NEAR(errorVariance(g.color, synth[3].truth), v1 / nEff, 0.1 * v1 / nEff) << "falloff " << falloff;
    }
}

// A textured box slides 1 pixel a frame over a static textured ground, noisy, 13 frames, the defaults (radius 3,
// falloff 1.5, static_radius 6): the ground's pixels, which never move, average all 13 frames with
// equal weights (1/13 of the noise's variance), the box's keep the falloff's 3.7 effective frames
// of t-3..t+3. Under a moving camera, and with static_radius 0, the ground keeps the falloff too;
// a frame whose camera moved ends the static part of a track. Tolerances: 5% on the frame counts
// (a few 3-sigma colour rejections), 15% on a variance measured over ~1000 values (one standard
// error ~4.5%).
TEST(TemporalGather, PixelsThatNeverMoveTakeTheStaticWindow) {
    SceneOptions o;
    o.noiseSigma = 0.1f, o.width = 96, o.height = 64;  // a textured ground, a textured box
    o.boxSpeed = 1.0f, o.boxApproach = 0.0f, o.boxTurn = 0.0f;
    const auto synth = makeFrames(o, 13);
    TemporalParams p;
    ASSERT_EQ(p.radius, 3);
    ASSERT_EQ(p.staticRadius, 6);
    EXPECT_EQ(temporalWindowRadius(p), 6);
    double sw = 0, sw2 = 0;
    for (int k = -3; k <= 3; ++k) {
        const double w = std::exp(-double(k * k) / (2.0 * p.falloff * p.falloff));
        sw += w, sw2 += w * w;
    }
    const double nEff = sw * sw / sw2;
    const int bx = svgf_test::boxX0(o, 6), by = svgf_test::boxY0(o), bs = svgf_test::boxSize(o);
    // The ground below the box, and the box's interior.
    auto regionMean = [&](const Image& img, bool box) {
        double s = 0;
        int n = 0;
        for (int y = box ? by + 2 : by + bs + 4; y < (box ? by + bs - 2 : o.height); ++y)
            for (int x = box ? bx + 2 : 0; x < (box ? bx + bs - 2 : o.width); ++x, ++n) s += img(x, y, 0);
        return s / n;
    };
    auto planeErrorVariance = [&](const Image& img) {
        double s = 0, s2 = 0;
        int n = 0;
        for (int y = by + bs + 4; y < o.height; ++y)
            for (int x = 0; x < o.width; ++x, ++n) {
                const double d = double(img(x, y, 0)) - double(synth[6].truth(x, y, 0));
                s += d, s2 += d * d;
            }
        return s2 / n - (s / n) * (s / n);
    };
    ASSERT_GT(o.height - (by + bs + 4), 4);
    const double v1 = planeErrorVariance(synth[6].color);
    const TemporalGather g = gatherTemporal(framesOf(synth), 6, p);
    EXPECT_NEAR(regionMean(g.frames, false), 13.0, 0.05 * 13.0);
    EXPECT_NEAR(planeErrorVariance(g.color), v1 / 13.0, 0.15 * v1 / 13.0);
    EXPECT_LE(regionMean(g.frames, true), nEff * 1.02);
    EXPECT_GT(regionMean(g.frames, true), nEff * 0.8);

    // A moving camera: the pixels above the measured rows move (half a pixel a frame, any motion
    // does), the measured rows keep motion 0, as an orbit's pivot does: they see the camera move
    // all the same (highlights slide) and keep the falloff.
    auto panned = makeFrames(o, 13);
    for (SynthFrame& f : panned)
        for (int y = 0; y < by + bs + 4; ++y)
            for (int x = 0; x < o.width; ++x) f.motion(x, y, 0) += 0.5f;
    EXPECT_NEAR(regionMean(gatherTemporal(framesOf(panned), 6, p).frames, false), nEff, 0.05 * nEff);
    // The camera moves in frame 8 only: the ground's tracks are static up to frame 7 (weight 1),
    // then take the falloff (t+2, t+3) and stop at t+3; backward they reach t-6.
    auto once = makeFrames(o, 13);
    for (int y = 0; y < by + bs + 4; ++y)
        for (int x = 0; x < o.width; ++x) once[8].motion(x, y, 0) += 0.5f;
    const double g2 = std::exp(-4.0 / (2.0 * p.falloff * p.falloff)), g3 = std::exp(-9.0 / (2.0 * p.falloff * p.falloff));
    const double sOnce = 8.0 + g2 + g3, s2Once = 8.0 + g2 * g2 + g3 * g3;
    EXPECT_NEAR(regionMean(gatherTemporal(framesOf(once), 6, p).frames, false), sOnce * sOnce / s2Once,
                0.05 * sOnce * sOnce / s2Once);
    // The ground just behind the box's trailing edge was under the box in the frames before: its
    // static track must not take the box's taps through the box pixel next to it (a moving
    // neighbour is not a surface of this pixel's footprint). Backward it stops at once; forward
    // it reaches t+6: at most 7 frames.
    const TemporalGather gb = gatherTemporal(framesOf(synth), 6, p);
    for (int y = by + 2; y < by + bs - 2; ++y) EXPECT_LE(gb.frames(bx - 1, y, 0), 7.0f + 1e-4f) << y;
    // A centre frame whose motion is zeros only (a renderer's first frame: no previous one) shows
    // nothing of what moves: no static window through it.
    auto zeros = makeFrames(o, 13);
    zeros[6].motion.fill(0.0f);
    EXPECT_NEAR(regionMean(gatherTemporal(framesOf(zeros), 6, p).frames, false), nEff, 0.05 * nEff);
    // Frames without motion are taken as still: nothing then tells the box from the ground, and
    // the static window is off.
    std::vector<Frame> noMotion = framesOf(synth);
    for (Frame& f : noMotion) f.motion = nullptr;
    EXPECT_NEAR(regionMean(gatherTemporal(noMotion, 6, p).frames, false), nEff, 0.05 * nEff);

    p.staticRadius = 0;
    EXPECT_EQ(temporalWindowRadius(p), 3);
    EXPECT_NEAR(regionMean(gatherTemporal(framesOf(synth), 6, p).frames, false), nEff, 0.05 * nEff);
    p.staticRadius = 6, p.causal = true;  // causal mode keeps its radius
    EXPECT_EQ(temporalWindowRadius(p), 3);
    p.causal = false, p.radius = 0;  // radius 0: the frame alone
    EXPECT_EQ(temporalWindowRadius(p), 0);
}

// A still camera sees the edge of a light in a ceiling: column 8 of a 16x8 image is covered half
// by each, and its one sample a frame (1 spp: the colour, depth and id are that sample's) lands
// on the light (5) in some frames and on the ceiling (0) in the others. The frames' samples are
// samples of the same footprint: with the static window they are all averaged, whichever surface
// each one hit (the id test accepts the surfaces next to the pixel), and the edge pixel's mean is
// the fraction of frames that hit the light. Without it (static_radius 0) only the frames that hit
// what the centre frame's sample hit are kept: the centre's 0 or 5 with t-3..t+3 of the same.
TEST(TemporalGather, AStillEdgePixelAveragesWhateverItsSamplesHit) {
    const int w = 16, h = 8, n = 13;
    const int hits[n] = {1, 0, 0, 1, 1, 0, 1, 0, 1, 1, 0, 0, 1};  // frame 6 hit the light; 7 of 13
    std::vector<Image> color, albedo, normal, depth, ids, motion;
    for (int t = 0; t < n; ++t) {
        color.emplace_back(w, h, 3), albedo.emplace_back(w, h, 3), normal.emplace_back(w, h, 3);
        depth.emplace_back(w, h, 1), ids.emplace_back(w, h, 1), motion.emplace_back(w, h, 2);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool light = x > 8 || (x == 8 && hits[t]);
                for (int c = 0; c < 3; ++c) {
                    color.back()(x, y, c) = light ? 5.0f : 0.0f;
                    albedo.back()(x, y, c) = 1.0f;
                    normal.back()(x, y, c) = c == 1 ? -1.0f : 0.0f;  // both face down
                }
                depth.back()(x, y, 0) = light ? 3.999f : 4.0f;
                ids.back()(x, y, 0) = light ? 1.0f : 0.0f;
            }
        // Something moves in a far corner: a motion buffer of zeros only is what renderers write
        // for a first frame (no sign of what moves), and turns the static window off.
        motion.back()(15, 7, 0) = 1.0f;
    }
    std::vector<Frame> frames(n);
    for (int t = 0; t < n; ++t) {
        frames[t].color = &color[t], frames[t].albedo = &albedo[t], frames[t].normal = &normal[t];
        frames[t].depth = &depth[t], frames[t].ids = &ids[t], frames[t].motion = &motion[t];
    }
    TemporalParams p;
    p.falloff = 0.0f, p.colorSigmas = 0.0f, p.fireflyK = 0.0f;  // plain means: the tests alone decide
    const TemporalGather g = gatherTemporal(frames, 6, p);
    for (int y = 0; y < h; ++y) {
        EXPECT_NEAR(g.color(8, y, 0), 5.0f * 7.0f / 13.0f, 1e-4f) << y;
        EXPECT_EQ(g.frames(8, y, 0), 13.0f) << y;
        EXPECT_NEAR(g.color(3, y, 0), 0.0f, 1e-6f) << y;   // the ceiling and the light away from the
        EXPECT_NEAR(g.color(12, y, 0), 5.0f, 1e-6f) << y;  // edge keep their own value
    }
    p.staticRadius = 0;
    const TemporalGather g0 = gatherTemporal(frames, 6, p);
    for (int y = 0; y < h; ++y) EXPECT_NEAR(g0.color(8, y, 0), 5.0f, 1e-6f) << y;  // frame 6's light only
}

// The neighbours are 20 noise sigmas brighter (a light switched on): the colour test leaves them
// out and the centre stands alone. With the test off they are averaged in.
TEST(TemporalGather, LeavesOutNeighboursWhoseColourChanged) {
    SceneOptions o;
    o.flat = true, o.withBox = false, o.noiseSigma = 0.05f;
    auto synth = makeFrames(o, 5);
    for (int t : {0, 1, 3, 4})
        for (size_t i = 0; i < synth[size_t(t)].color.size(); ++i) synth[size_t(t)].color.data()[i] += 1.0f;
    TemporalParams p;
    TemporalGather g = gatherTemporal(framesOf(synth), 2, p);
    EXPECT_LT(meanOf(g.frames, 0), 1.01);
    EXPECT_LT(std::fabs(meanOf(g.color, 0) - 1.0), 0.01);
    p.colorSigmas = 0.0f;
    EXPECT_GT(meanOf(gatherTemporal(framesOf(synth), 2, p).frames, 0), 3.0);
}

// NaN and Inf in a neighbour are left out (and the track stops there); the average stays finite.
TEST(TemporalGather, NonFiniteNeighbourValuesDoNotSpread) {
    SceneOptions o;
    o.flat = true, o.withBox = false, o.noiseSigma = 0.05f;
    auto synth = makeFrames(o, 5);
    for (int x = 10; x < 20; ++x) {
        synth[1].color(x, 10, 0) = NAN;
        synth[3].color(x, 20, 1) = INFINITY;
        synth[3].albedo(x, 30, 2) = NAN;
    }
    TemporalParams p;
    p.falloff = 0.0f;
    TemporalGather g = gatherTemporal(framesOf(synth), 2, p);
    EXPECT_TRUE(svgf_test::allFinite(g.color));
    EXPECT_TRUE(svgf_test::allFinite(g.albedo));
    EXPECT_EQ(g.frames(15, 10, 0), 3.0f);  // frames 1 and 0 behind the NaN are not reached
    EXPECT_EQ(g.frames(15, 20, 0), 3.0f);
    EXPECT_EQ(g.frames(15, 30, 0), 3.0f);
    Image out = denoiseTemporal(framesOf(synth), 2, p, DenoiseOptions{});
    EXPECT_TRUE(svgf_test::allFinite(out));
}

// Radius 0 is the still method on the frame alone, bit for bit.
TEST(TemporalDenoise, RadiusZeroIsTheStillMethod) {
    SceneOptions o;
    o.noiseSigma = 0.05f;
    const auto synth = makeFrames(o, 3);
    TemporalParams p;
    p.radius = 0;
    for (DenoiseMethod m : {DenoiseMethod::Eaw, DenoiseMethod::Auto}) {
        DenoiseOptions opt;
        opt.method = m;
        Image a = denoiseTemporal(framesOf(synth), 1, p, opt);
        Image c = synth[1].color.clone();
        DenoiseBuffers b;
        b.color = &c;
        b.albedo = &synth[1].albedo, b.normal = &synth[1].normal, b.depth = &synth[1].depth, b.ids = &synth[1].ids;
        b.emission = nullptr;
        EXPECT_TRUE(sameImages(a, denoise(b, opt))) << denoiseMethodName(m);
    }
}

// On a noisy sequence the temporal denoiser is closer to the truth than the same still method per frame.
TEST(TemporalDenoise, BeatsTheStillMethodPerFrame) {
    SceneOptions o;
    o.noiseSigma = 0.3f;
    const auto synth = makeFrames(o, 7);
    DenoiseOptions opt;
    opt.method = DenoiseMethod::Eaw;
    Image t = denoiseTemporal(framesOf(synth), 3, TemporalParams{}, opt);
    TemporalParams alone;
    alone.radius = 0;
    Image s = denoiseTemporal(framesOf(synth), 3, alone, opt);
    EXPECT_LT(svgf_test::mse(t, synth[3].truth), 0.7 * svgf_test::mse(s, synth[3].truth));
}

// A cache (each frame prepared once for the windows it is in) gives what preparing every frame for
// every window gives, bit for bit, as the window slides over a sequence, and starts over when the
// parameters that shape the preparation change.
TEST(TemporalGather, CacheOverASlidingWindowChangesNothing) {
    SceneOptions o;
    o.noiseSigma = 0.2f;
    const auto synth = makeFrames(o, 9);
    TemporalCache cache;  // one cache for both settings: the second must not see the first's frames
    for (float fireflyK : {16.0f, 2.0f}) {
        TemporalParams p;
        p.fireflyK = fireflyK;
        // The second setting walks back from the end, where the first left its frames in the cache.
        for (size_t step = 0; step < synth.size(); ++step) {
            const size_t t = fireflyK == 16.0f ? step : synth.size() - 1 - step;
            const size_t lo = t >= 3 ? t - 3 : 0, hi = std::min(synth.size() - 1, t + 3);
            std::vector<Frame> window;
            std::vector<long long> ids;
            for (size_t i = lo; i <= hi; ++i) window.push_back(synth[i].frame()), ids.push_back((long long)i);
            const TemporalGather a = gatherTemporal(window, t - lo, p, &cache, &ids);
            const TemporalGather b = gatherTemporal(window, t - lo, p);
            EXPECT_TRUE(sameImages(a.color, b.color)) << t;
            EXPECT_TRUE(sameImages(a.frames, b.frames)) << t;
        }
    }
    std::vector<Frame> window = framesOf(synth);
    EXPECT_THROW(gatherTemporal(window, 1, TemporalParams{}, &cache, nullptr), InputError);
    std::vector<long long> shortIds = {0, 1};
    EXPECT_THROW(gatherTemporal(window, 1, TemporalParams{}, &cache, &shortIds), InputError);
}

// The temporal row of the registry through the one interface (sequence_methods.h): frame t comes
// out once frames up to t + radius are in (or at finish()), and is denoiseTemporal on the window
// t - r .. t + r, bit for bit (the stream's cache changes nothing); skip() passes a frame over
// without changing its neighbours'; ignore(ObjectId) before any frame is denoised is the frames
// without ids; reset() starts over; the still methods run frame by frame through the same interface.
TEST(TemporalStream, IsDenoiseTemporalOverEachWindow) {
    SceneOptions o;
    o.noiseSigma = 0.2f;
    const auto synth = makeFrames(o, 5);
    TemporalParams p;
    p.radius = 1, p.staticRadius = 0;
    SequenceSetup setup;
    setup.params = ParamSet(temporalParams(), p);
    setup.still.method = DenoiseMethod::Eaw;
    const std::unique_ptr<SequenceDenoiser> d = makeSequenceDenoiser(kTemporalMethod, setup);
    EXPECT_EQ(d->lookahead(), 1);
    EXPECT_EQ(d->lookbehind(), 1);
    auto expected = [&](size_t t, bool withIds) {
        std::vector<Frame> window;
        for (size_t i = t > 0 ? t - 1 : 0; i <= std::min(synth.size() - 1, t + 1); ++i) {
            window.push_back(synth[i].frame());
            if (!withIds) window.back().ids = nullptr;
        }
        DenoiseOptions eaw;
        eaw.method = DenoiseMethod::Eaw;
        return denoiseTemporal(window, t > 0 ? 1 : 0, p, eaw);
    };
    std::vector<SequenceOutput> outs;
    for (size_t i = 0; i < synth.size(); ++i) {
        d->push({synth[i].frame(), nullptr});
        if (i == 0) d->ignore(Buffer::ObjectId);  // from here on (the frame pushed included): no ids
        if (i == 1) {
            ASSERT_TRUE(d->ready());
            d->skip();  // frame 0
            continue;
        }
        while (d->ready()) outs.push_back(d->next());
    }
    EXPECT_FALSE(d->ready());
    d->finish();
    outs.push_back(d->next());
    EXPECT_THROW(d->next(), InputError);
    EXPECT_THROW(d->push({synth[0].frame(), nullptr}), InputError);  // after finish()
    ASSERT_EQ(outs.size(), 4u);
    for (const SequenceOutput& out : outs) {
        EXPECT_TRUE(sameImages(out.image, expected(out.index, false))) << out.index;
        EXPECT_EQ(out.methodUsed, "eaw");
        EXPECT_EQ(out.detail.rfind(" (+-1 frames, ", 0), 0u) << out.detail;
    }
    EXPECT_EQ(outs.front().index, 1u);
    d->reset();
    d->push({synth[0].frame(), nullptr});
    d->push({synth[1].frame(), nullptr});
    const SequenceOutput again = d->next();
    EXPECT_EQ(again.index, 0u);
    EXPECT_TRUE(sameImages(again.image, expected(0, true)));  // ids back: reset() forgets ignore()
    // A still method through the same interface: each frame alone, auto's choice in its words.
    const std::unique_ptr<SequenceDenoiser> still = makeSequenceDenoiser("auto", setup);
    EXPECT_EQ(still->lookahead(), 0);
    still->push({synth[2].frame(), nullptr});
    const SequenceOutput s = still->next();
    EXPECT_EQ(s.detail, " -> " + s.methodUsed);
    EXPECT_THROW(makeSequenceDenoiser("median", setup), InputError);
    setup.params = ParamSet(svgfParams());
    EXPECT_THROW(makeSequenceDenoiser(kTemporalMethod, setup), InputError);  // another method's table
}

TEST(TemporalGather, BadWindowsThrow) {
    SceneOptions o;
    auto synth = makeFrames(o, 3);
    std::vector<Frame> f = framesOf(synth);
    EXPECT_THROW(gatherTemporal(f, 3, TemporalParams{}), InputError);
    TemporalParams bad;
    bad.radius = 17;
    EXPECT_THROW(gatherTemporal(f, 1, bad), ParamError);
    std::vector<Frame> missing = f;
    missing[0].albedo = nullptr;
    EXPECT_THROW(gatherTemporal(missing, 1, TemporalParams{}), InputError);
    SceneOptions small = o;
    small.width = 32;
    SynthFrame other = makeFrame(small, 0);
    std::vector<Frame> sizes = f;
    sizes[2] = other.frame();
    EXPECT_THROW(gatherTemporal(sizes, 1, TemporalParams{}), InputError);
    // Out of the radius, a frame is not looked at.
    TemporalParams one;
    one.radius = 0;
    EXPECT_NO_THROW(gatherTemporal(sizes, 0, one));
}

// `denoise --sequence` without --method runs the temporal method and says so, per frame, with the
// still method auto chose; --spatial picks that method.
TEST(TemporalCli, IsTheSequenceDefaultAndSaysSo) {
    TempDir dir;
    const std::string seq = renderSequence(dir);
    test::expectCli("denoise --sequence " + seq + " --out " + (dir / "out"), 0,
                    {"frame_0001: temporal (+-3 frames", "then auto -> blend)"});
    for (int f = 0; f < 3; ++f) EXPECT_TRUE(fs::exists(dir / ("out/frame_000" + std::to_string(f) + ".exr")));
    test::expectCli("denoise --sequence " + seq + " --spatial eaw --out " + (dir / "eaw"), 0, {"then eaw)"});
}

// Radius 0 with --spatial eaw writes what --method eaw writes, bit for bit. The causal mode
// denoises each frame from the ones before it: frame 0 alone (what --method eaw gives), frame 2
// from frames 0..2, and its lines say so.
TEST(TemporalCli, RadiusZeroEqualsThePerFrameMethod) {
    TempDir dir;
    const std::string seq = renderSequence(dir);
    std::string causalOutput;
    for (const char* run : {"t --temporal-radius 0 --spatial eaw", "e --method eaw", "c --temporal-causal --spatial eaw"}) {
        const std::string args(run);
        auto r = runCli("denoise --sequence " + seq + " --device cpu --out " + (dir / args.substr(0, 1)) + args.substr(1));
        ASSERT_EQ(r.exitCode, 0) << r.output;
        if (args[0] == 'c') causalOutput = r.output;
    }
    for (int f = 0; f < 3; ++f) {
        const std::string name = "/frame_000" + std::to_string(f) + ".exr";
        EXPECT_TRUE(sameImages(atrous::readImage(dir / "t" + name), atrous::readImage(dir / "e" + name))) << name;
    }
    EXPECT_NE(causalOutput.find("frame_0001: temporal (causal, -3 frames"), std::string::npos) << causalOutput;
    EXPECT_TRUE(sameImages(atrous::readImage(dir / "c/frame_0000.exr"), atrous::readImage(dir / "e/frame_0000.exr")));
    EXPECT_FALSE(sameImages(atrous::readImage(dir / "c/frame_0002.exr"), atrous::readImage(dir / "e/frame_0002.exr")));
}

TEST(TemporalCli, BadFlagsExitTwoAndWriteNothing) {
    TempDir dir;
    const std::string seq = renderSequence(dir);
    const std::string out = dir / "out";
    struct Case {
        std::string args, says;
    };
    for (const Case& c : {Case{"--method svgf --spatial eaw", "--spatial"}, Case{"--step 2", "--step 2"},
                          Case{"--temporal-radius 17", "--temporal-radius"}, Case{"--spatial nope", "--spatial"},
                          Case{"--temporal-falloff -1", "--temporal-falloff"}}) {
        auto r = runCli("denoise --sequence " + seq + " " + c.args + " --out " + out);
        EXPECT_EQ(r.exitCode, 2) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
        EXPECT_FALSE(fs::exists(out)) << c.args;
    }
    auto r = runCli("denoise --in " + seq + "/frame_0000 --method temporal --out " + (dir / "x.exr"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("--sequence"), std::string::npos) << r.output;
}

// The sequence methods come from one list: the CLI's help and its unknown-method message name every
// row, the default with --sequence is the first row, and each row denoises a sequence.
TEST(TemporalCli, SequenceMethodsComeFromTheList) {
    ASSERT_FALSE(sequenceMethods().empty());
    EXPECT_STREQ(sequenceMethods().front().name, "temporal");
    auto help = runCli("denoise --help");
    auto unknown = runCli("denoise --method nope --color x.exr --out y.exr");
    EXPECT_EQ(unknown.exitCode, 2) << unknown.output;
    TempDir dir;
    const std::string seq = renderSequence(dir, 2);
    for (const SequenceMethodInfo& m : sequenceMethods()) {
        EXPECT_NE(help.output.find(std::string(m.name) + " (with --sequence): " + m.summary), std::string::npos)
            << m.name << "\n" << help.output;
        EXPECT_NE(unknown.output.find(m.name), std::string::npos) << unknown.output;
        EXPECT_EQ(findSequenceMethod(m.name), &m);
        auto r = runCli("denoise --sequence " + seq + " --method " + m.name + " --out " + (dir / m.name));
        EXPECT_EQ(r.exitCode, 0) << r.output;
    }
    EXPECT_EQ(findSequenceMethod("eaw"), nullptr);
    EXPECT_EQ(sequenceMethodNames(), "temporal, svgf");
}

// Causal: the frames after the centre are not used, whatever the window holds: the gather over
// frames 0..6 centred on 3 is the gather over frames 0..3 (bit for bit), and it averages the
// centre and the three before it (4 frames at falloff 0), where the two-sided one averages 7.
// The causal falloff is the one used then: at 1, frames t-1..t-3 weigh 0.61, 0.14, 0.011.
TEST(TemporalGather, CausalUsesTheFramesBeforeOnly) {
    SceneOptions o;
    o.flat = true, o.withBox = false, o.noiseSigma = 0.1f;
    const auto synth = makeFrames(o, 7);
    const auto all = framesOf(synth);
    TemporalParams p;
    p.falloff = p.causalFalloff = 0.0f;
    p.causal = true;
    const TemporalGather g = gatherTemporal(all, 3, p);
    const std::vector<Frame> past(all.begin(), all.begin() + 4);
    const TemporalGather h = gatherTemporal(past, 3, p);
    EXPECT_TRUE(sameImages(g.color, h.color));
    EXPECT_NEAR(meanOf(g.frames, 0), 4.0, 0.2);
    p.causalFalloff = 1.0f;
    const double sw = 1 + std::exp(-0.5) + std::exp(-2.0) + std::exp(-4.5);
    const double sw2 = 1 + std::exp(-1.0) + std::exp(-4.0) + std::exp(-9.0);
    EXPECT_NEAR(meanOf(gatherTemporal(all, 3, p).frames, 0), sw * sw / sw2, 0.05 * sw * sw / sw2);
    p.causal = false;
    EXPECT_NEAR(meanOf(gatherTemporal(all, 3, p).frames, 0), 7.0, 0.35);
}

// A sun-lit sky whose 4-spp frames carry fireflies where a sample saw the sun (colour = emission
// there): the window's firefly pass scales such a pixel's colour, and its emission must be scaled
// with it (the frame's own and its neighbours'), or colour - emission in the average turns hugely
// negative and the output with it. On atrous's own sphere-env orbit the temporal output was
// 0.8-72 relMSE (negative pixels of -118) against 0.02 per frame. Now every frame is at most 1.25x
// the per-frame method's relMSE (1.25: the margin of a 6-frame 96x72 sequence against a 64-spp
// reference) and no pixel is below -0.01 (SURE's own rounding reaches -0.004 per frame).
TEST(TemporalCli, FirefliesOnTheSunLeaveNoNegativeOutput) {
    TempDir dir;
    auto r = runCli("render --scene sphere-env --width 96 --height 72 --spp 4 --frames 6 --camera-path orbit "
                    "--reference-spp 64 --quiet --out " + dir / "seq");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    ASSERT_EQ(runCli("denoise --sequence " + dir / "seq" + " --out " + dir / "t").exitCode, 0);
    ASSERT_EQ(runCli("denoise --sequence " + dir / "seq" + " --method auto --out " + dir / "f").exitCode, 0);
    for (int i = 0; i < 6; ++i) {
        const std::string n = "frame_000" + std::to_string(i);
        const Image ref = atrous::readImage(dir / "seq" + "/" + n + "/reference.exr");
        const Image t = atrous::readImage(dir / "t" + "/" + n + ".exr"), f = atrous::readImage(dir / "f" + "/" + n + ".exr");
        EXPECT_LE(computeMetrics(t, ref).relMse, 1.25 * computeMetrics(f, ref).relMse) << n;
        float lo = 0;
        for (size_t k = 0; k < t.size(); ++k) lo = std::min(lo, t.data()[k]);
        EXPECT_GE(lo, -0.01f) << n;
    }
}

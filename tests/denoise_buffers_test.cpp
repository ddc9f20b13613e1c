// denoise() on DenoiseBuffers (include/atrous/denoise.h): the caller hands its colour, variance
// and emission images over and the filter works in their storage. Its result must be the const
// overload's bit for bit, for every method, with a variance, without one and with an all-zero one,
// with and without the firefly pass and the emission; depth in 1 channel and ids in 2 must give
// what 3-channel copies give.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "denoise_test_util.h"

using namespace atrous;

using test::firstBitDifference;

namespace {

Image firstChannels(const Image& src, int channels) {
    Image out(src.width(), src.height(), channels);
    std::memcpy(out.data(), src.data(), out.size() * sizeof(float));
    return out;
}

// A scene with an emission (a bright patch) and a few fireflies, so the emission filter and the
// firefly pass do work.
struct Scene {
    test::SyntheticScene s;
    Image emission;
    Scene() : s(test::makeScene(53, 41, 0.3f, 17)), emission(53, 41, 3) {
        for (int y = 5; y < 12; ++y)
            for (int x = 30; x < 40; ++x)
                for (int c = 0; c < 3; ++c) {
                    emission(x, y, c) = (x == 30 || y == 5) ? 2.0f : 5.0f;
                    s.noisy(x, y, c) += emission(x, y, c);
                }
        std::mt19937 rng(3);
        for (int k = 0; k < 12; ++k) {
            const int x = int(rng() % 53), y = int(rng() % 41);
            for (int c = 0; c < 3; ++c) s.noisy(x, y, c) += 30.0f;
        }
    }
};

}  // namespace

TEST(DenoiseBuffers, HandedOverImagesGiveTheConstOverloadsResult) {
    const Scene sc;
    for (DenoiseMethod m : {DenoiseMethod::Eaw, DenoiseMethod::Sure, DenoiseMethod::Learned})
        for (int variance = 0; variance < 3; ++variance)  // given, none, all zero
            for (int emission = 0; emission < 2; ++emission)
                for (int firefly = 0; firefly < 2; ++firefly) {
                    const std::string what = std::string(denoiseMethodName(m)) + " variance " + std::to_string(variance) +
                                             " emission " + std::to_string(emission) + " firefly " +
                                             std::to_string(firefly);
                    DenoiseOptions o;
                    o.method = m;
                    o.firefly.enabled = firefly == 1;
                    DenoiseReport r1, r2;
                    Image zero(53, 41, 3);
                    Frame in = sc.s.inputs();
                    in.variance = variance == 0 ? &sc.s.variance : (variance == 1 ? nullptr : &zero);
                    if (emission) in.emission = &sc.emission;
                    const Image want = test::denoiseReporting(in, o, r1);

                    Image color = sc.s.noisy.clone(), var = sc.s.variance.clone(), em = sc.emission.clone();
                    Image zero2(53, 41, 3);
                    DenoiseBuffers b;
                    b.color = &color;
                    b.variance = variance == 0 ? &var : (variance == 1 ? nullptr : &zero2);
                    b.emission = emission ? &em : nullptr;
                    b.albedo = &sc.s.albedo, b.normal = &sc.s.normal, b.position = &sc.s.position;
                    b.depth = &sc.s.depth, b.ids = &sc.s.ids;
                    const Image got = test::denoiseReporting(b, o, r2);
                    EXPECT_EQ(firstBitDifference(got, want), -1) << what;
                    EXPECT_EQ(got.channels(), 3) << what;
                    EXPECT_EQ(r1.firefliesClamped, r2.firefliesClamped) << what;
                    EXPECT_EQ(r1.meanLuminanceAfterFirefly, r2.meanLuminanceAfterFirefly) << what;
                    EXPECT_EQ(r1.meanLuminanceIn, r2.meanLuminanceIn) << what;
                    EXPECT_EQ(r1.noiseSigma[1], r2.noiseSigma[1]) << what;
                    if (firefly && variance != 0) EXPECT_GT(r1.firefliesClamped, 0) << what;  // (a given variance keeps them: their own variance is small)
                }
}

// The frame's conventions (atrous/buffers.h): depth in channel 0, ids with the object id in channel 0
// and the material id in channel 1 when given; one channel of ids is the same as a material id of 0.
TEST(DenoiseBuffers, DepthInOneChannelAndIdsInTwoAreTheSame) {
    const test::SyntheticScene s = test::makeScene(40, 33, 0.3f, 5);
    const Image depth1 = firstChannels(s.depth, 1), ids2 = firstChannels(s.ids, 2);
    for (DenoiseMethod m : {DenoiseMethod::Eaw, DenoiseMethod::Sure, DenoiseMethod::Learned})
        for (int variance = 0; variance < 2; ++variance) {
            DenoiseOptions o;
            o.method = m;
            o.eaw.sigmaDepth = 0.1f;  // the depth stop reads depth too
            Frame in = s.inputs();
            if (!variance) in.variance = nullptr;
            const Image want = denoise(in, o);
            in.depth = &depth1, in.ids = &ids2;
            EXPECT_EQ(firstBitDifference(denoise(in, o), want), -1)
                << denoiseMethodName(m) << " variance " << variance;
        }
    Image ids1 = firstChannels(s.ids, 1), idsZero = firstChannels(s.ids, 2);
    std::fill(idsZero.data() + idsZero.plane(), idsZero.data() + 2 * idsZero.plane(), 0.0f);
    Frame in = s.inputs();
    in.ids = &idsZero;
    const Image want = denoise(in, DenoiseOptions{});
    in.ids = &ids1;
    EXPECT_EQ(firstBitDifference(denoise(in, DenoiseOptions{}), want), -1);
    // An empty buffer is an error naming it.
    const Image none;
    in.ids = &none;
    try {
        denoise(in, DenoiseOptions{});
        FAIL() << "an empty ids buffer accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("ids buffer is empty"), std::string::npos) << e.what();
    }
}

// An uninformative variance (every value 0 or non-finite, -inf included) is dropped before its
// values are checked, as it was by its own scan; a negative value in an informative one is an error
// naming the variance buffer.
TEST(DenoiseBuffers, UninformativeVarianceIsDroppedBeforeItsValuesAreChecked) {
    const test::SyntheticScene s = test::makeScene(30, 20, 0.3f, 3);
    Image var(30, 20, 3);
    var.fill(-INFINITY);
    var(3, 4, 1) = 0.0f;
    Frame in = s.inputs();
    in.variance = &var;
    DenoiseReport rep;
    DenoiseOptions o;
    EXPECT_NO_THROW(test::denoiseReporting(in, o, rep));
    EXPECT_TRUE(rep.varianceIgnored);
    EXPECT_TRUE(rep.noiseEstimated);
    Image bad = s.variance.clone();
    bad(7, 2, 0) = -1.0f;
    in.variance = &bad;
    const std::string msg = test::inputErrorOf(in, o);
    EXPECT_NE(msg.find("variance buffer has a negative value"), std::string::npos) << "InputError: '" << msg << "'";
    EXPECT_NE(msg.find("(7, 2)"), std::string::npos) << msg;
}

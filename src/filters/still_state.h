// The still path's vocabulary (docs/architecture.md, "The still path"): what a call is given
// (StillInputs, StillConfig, StillOutputs), the planes it recycles (PlanePool), what the preparation
// leaves (Prepared) and what a cascade hands the finishing (Filtered). The stages themselves are
// still_prepare.h, still_cascades.h and still_finish.h, run in order by still_pipeline.h.
#pragma once
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/image.h"
#include "atrous/learned.h"
#include "filters/modulation.h"
#include "filters/stage_clock.h"

namespace atrous {
struct CpuExec;
}

namespace atrous::filters {

constexpr int kMaxLevels = 10;
// Exponent added per unit squared id difference: ids are integers, so a differing id gives a
// weight of exactly 0 (fastExp returns 0 below -80).
constexpr float kIdPenalty = 1e4f;

// A call's buffers as views on the executor's device (invalid when absent).
struct StillInputs {
    // variance: invalid when estimated (no variance buffer): the preparation then fills its own from
    // the global estimate (GlobalVariance, cfg.noiseFloorVar); the GPU path passes a constant one.
    ImageView color, variance;
    ImageView albedo, normal, position, depth, ids, emission;
    // Optional, host only (denoise() on DenoiseBuffers): the caller's Images behind color, variance
    // and emission, handed over. The path then works in their storage (c_0 and var(c_0) are
    // sanitised in place, the emission filter ping-pongs through the emission's image) and may
    // keep any of them as its result; a handed-over image is left empty or holding intermediate
    // values. Null, or not the image the view is of: copies.
    Image* colorStore = nullptr;
    Image* varianceStore = nullptr;
    Image* emissionStore = nullptr;
};

// The caller's options held whole, plus what is derived from the inputs.
struct StillConfig {
    DenoiseOptions opts;       // opts.method is resolved (not Auto)
    LearnedWeights learned{};  // the learned cascade's weights (loaded by denoise())
    bool varianceGiven = true;  // false: the variance is a constant estimate
    // Without a variance: the local estimate (noise_estimate.h) over quadrants of this radius
    // (0 = keep the constant), floored at noiseFloorVar (the global estimate times a fraction) and
    // capped at kNoiseCapMul times it.
    int noiseRadius = 0;
    float noiseFloorVar[3] = {0, 0, 0};
    // EAW and SURE with an albedo: the residual the albedo explains goes back after the cascade
    // (safety_net.h, runAlbedoGiveBack). Off only for tests that measure without it.
    bool albedoGiveBack = true;
};

// What the CPU path measures for the report while it runs (the GPU path reduces its afterFirefly
// and fireflyFlag planes instead).
struct StillReport {
    int firefliesClamped = 0;
    double lumAfterSum = 0;  // Σ of the finite luminances of c_0 after the firefly pass
    double lumAfterCount = 0;
};

struct StillOutputs {
    // 3 channels. Invalid: the result is remodulated in place in the path's own planes and moved
    // into *result.
    ImageView out;
    Image* result = nullptr;
    ImageView afterFirefly;  // optional: c_0 after sanitising and firefly suppression (3 ch)
    ImageView fireflyFlag;   // optional: 1 where a firefly was clamped (1 ch)
    ImageView sureS;         // optional: SURE's s_i per level (levels channels)
    StageClock* clock = nullptr;  // optional: started by the caller, marked after each stage
    StillReport* report = nullptr;  // optional (CPU): the firefly count and the luminance after it
};

// The still path's temporaries, recycled in one place (docs/architecture.md, "Memory"). Every plane
// is taken without a zero fill (each is written whole before it is read) unless asked zeroed, and
// a stage gives back what it no longer needs where a later stage can use it: the colour and
// variance the firefly pass copied from (the kept input, the cascade's spare buffers, the σ
// planes), the variance once the colour scale is taken (EAW's second cascade buffer).
class PlanePool {
public:
    PlanePool(int width, int height, Device device) : mWidth(width), mHeight(height), mDevice(device) {}
    int width() const { return mWidth; }
    int height() const { return mHeight; }
    Device device() const { return mDevice; }
    // A given-back plane set of `channels` channels, else a new one.
    Image take(int channels) {
        Image spare = takeSpare(channels);
        return spare.empty() ? Image::uninitialized(mWidth, mHeight, channels, mDevice) : std::move(spare);
    }
    // A given-back plane set, or an empty image when there is none (no allocation).
    Image takeSpare(int channels) {
        for (size_t i = 0; i < mFree.size(); ++i)
            if (mFree[i].channels() == channels) {
                Image img = std::move(mFree[i]);
                mFree.erase(mFree.begin() + long(i));
                return img;
            }
        return Image();
    }
    Image zeroed(int channels) const { return Image(mWidth, mHeight, channels, mDevice); }
    void give(Image&& img) {
        if (!img.empty()) mFree.push_back(std::move(img));
    }

private:
    int mWidth, mHeight;
    Device mDevice;
    std::vector<Image> mFree;
};

// What the preparation leaves: the demodulated, clamped colour and its variance (the cascade's
// input, which a built-in cascade may overwrite), the sanitised features (views of their owners
// below or, on the CPU, of the caller's clean buffers; invalid when absent or not read), the
// filtered emission, and whether the variance was estimated per pixel.
struct Prepared {
    Image color, variance;
    ImageView albedo, normal, position, depth, ids, emission;
    bool noise = false;
    // The owners of the views above.
    Image albedoStore, rimStore, normalStore, positionStore, depthStore, idsStore;
    Image emissionStore, emissionA, emissionB;
};

// A cascade's output, in the demodulated units: F = base (+ detail, SURE's kept detail sum Σ s_i d_i,
// added by whoever reads F: the give-back, the blend, the safety net, the remodulation).
struct Filtered {
    Image base;
    Image detail;        // empty: none
    ImageView fallback;  // valid: base's non-finite samples become these (a registered cascade's output)
    ImageView detailView() const { return detail.empty() ? ImageView{} : detail.view(); }
};

// The still filters' albedo rule (modulation.h): the options' eps and floor, the rim rule on, a
// non-finite albedo read as 0.
inline AlbedoRule stillAlbedoRule(const DenoiseOptions& o) {
    AlbedoRule r;
    r.eps = o.albedoEpsilon, r.floor = o.albedoFloor;
    return r;
}

// The caller's image behind `v` when it was handed over (3 channels, on `dev`, the view's very
// storage), moved out of *store; else an empty image.
inline Image takeStore(Image* store, const ImageView& v, Device dev) {
    if (!store || store->empty() || store->device() != dev || store->channels() != 3 || store->data() != v.data ||
        store->width() != v.width || store->height() != v.height)
        return Image();
    return std::move(*store);
}

// out = a' of the rule (Remodulate's multiplier; 1 without an albedo).
struct ModulationOf {
    AlbedoRule rule;
    ImageView albedo, out;
    ATROUS_HOST_DEVICE void operator()(int x, int y) const {
        float a[3];
        rule.at(albedo, x, y, a);
        for (int c = 0; c < 3; ++c) out(x, y, c) = a[c];
    }
};

// The report's luminance after the firefly pass: nothing on a device executor (its caller
// reduces the afterFirefly plane); the CpuExec overload (src/cpu/driver_cpu.cpp) sums the finite
// luminances of `c` per row in double, the rows in order.
template <class Exec>
void reportLuminance(const Exec&, const ImageView&, StillReport&) {}
void reportLuminance(const CpuExec& exec, const ImageView& c, StillReport& report);
// The report's count of clamped pixels: nothing on a device executor; the CpuExec overload counts
// the flags (1 where the pass, dense step included, clamped).
template <class Exec>
void reportFireflies(const Exec&, const ImageView&, StillReport&) {}
void reportFireflies(const CpuExec& exec, const ImageView& flag, StillReport& report);

}  // namespace atrous::filters

// Image-quality metrics against a reference (docs/eval.md, "What is measured"), and one without
// (computeFlicker: a sequence's frame-to-frame change where the motion vectors reproject). All inputs are linear HDR RGB
// host images of the same size; non-finite pixels count as errors (they are replaced by 0 before
// comparing, so a NaN in the image shows up as a large error instead of poisoning the mean).
#pragma once
#include "atrous/buffers.h"
#include "atrous/image.h"

namespace atrous {

struct ImageMetrics {
    double mse = 0;     // mean over pixels and channels of (x - r)², linear HDR
    double relMse = 0;  // mean of (x - r)² / (r² + 0.01)
    double psnr = 0;    // dB, on tonemapped images: x/(1+x), then ^(1/2.2), clamped to [0,1]
    double ssim = 0;    // on the tonemapped luminance, 11×11 Gaussian window σ = 1.5
    // Pixels with a NaN or Inf in any channel (counted as 0 in the figures above): the CLI and
    // Python report them, since a broken image must not pass for a good one.
    int nonFinitePixels = 0;           // in the image
    int referenceNonFinitePixels = 0;  // in the reference
};

// Throws InputError when the sizes differ or an image is empty.
ImageMetrics computeMetrics(const Image& image, const Image& reference);

// The temporal error of one step of a sequence (docs/eval.md, "Sequences"): with d = image −
// previous and d_ref = reference − previousReference, relMse = mean over pixels and channels of
// (d − d_ref)² / (reference² + 0.01) (what the evaluation report's temporal relMSE is), and psnr the
// PSNR of the tonemapped frames' differences against the reference's (tPSNR; 100 dB when equal).
// Flicker the reference does not have raises both. Throws InputError as computeMetrics does.
struct TemporalMetrics {
    double relMse = 0;
    double psnr = 0;
};
TemporalMetrics computeTemporalMetrics(const Image& image, const Image& previous, const Image& reference,
                                       const Image& previousReference);

// The reference-free flicker of one step of a sequence (docs/temporal.md, "Flicker without a
// reference"): frame t's `image` against frame t-1's `previous` warped onto t by the motion vectors
// of `guide` (frame t's buffers: motion previous - current in pixels, and the depth, normal and ids
// where it has them; atrous/buffers.h), each bilinear tap kept only where the offline temporal
// filter's reprojection test holds between `guide` and `previousGuide` (frame t-1's): equal ids,
// depth within 2x the local depth gradient + 1%, normals within cos 0.9. A pixel without motion, or
// whose kept taps weigh under half the footprint, is left out. relMse = the mean, over the pixels
// that reproject and the channels, of (x - w)² / (((x + w) / 2)² + 0.01), with w the warped
// previous value (temporal relMSE with the reference's difference taken as 0: what does not
// reproject, and a surface whose true colour changes, are not told apart from flicker);
// reprojected = the fraction of the pixels that reproject (relMse 0 when none does). Non-finite
// values count as 0. Throws InputError when sizes differ, an image is empty or guide has no motion.
struct FlickerMetrics {
    double relMse = 0;
    double reprojected = 0;
};
FlickerMetrics computeFlicker(const Image& image, const Image& previous, const Frame& guide, const Frame& previousGuide);

// Tonemap used by PSNR/SSIM: clamp(pow(x/(1+x), 1/2.2), 0, 1) (x < 0 → 0).
float tonemapForMetrics(float x);
// The same as an 8-bit display value (displayByte, atrous/srgb.h: rounded to nearest): the one
// tonemapped preview of an HDR image (the evaluation's crops and reports, the corpus previews;
// Python's atrous.tonemap(image, dtype=numpy.uint8)). Non-finite values are 0, as in the PNG writer.
unsigned char tonemap8(float x);

// Per-pixel error maps (3-channel host images, the value repeated in R,G,B): squared error
// averaged over channels, and relative squared error.
Image squaredErrorMap(const Image& image, const Image& reference);
Image relativeErrorMap(const Image& image, const Image& reference);

}  // namespace atrous

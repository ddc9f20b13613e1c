// The filters' parameter tables (the machinery: atrous/param_table.h), one row per field of each
// struct:
//
//   denoiseParams(): DenoiseOptions' scalars with its EawParams, SureParams, FireflyParams and
//                    SafetyNetParams (each row says which in `group`); CLI flag --<name>
//   svgfParams():    SvgfParams; CLI flag --svgf-<name> (a few keep older spellings, `flag`)
//   temporalParams(): TemporalParams (the offline sequence denoiser); CLI flag --temporal-<name>
//
// The renderer's table, renderParams() (RenderSettings; CLI flag --<name> of `atrous render` and
// `atrous view`), is in atrous/render.h.
#pragma once
#include <iterator>
#include <string>
#include <utility>

#include "atrous/denoise.h"
#include "atrous/param_table.h"
#include "atrous/svgf.h"
#include "atrous/temporal.h"

namespace atrous {

namespace params_detail {
inline constexpr const char* kSureModes[] = {"discrete", "james-stein", nullptr};
std::string checkFeedbackTap(const SvgfParams& p);
std::string checkCandidates(const DenoiseOptions& o);

using D = DenoiseOptions;
using P = SvgfParams;
using T = TemporalParams;
// clang-format off
inline const ParamField<D> kDenoise[] = {
    {"levels", &at2<&D::eaw, &EawParams::levels>, paramIn(1, 10), "a-trous levels (5 reach +-62 pixels)", "eaw"},
    {"sigma_color", &at2<&D::eaw, &EawParams::sigmaColor>, paramZeroOr(1e-6, "automatic"),
     "raw sigma_c (0 = automatic, from the variance)", "eaw"},
    {"color_scale", &at2<&D::eaw, &EawParams::colorScale>, paramIn(1e-6, 1e6), "k_c of the automatic sigma_c", "eaw"},
    {"color_level_factor", &at2<&D::eaw, &EawParams::colorLevelFactor>, paramAbove(0, 1),
     "sigma_c,i = sigma_c * factor^i", "eaw"},
    {"sigma_normal", &at2<&D::eaw, &EawParams::sigmaNormal>, paramZeroOr(1e-6, "off"),
     "sigma_n on |n_p - n_q| (0 = no normal stop)", "eaw"},
    {"normal_step_scale", &at2<&D::eaw, &EawParams::normalStepScale>, {},
     "divide the normal distance by step^2 (the paper's GLSL)", "eaw"},
    {"sigma_position", &at2<&D::eaw, &EawParams::sigmaPosition>, paramZeroOr(1e-6, "automatic"),
     "raw sigma_x (0 = automatic, from the pixel footprint)", "eaw"},
    {"position_scale", &at2<&D::eaw, &EawParams::positionScale>, paramIn(1e-6, 1e6), "k_x of the automatic sigma_x", "eaw"},
    {"sigma_depth", &at2<&D::eaw, &EawParams::sigmaDepth>, paramZeroOr(1e-6, "off"),
     "sigma_z on the relative depth difference (0 = off)", "eaw"},
    {"use_ids", &at2<&D::eaw, &EawParams::useIds>, {}, "weight 0 across mesh or material id changes (the ids buffer)",
     "eaw", "no-ids", true},
    {"emission_levels", &at2<&D::eaw, &EawParams::emissionLevels>, paramIn(0, 10),
     "levels of the emission buffer's edge-avoiding filter (0 = add the emission back as is)", "emission"},
    {"emission_scale", &at2<&D::eaw, &EawParams::emissionScale>, paramIn(1e-6, 1e6),
     "k of the emission filter's sigma^2 = k * 2 min(V_p, V_q)", "emission"},
    {"sure_mode", &at2<&D::sure, &SureParams::mode>, {}, "discrete | james-stein", "sure", nullptr, false, kSureModes},
    {"sure_candidates", &at2<&D::sure, &SureParams::candidates>, paramIn(0, 1),
     "the fractions of each detail SURE chooses from (comma-separated on the CLI)", "sure", nullptr, false, nullptr,
     &checkCandidates},
    {"sure_window", &at2<&D::sure, &SureParams::windowRadius>, paramIn(1, 10), "SURE window radius r ((2r+1)^2 window)",
     "sure"},
    {"sure_first_level", &at2<&D::sure, &SureParams::firstLevel>, paramIn(0, 16),
     "SURE keeps no detail of levels below this one (0 = the paper's form)", "sure"},
    {"correlated_variance", &at2<&D::sure, &SureParams::correlatedVariance>, {},
     "correct the propagated variance for the levels' correlation (else plain independence)", "sure", nullptr, true},
    {"firefly", &at2<&D::firefly, &FireflyParams::enabled>, {}, "firefly suppression", "firefly", nullptr, true},
    {"firefly_k", &at2<&D::firefly, &FireflyParams::k>, paramAtLeast(1e-6), "firefly bound: k local standard deviations",
     "firefly"},
    {"firefly_restore", &at2<&D::firefly, &FireflyParams::restore>, {},
     "put the clamped light back, spread where clamped pixels are dense (a lone firefly's is dropped)", "firefly",
     "no-firefly-restore", true},
    {"safety_net", &at2<&D::safety, &SafetyNetParams::enabled>, {},
     "where SURE estimates the output worse than the input, move it back toward the input (for a trusted variance)",
     "safety"},
    {"safety_window", &at2<&D::safety, &SafetyNetParams::windowRadius>, paramIn(1, 10),
     "radius of the safety net's SURE window", "safety"},
    {"safety_trigger", &at2<&D::safety, &SafetyNetParams::trigger>, paramIn(0, 1e6),
     "the safety net acts where the residual's energy exceeds this many times the input's variance", "safety"},
    {"demodulate", &at<&D::demodulate>, {}, "divide by the albedo before filtering, multiply after", "", nullptr, true},
    {"albedo_epsilon", &at<&D::albedoEpsilon>, paramAtLeast(1e-6), "smallest albedo divided by"},
    {"albedo_floor", &at<&D::albedoFloor>, paramIn(0, 1),
     "demodulation fades out where the largest albedo channel is below this (black albedo on glass, mirrors, "
     "lights; 0 = off)"},
};

inline const ParamField<P> kSvgf[] = {
    {"sigma_l", &at<&P::sigmaL>, paramAtLeast(1e-6), "luminance edge stop sigma_l, in standard deviations"},
    {"sigma_n", &at<&P::sigmaN>, paramAtLeast(0), "normal edge stop exponent sigma_n"},
    {"sigma_z", &at<&P::sigmaZ>, paramAtLeast(1e-6), "depth edge stop sigma_z, relative to the depth gradient"},
    {"alpha", &at<&P::alpha>, paramAbove(0, 1), "minimum temporal blend factor of the colour"},
    {"moments_alpha", &at<&P::momentsAlpha>, paramAbove(0, 1), "minimum temporal blend factor of the moments"},
    {"history_cap", &at<&P::historyCap>, paramIn(1, 1 << 20), "maximum history length in frames"},
    {"history_clip", &at<&P::historyClip>, paramAtLeast(0),
     "clip the reprojected history into mean +- this many std of the current 3x3 samples (0 = off)"},
    {"levels", &at<&P::levels>, paramIn(0, 10), "a-trous levels (0 = temporal accumulation only)"},
    {"feedback_tap", &at<&P::feedbackTap>, paramIn(-1, 9), "level whose output becomes the colour history (-1 = unfiltered)",
     "", nullptr, false, nullptr, &checkFeedbackTap},
    {"spatial_variance_frames", &at<&P::spatialVarianceFrames>, paramIn(1, 1 << 20),
     "history length below which the variance is estimated spatially (7x7)"},
    {"depth_tolerance", &at<&P::depthTolerance>, paramAtLeast(0),
     "reprojection depth test tau_z, relative to the depth gradient"},
    {"normal_cos", &at<&P::normalCos>, paramIn(-1, 1), "reprojection: minimum cosine between normals"},
    {"taa", &at<&P::taa>, {}, "temporal anti-aliasing after SVGF", "", "taa"},
    {"taa_alpha", &at<&P::taaAlpha>, paramAbove(0, 1), "TAA blend weight of the current frame", "", "taa-alpha"},
    {"emission_alpha", &at<&P::emissionAlpha>, paramAbove(0, 1),
     "minimum temporal blend factor of the emission (3x3-clamped history; 1 = the raw emission)"},
    {"emission_motion_alpha", &at<&P::emissionMotionAlpha>, paramAtLeast(0),
     "emission blend factor at least this times the motion across a light's edge, pixels per frame (0 = off)"},
    {"learned_spatial", &at<&P::learnedSpatial>, {},
     "the learned a-trous cascade (built-in weights, or learned_weights / --learned-weights) as the spatial "
     "filter instead of SVGF's a-trous"},
    {"safety_net", &at<&P::safetyNet>, paramAtLeast(0),
     "per-frame safety net: where SVGF's output differs from the still default's of the frame alone by more "
     "than this (3x3 mean relative luminance difference), the output becomes the still one's (0 = off)"},
};

inline const ParamField<T> kTemporal[] = {
    {"radius", &at<&T::radius>, paramIn(0, 16),
     "frames on each side of the one denoised (0 = that frame alone; where nothing moves: static_radius)"},
    {"depth_tolerance", &at<&T::depthTolerance>, paramAtLeast(0),
     "reprojection depth test tau_z, relative to the depth gradient"},
    {"normal_cos", &at<&T::normalCos>, paramIn(-1, 1), "reprojection: minimum cosine between normals"},
    {"color_sigmas", &at<&T::colorSigmas>, paramAtLeast(0),
     "leave a neighbour out where its 3x3 mean luminance differs by more than this many standard errors (0 = off)"},
    {"falloff", &at<&T::falloff>, paramAtLeast(0),
     "frame t+-k weighs exp(-k^2 / (2 falloff^2)) in the average (0 = all frames equal)"},
    {"firefly_k", &at<&T::fireflyK>, paramZeroOr(1e-6, "off"),
     "each frame's fireflies are clamped to k local standard deviations before averaging (0 = off)"},
    {"causal", &at<&T::causal>, {},
     "the frames before each one only (t-radius .. t): each frame as soon as it is rendered, as in a viewer"},
    {"causal_falloff", &at<&T::causalFalloff>, paramAtLeast(0), "the falloff in causal mode (in place of falloff)"},
    {"static_radius", &at<&T::staticRadius>, paramIn(0, 16),
     "frames on each side, equally weighted, for the pixels that have not moved (static camera and surface; "
     "offline mode, with the renderer's motion vectors; 0 = off)"},
};

// clang-format on
}  // namespace params_detail

inline const ParamTable<DenoiseOptions>& denoiseParams() {
    static const ParamTable<DenoiseOptions> t{"denoise", "", params_detail::kDenoise, std::size(params_detail::kDenoise)};
    return t;
}
// The title of a group of denoiseParams() (the CLI's help groups, the viewer's sections).
inline const char* denoiseGroupTitle(const std::string& group) {
    static const std::pair<const char*, const char*> kTitles[] = {
        {"", "Albedo demodulation"}, {"firefly", "Fireflies"}, {"emission", "Emission"},
        {"safety", "Safety net"},    {"eaw", "EAW's edge stops"},  {"sure", "SURE's choice of details"}};
    for (const auto& t : kTitles)
        if (group == t.first) return t.second;
    return "";
}
inline const ParamTable<SvgfParams>& svgfParams() {
    static const ParamTable<SvgfParams> t{"svgf", "svgf-", params_detail::kSvgf, std::size(params_detail::kSvgf)};
    return t;
}
inline const ParamTable<TemporalParams>& temporalParams() {
    static const ParamTable<TemporalParams> t{"temporal", "temporal-", params_detail::kTemporal,
                                              std::size(params_detail::kTemporal)};
    return t;
}

inline std::string params_detail::checkFeedbackTap(const SvgfParams& p) {
    // levels 0 (temporal accumulation only) works with the default tap 0: there is no filtered
    // level to feed back, so the history is the accumulation (as with -1).
    if (p.feedbackTap < p.levels || (p.levels == 0 && p.feedbackTap == 0)) return "";
    return "must be in [-1, levels - 1] (-1 = unfiltered accumulation; got " + std::to_string(p.feedbackTap) +
           " with levels " + std::to_string(p.levels) + ")";
}

inline std::string params_detail::checkCandidates(const DenoiseOptions& o) {
    const size_t n = o.sure.candidates.size();
    return n >= 1 && n <= 8 ? "" : "must list 1..8 values (got " + std::to_string(n) + ")";
}

}  // namespace atrous

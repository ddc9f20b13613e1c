// Self-describing parameters: one table per parameter set, listing each field once with the name
// users know it by (snake_case: the Python keyword, the CLI flag with '-' for '_', the name in
// error messages), a doc line, its range and where it lives in the struct. Validation, the CLI's
// flags, Python's keywords, the viewer's controls and equality all walk these tables, so a new
// field is one new line here (tests/params_test.cpp checks that every struct field has one).
// Defaults are never copied: they are what a default-constructed struct holds.
//
//   denoiseParams(): DenoiseOptions' scalars with its EawParams, SureParams, FireflyParams and
//                    SafetyNetParams (each row says which in `group`); CLI flag --<name>
//   svgfParams():    SvgfParams; CLI flag --svgf-<name> (a few keep older spellings, `flag`)
//   temporalParams(): TemporalParams (the offline sequence denoiser); CLI flag --temporal-<name>
//   renderParams():  RenderSettings (but its progress counter); CLI flag --<name> of `atrous render`
//                    and `atrous view`
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/image.h"
#include "atrous/render.h"
#include "atrous/svgf.h"
#include "atrous/temporal.h"

namespace atrous {

// A parameter out of range (or a value that does not parse). what() names the field (`parameter
// sigma_normal must be 0 (off) or >= 1e-6 (got 1e-20)`); field() and rule() let the CLI name its
// flag instead, without reading the message.
class ParamError : public InputError {
public:
    ParamError(const std::string& set, const std::string& field, const std::string& rule, const std::string& got = "")
        : InputError(std::string(set == "svgf" ? "SVGF parameter " : "parameter ") + field + " " + rule +
                     (got.empty() ? "" : " (got " + got + ")")),
          mSet(set), mField(field), mRule(rule), mGot(got) {}
    const std::string& set() const { return mSet; }      // "denoise", "svgf", "render" (a table), "device", "camera_path" or "scene"
    const std::string& field() const { return mField; }  // the row's name, e.g. "sigma_normal"
    const std::string& rule() const { return mRule; }    // e.g. "must be in 1..10"
    const std::string& got() const { return mGot; }      // the value as given ("" when not shown)

private:
    std::string mSet, mField, mRule, mGot;
};

// Where a field lives; its alternative is the field's kind.
using ParamRef = std::variant<int*, float*, bool*, SureMode*, std::vector<float>*, uint32_t*>;
enum class ParamKind { Int, Float, Bool, Choice, FloatList, UInt };  // ParamRef's alternatives, in order

// The values a number may take (a FloatList's elements, for a list): finite, in [lo, hi] or
// (lo, hi]; `zero` also allows 0 and says what it means ("off", "automatic").
struct ParamRange {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loOpen = false;
    const char* zero = nullptr;

    // Floats compare in float, as the filters see them (1e-6f is below the double 1e-6).
    bool allows(double v, bool isFloat) const {
        if (!std::isfinite(v)) return false;
        if (zero && v == 0) return true;
        const double l = isFloat ? double(float(lo)) : lo, h = isFloat ? double(float(hi)) : hi;
        return (loOpen ? v > l : v >= l) && v <= h;
    }
    std::string rule(bool isFloat) const;
};

constexpr ParamRange paramIn(double lo, double hi) { return {lo, hi, false, nullptr}; }    // [lo, hi], lo..hi
constexpr ParamRange paramAbove(double lo, double hi) { return {lo, hi, true, nullptr}; }  // (lo, hi]
constexpr ParamRange paramAtLeast(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, nullptr}; }
constexpr ParamRange paramZeroOr(double lo, const char* zero) {
    return {lo, std::numeric_limits<double>::infinity(), false, zero};
}

template <class S>
struct ParamField {
    const char* name;    // snake_case, unique in its table
    ParamRef (*at)(S&);  // the field in a struct
    ParamRange range;    // Int, Float and FloatList elements; unused for Bool and Choice
    const char* doc;     // one line: the CLI's help, Python's and the viewer's tooltip
    const char* group = "";         // the nested struct ("eaw", "sure", ...), "" for S's own fields
    const char* flag = nullptr;     // the CLI flag without "--" when it is not the table's rule; "" = none
    bool negated = false;           // Bool: the CLI flag (--no-<name>) clears it; Python accepts no_<name> too
    const char* const* choices = nullptr;      // Choice: the names of the enum's values, in order, null-ended
    std::string (*check)(const S&) = nullptr;  // a rule that involves other fields: "" or what is wrong
    ParamKind kind() const {
        static S probe{};
        return ParamKind(at(probe).index());
    }
};

template <class S>
struct ParamTable {
    const char* set;         // "denoise" | "svgf" | "render" (ParamError::set)
    const char* flagPrefix;  // CLI flag = "--" + flagPrefix + name with '-' for '_'
    const ParamField<S>* first;
    size_t count;
    const ParamField<S>* begin() const { return first; }
    const ParamField<S>* end() const { return first + count; }
    const ParamField<S>* find(const std::string& name) const {
        for (const auto& f : *this)
            if (name == f.name) return &f;
        return nullptr;
    }
    std::string flag(const ParamField<S>& f) const;  // "--sigma-normal", "--no-firefly", "--svgf-alpha"; "" = none
};

namespace params_detail {
template <class T>
struct ClassOf;
template <class S, class V>
struct ClassOf<V S::*> {
    using type = S;
};
template <auto M>
ParamRef at(typename ClassOf<decltype(M)>::type& s) {
    return &(s.*M);
}
template <auto Outer, auto Inner>
ParamRef at2(typename ClassOf<decltype(Outer)>::type& s) {
    return &(s.*Outer.*Inner);
}
inline constexpr const char* kSureModes[] = {"discrete", "james-stein", nullptr};
std::string checkFeedbackTap(const SvgfParams& p);
std::string checkCandidates(const DenoiseOptions& o);

using D = DenoiseOptions;
using P = SvgfParams;
using R = RenderSettings;
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
     "levels of the emission buffer's edge-avoiding filter (0 = add the emission back as is)", "eaw"},
    {"emission_scale", &at2<&D::eaw, &EawParams::emissionScale>, paramIn(1e-6, 1e6),
     "k of the emission filter's sigma^2 = k * 2 min(V_p, V_q)", "eaw"},
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
    {"reproject_depth_tolerance", &at<&P::reprojectDepthTolerance>, paramAtLeast(0), "reprojection depth test tau_z", "",
     "svgf-depth-tolerance"},
    {"reproject_normal_cos", &at<&P::reprojectNormalCos>, paramIn(-1, 1), "reprojection: minimum cosine between normals",
     "", "svgf-normal-cos"},
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

// threads: a ceiling, since tbb::task_arena aborts in its destructor from 65537 threads on
// (docs/reliability.md).
inline const ParamField<R> kRender[] = {
    {"width", &at<&R::width>, paramIn(1, kMaxImageDim), "image width in pixels"},
    {"height", &at<&R::height>, paramIn(1, kMaxImageDim), "image height in pixels"},
    {"spp", &at<&R::spp>, paramAtLeast(1), "samples per pixel"},
    {"seed", &at<&R::seed>, paramIn(0, 4294967295.0), "random seed (same seed, same image, whatever the thread count)"},
    {"first_sample", &at<&R::firstSample>, paramIn(0, 4294967295.0),
     "global index of the first sample (progressive accumulation: frame * spp)", "", ""},
    {"max_depth", &at<&R::maxDepth>, paramIn(0, 1024), "maximum bounces (0 = emitted light only, 1 = direct light)"},
    {"threads", &at<&R::threads>, paramIn(0, 4096), "worker threads (0 = all cores)"},
    {"light_sampling", &at<&R::lightSampling>, {},
     "next-event estimation with multiple importance sampling (else BSDF sampling only)", "", nullptr, true},
};
// clang-format on
}  // namespace params_detail

inline const ParamTable<DenoiseOptions>& denoiseParams() {
    static const ParamTable<DenoiseOptions> t{"denoise", "", params_detail::kDenoise, std::size(params_detail::kDenoise)};
    return t;
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
inline const ParamTable<RenderSettings>& renderParams() {
    static const ParamTable<RenderSettings> t{"render", "", params_detail::kRender, std::size(params_detail::kRender)};
    return t;
}

// ---- what the consumers share -------------------------------------------------------------------

// The name of `names` closest to `got` (an unknown parameter, flag or keyword) by edit distance
// (insertions, deletions, substitutions and swaps of neighbours, each 1; case, '-' and '_' ignored),
// when it is near enough to be a slip: at most 2 edits, and fewer than half of `got`'s length. ""
// when none is. For "did you mean ...?" after an unknown name (Python's keywords, the CLI's flags).
inline std::string closestName(const std::string& got, const std::vector<std::string>& names) {
    auto norm = [](std::string s) {
        for (char& c : s) c = c == '-' ? '_' : char(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
        return s;
    };
    const std::string a = norm(got);
    std::string best;
    size_t bestD = std::min<size_t>(3, (a.size() + 1) / 2);  // a candidate must beat this
    for (const std::string& name : names) {
        const std::string b = norm(name);
        // Optimal string alignment distance, three rows.
        std::vector<size_t> p2(b.size() + 1), p1(b.size() + 1), cur(b.size() + 1);
        for (size_t j = 0; j <= b.size(); ++j) p1[j] = j;
        for (size_t i = 1; i <= a.size(); ++i) {
            cur[0] = i;
            for (size_t j = 1; j <= b.size(); ++j) {
                cur[j] = std::min({p1[j] + 1, cur[j - 1] + 1, p1[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
                if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) cur[j] = std::min(cur[j], p2[j - 2] + 1);
            }
            p2.swap(p1);
            p1.swap(cur);
        }
        if (p1[b.size()] < bestD) bestD = p1[b.size()], best = name;
    }
    return best;
}

// " (did you mean 'NAME'?)" for closestName's answer, with `quote` around it; "" when there is none.
inline std::string didYouMean(const std::string& got, const std::vector<std::string>& names, const char* quote = "'") {
    const std::string n = closestName(got, names);
    return n.empty() ? "" : std::string(" (did you mean ") + quote + n + quote + "?)";
}

// Every name a table's rows take in Python: the row's name, and a negated switch's CLI name as a
// keyword (--no-firefly: no_firefly).
template <class S>
std::vector<std::string> paramKeywords(const ParamTable<S>& t) {
    std::vector<std::string> names;
    for (const ParamField<S>& f : t) {
        names.push_back(f.name);
        if (!f.negated || t.flag(f).size() < 3) continue;
        std::string k = t.flag(f).substr(2);
        for (char& c : k)
            if (c == '-') c = '_';
        names.push_back(k);
    }
    return names;
}

// The shortest text that reads back as the same float: 1e-6, 0.9, 1048576.
inline std::string formatParamNumber(double v) {
    if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
    char buf[40];
    if (v == std::floor(v) && std::fabs(v) < 1e5) {
        std::snprintf(buf, sizeof buf, "%.0f", v);
        return buf;
    }
    for (int prec = 1; prec <= 9; ++prec) {
        std::snprintf(buf, sizeof buf, "%.*g", prec, v);
        if (float(std::strtod(buf, nullptr)) == float(v)) break;
    }
    std::string s = buf;
    const size_t e = s.find('e');
    if (e == std::string::npos) return s;
    std::string exp = s.substr(e + 1);
    const bool neg = exp[0] == '-';
    exp.erase(0, exp.find_first_not_of("+-0"));
    return s.substr(0, e) + "e" + (neg ? "-" : "") + exp;
}

inline std::string ParamRange::rule(bool isFloat) const {
    const bool open = std::isinf(hi);
    // Integer bounds in full (4294967295, not 4.2949673e9).
    auto text = [&](double v) { return isFloat || std::isinf(v) ? formatParamNumber(v) : std::to_string((long long)v); };
    const std::string l = text(lo), h = text(hi);
    if (zero) return std::string("must be 0 (") + zero + ") or " + (open ? ">= " + l : "in [" + l + ", " + h + "]");
    if (!isFloat) return open ? "must be at least " + l : "must be in " + l + ".." + h;
    if (open) return "must be a finite number " + std::string(loOpen ? "> " : ">= ") + l;
    return "must be in " + std::string(loOpen ? "(" : "[") + l + ", " + h + "]";
}

template <class S>
std::string ParamTable<S>::flag(const ParamField<S>& f) const {
    if (f.flag) return *f.flag ? std::string("--") + f.flag : std::string();
    std::string s = std::string("--") + flagPrefix + (f.negated ? "no-" : "") + f.name;
    for (char& c : s)
        if (c == '_') c = '-';
    return s;
}

// The field's value as text (the CLI's shown default, Python's repr of a choice).
inline std::string paramText(const ParamRef& r, const char* const* choices = nullptr) {
    struct V {
        const char* const* choices;
        std::string operator()(int* p) const { return std::to_string(*p); }
        std::string operator()(uint32_t* p) const { return std::to_string(*p); }
        std::string operator()(float* p) const { return formatParamNumber(*p); }
        std::string operator()(bool* p) const { return *p ? "true" : "false"; }
        std::string operator()(SureMode* p) const { return choices ? choices[int(*p)] : std::to_string(int(*p)); }
        std::string operator()(std::vector<float>* p) const {
            std::string s;
            for (float x : *p) s += (s.empty() ? "" : ",") + formatParamNumber(x);
            return s;
        }
    };
    return std::visit(V{choices}, r);
}

// Sets a Choice from its name ('_' accepted for '-') or a FloatList from "0,0.5,1"; other kinds
// are set by their own readers (CLI11, Python). ParamError naming the field otherwise.
template <class S>
void setParamFromText(S& s, const ParamTable<S>& t, const ParamField<S>& f, const std::string& text) {
    const ParamRef r = f.at(s);
    if (SureMode* const* m = std::get_if<SureMode*>(&r)) {
        std::string want, norm = text;
        for (char& c : norm)
            if (c == '_') c = '-';
        std::vector<std::string> names;
        for (int i = 0; f.choices[i]; ++i) {
            if (norm == f.choices[i]) {
                **m = SureMode(i);
                return;
            }
            want += std::string(i ? (f.choices[i + 1] ? ", " : " or ") : "") + f.choices[i];
            names.push_back(f.choices[i]);
        }
        throw ParamError(t.set, f.name, "must be " + want, "'" + text + "'" + didYouMean(text, names));
    }
    if (std::vector<float>* const* list = std::get_if<std::vector<float>*>(&r)) {
        std::vector<float> v;
        size_t start = 0;
        while (start <= text.size()) {
            const size_t comma = std::min(text.find(',', start), text.size());
            const std::string item = text.substr(start, comma - start);
            char* end = nullptr;
            const float x = std::strtof(item.c_str(), &end);
            if (item.empty() || *end) throw ParamError(t.set, f.name, "must be a comma-separated list of numbers", "'" + item + "'");
            v.push_back(x);
            start = comma + 1;
        }
        **list = v;
        return;
    }
    throw ParamError(t.set, f.name, "is not set from text");
}

// ParamError for the first field out of its range (the table's order), else nothing.
template <class S>
void validateParams(const S& s, const ParamTable<S>& t) {
    S& m = const_cast<S&>(s);  // read only: ParamRef has no const alternatives
    for (const auto& f : t) {
        const ParamRef r = f.at(m);
        if (const int* const* i = std::get_if<int*>(&r); i && !f.range.allows(**i, false))
            throw ParamError(t.set, f.name, f.range.rule(false), std::to_string(**i));
        if (const uint32_t* const* u = std::get_if<uint32_t*>(&r); u && !f.range.allows(**u, false))
            throw ParamError(t.set, f.name, f.range.rule(false), std::to_string(**u));
        if (const float* const* x = std::get_if<float*>(&r); x && !f.range.allows(**x, true))
            throw ParamError(t.set, f.name, f.range.rule(true), formatParamNumber(**x));
        if (f.check)
            if (std::string why = f.check(s); !why.empty()) throw ParamError(t.set, f.name, why);
        if (const std::vector<float>* const* l = std::get_if<std::vector<float>*>(&r))
            for (float x : **l)
                if (!f.range.allows(x, true)) throw ParamError(t.set, f.name, f.range.rule(true), formatParamNumber(x));
    }
}

// Every field of the table equal (floats compared as floats: NaN differs from everything).
template <class S>
bool sameParams(const S& a, const S& b, const ParamTable<S>& t) {
    S& x = const_cast<S&>(a);
    S& y = const_cast<S&>(b);
    for (const auto& f : t) {
        const bool same = std::visit([&](auto* p) { return *p == *std::get<decltype(p)>(f.at(y)); }, f.at(x));
        if (!same) return false;
    }
    return true;
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

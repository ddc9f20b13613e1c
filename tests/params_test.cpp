// The parameter tables (include/atrous/params.h): every field of every params struct has a row;
// each row's CLI flag sets exactly its field; out-of-range values are refused naming the field
// (library) or the flag (CLI); equality sees every field; the docs' tables list every row with its
// flag and the struct's default. Python's keywords are checked in tests/python/test_params.py.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../apps/atrous/cli_flags.h"
#include "atrous/params.h"
#include "atrous/render.h"

using namespace atrous;

namespace {

// ---- how many fields a struct has (aggregate initialisation with N "anything"s) ---------------

struct AnyField {
    template <class T>
    operator T() const;  // never called: unevaluated only
};
template <class T, class... A>
constexpr auto braces(int) -> decltype(T{A{}...}, true) {
    return true;
}
template <class T, class... A>
constexpr bool braces(...) {
    return false;
}
template <class T, class... A>
constexpr size_t fieldCount() {
    if constexpr (braces<T, A...>(0))
        return fieldCount<T, A..., AnyField>();
    else
        return sizeof...(A) - 1;
}

template <class S>
size_t rowsOf(const ParamTable<S>& t, const std::string& group) {
    size_t n = 0;
    for (const auto& f : t) n += group == f.group;
    return n;
}

TEST(ParamTables, EveryStructFieldHasARow) {
    const auto& d = denoiseParams();
    // EawParams' rows: the EAW stops' group and the emission filter's (the preparation reads it).
    EXPECT_EQ(rowsOf(d, "eaw") + rowsOf(d, "emission"), fieldCount<EawParams>());
    EXPECT_EQ(rowsOf(d, "emission"), 2u);
    EXPECT_EQ(rowsOf(d, "sure"), fieldCount<SureParams>());
    EXPECT_EQ(rowsOf(d, "firefly"), fieldCount<FireflyParams>());
    EXPECT_EQ(rowsOf(d, "safety"), fieldCount<SafetyNetParams>());
    // DenoiseOptions' own rows; method, device, the four structs, weights and refineWeights (the
    // loaded networks: --learned-weights and learned_weights= name the learned filter's file) are
    // not parameters.
    EXPECT_EQ(rowsOf(d, "") + 8, fieldCount<DenoiseOptions>());
    EXPECT_EQ(d.count, rowsOf(d, "eaw") + rowsOf(d, "emission") + rowsOf(d, "sure") + rowsOf(d, "firefly") +
                           rowsOf(d, "safety") + rowsOf(d, ""));
    EXPECT_EQ(svgfParams().count, fieldCount<SvgfParams>());
    EXPECT_EQ(temporalParams().count, fieldCount<TemporalParams>());
    EXPECT_EQ(renderParams().count + 1, fieldCount<RenderSettings>());  // samplesDone is no parameter
}

template <class S>
void expectDistinctRows(const ParamTable<S>& t) {
    S s{};
    for (const auto& a : t) {
        EXPECT_FALSE(std::string(a.doc).empty()) << a.name;
        for (const auto& b : t) {
            if (&a == &b) continue;
            EXPECT_NE(std::string(a.name), b.name);
            EXPECT_NE(t.flag(a), t.flag(b));
            EXPECT_NE(a.at(s), b.at(s)) << a.name << " and " << b.name << " are the same field";
        }
    }
}

TEST(ParamTables, RowsAreDistinctFields) {
    expectDistinctRows(denoiseParams());
    expectDistinctRows(svgfParams());
    expectDistinctRows(temporalParams());
    expectDistinctRows(renderParams());
}

// ---- values to try per row -------------------------------------------------------------------

// A valid value other than the default, as CLI text, for a number row.
template <class S>
std::string otherValidText(const ParamField<S>& f, const S& defaults) {
    S s = defaults;
    const ParamRef r = f.at(s);
    if (int* const* i = std::get_if<int*>(&r)) {
        for (int v : {**i + 1, **i - 1, int(f.range.lo)})
            if (v != **i && f.range.allows(v, false)) {
                **i = v;
                if (!f.check || f.check(s).empty()) return std::to_string(v);
                **i = *std::get<int*>(f.at(const_cast<S&>(defaults)));
            }
    }
    if (uint32_t* const* u = std::get_if<uint32_t*>(&r)) return std::to_string(**u + 1);
    if (float* const* x = std::get_if<float*>(&r))
        for (double v : {double(**x) * 2, double(**x) * 0.5, 0.75, 0.5, f.range.lo, f.range.hi})
            if (float(v) != **x && f.range.allows(v, true)) return formatParamNumber(v);
    ADD_FAILURE() << f.name << ": no other valid value found";
    return "";
}

// A value outside the row's range, or "" when every value of its type is allowed.
template <class S>
std::string outOfRangeText(const ParamField<S>& f) {
    if (f.kind() == ParamKind::UInt) return "";  // 0..2^32-1: CLI11 refuses the rest itself
    const bool isFloat = f.kind() != ParamKind::Int;
    for (double v : {f.range.lo - 1, f.range.hi + 1, f.range.lo * 0.5, -1.0, 1e30})
        if (std::isfinite(v) && !f.range.allows(v, isFloat))
            return isFloat ? formatParamNumber(v) : std::to_string(long(v));
    return isFloat ? "nan" : "";
}

template <class S>
void setFromNumber(S& s, const ParamField<S>& f, const std::string& v) {
    const ParamRef r = f.at(s);
    if (int* const* i = std::get_if<int*>(&r)) **i = std::stoi(v);
    if (uint32_t* const* u = std::get_if<uint32_t*>(&r)) **u = uint32_t(std::stoul(v));
    if (float* const* x = std::get_if<float*>(&r)) **x = std::stof(v);
}

template <class S>
void parse(CLI::App& app, const std::vector<std::string>& args) {
    std::vector<std::string> argv = {"atrous"};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<const char*> p;
    for (const auto& a : argv) p.push_back(a.c_str());
    app.parse(int(p.size()), p.data());
}

// Each row's flag, given alone, sets its field to the value and leaves every other field at the
// struct's default; equality sees the change and only it.
template <class S>
void cliRoundTrip(const ParamTable<S>& t) {
    const S defaults{};
    for (const ParamField<S>& f : t) {
        if (t.flag(f).empty()) continue;  // no CLI flag (RenderSettings::firstSample)
        S got{};
        CLI::App app;
        cli::addParamOptions(app, got, t, [](const ParamField<S>&) { return "params"; });
        S want{};
        const ParamRef w = f.at(want);
        std::vector<std::string> args = {t.flag(f)};
        if (bool* const* b = std::get_if<bool*>(&w)) {
            ASSERT_EQ(**b, f.negated) << f.name << ": a switch's flag must change the default";
            **b = !**b;
        } else if (SureMode* const* m = std::get_if<SureMode*>(&w)) {
            **m = **m == SureMode::Discrete ? SureMode::JamesStein : SureMode::Discrete;
            args.push_back(paramText(w, f.choices));
        } else if (std::vector<float>* const* l = std::get_if<std::vector<float>*>(&w)) {
            **l = {0.0f, 0.5f};
            args.push_back("0,0.5");
        } else {
            const std::string v = otherValidText(f, defaults);
            args.push_back(v);
            setFromNumber(want, f, v);
        }
        parse<S>(app, args);
        EXPECT_TRUE(sameParams(got, want, t)) << t.flag(f) << " " << (args.size() > 1 ? args[1] : "");
        EXPECT_FALSE(sameParams(got, defaults, t)) << f.name << ": equality does not see it";
        EXPECT_NO_THROW(validateParams(got, t)) << f.name;
        for (const ParamField<S>& g : t)  // every other field unchanged
            if (&g != &f) {
                S other = got;
                std::visit([&](auto* p) { *p = *std::get<decltype(p)>(g.at(const_cast<S&>(defaults))); }, g.at(other));
                EXPECT_TRUE(sameParams(other, got, t)) << t.flag(f) << " changed " << g.name;
            }
    }
}

TEST(ParamTables, EveryRowHasACliFlagThatSetsItsField) {
    cliRoundTrip(denoiseParams());
    cliRoundTrip(svgfParams());
    cliRoundTrip(temporalParams());
    cliRoundTrip(renderParams());
}

TEST(ParamTables, NegatedSwitchesKeepTheirFlags) {
    std::vector<std::string> negated;
    for (const auto& f : denoiseParams())
        if (f.negated) negated.push_back(denoiseParams().flag(f));
    EXPECT_EQ(negated, (std::vector<std::string>{"--no-ids", "--no-correlated-variance", "--no-firefly", "--no-firefly-restore", "--no-demodulate"}));
    EXPECT_EQ(svgfParams().flag(*svgfParams().find("depth_tolerance")), "--svgf-depth-tolerance");
    EXPECT_EQ(svgfParams().flag(*svgfParams().find("taa_alpha")), "--taa-alpha");
    EXPECT_EQ(denoiseParams().flag(*denoiseParams().find("sure_window")), "--sure-window");
}

// Out of range: the library's error names the field (ParamError::field, and in the message);
// the CLI's names the flag and what was typed.
template <class S>
void outOfRange(const ParamTable<S>& t, void (*validate)(const S&), int minTried = 10) {
    int tried = 0;
    for (const ParamField<S>& f : t) {
        const ParamKind k = f.kind();
        if (k == ParamKind::Bool || k == ParamKind::Choice) continue;
        const std::string bad = k == ParamKind::FloatList ? "0,2" : outOfRangeText(f);
        if (bad.empty()) continue;
        ++tried;
        S s{};
        CLI::App app;
        cli::addParamOptions(app, s, t, [](const ParamField<S>&) { return "params"; });
        parse<S>(app, {t.flag(f), bad});
        try {
            validate(s);
            ADD_FAILURE() << f.name << " = " << bad << " was accepted";
        } catch (const ParamError& e) {
            EXPECT_EQ(e.field(), f.name);
            EXPECT_EQ(e.set(), t.set);
            EXPECT_NE(std::string(e.what()).find(std::string(f.name) + " must"), std::string::npos) << e.what();
            EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
        }
        try {
            cli::checkParamFlags(s, t, app);
            ADD_FAILURE() << f.name;
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(t.flag(f) + ": must", 0), 0u) << e.what();
            EXPECT_NE(std::string(e.what()).find("(got " + bad + ")"), std::string::npos) << e.what();
        }
    }
    EXPECT_GE(tried, minTried);
}

TEST(ParamTables, OutOfRangeValuesNameTheFieldOrTheFlag) {
    outOfRange(denoiseParams(), &validateDenoiseOptions);
    outOfRange(svgfParams(), &validateSvgfParams);
    outOfRange(temporalParams(), &validateTemporalParams, 6);  // every row
    outOfRange(renderParams(), &validateRenderSettings, 5);  // width, height, spp, max_depth, threads
}

// Library errors outside a command's own tables (the render settings, the device) reach main.cpp
// as ParamError; cli::flagMessage names the flag from the field, never from the message.
TEST(ParamTables, LibraryErrorsMapToFlagsByField) {
    RenderSettings s;
    s.maxDepth = -1;
    try {
        validateRenderSettings(s);
        ADD_FAILURE();
    } catch (const ParamError& e) {
        EXPECT_EQ(e.set(), "render");
        EXPECT_EQ(e.field(), "max_depth");
        EXPECT_STREQ(e.what(), "parameter max_depth must be in 0..1024 (got -1)");
        EXPECT_EQ(cli::flagMessage(e), "--max-depth: must be in 0..1024 (got -1)");
    }
    s = RenderSettings{};
    s.spp = 0;
    try {
        validateRenderSettings(s);
        ADD_FAILURE();
    } catch (const ParamError& e) {
        EXPECT_EQ(cli::flagMessage(e), "--spp: must be at least 1 (got 0)");
    }
    try {
        (void)parseDevice("gpu");
        ADD_FAILURE();
    } catch (const ParamError& e) {
        EXPECT_EQ(e.set(), "device");
        EXPECT_EQ(e.field(), "device");
        EXPECT_EQ(cli::flagMessage(e), "--device: must be cpu, cuda or auto (got 'gpu')");
    }
    if (!cudaAvailable()) {
        try {
            (void)parseDevice("cuda");
            ADD_FAILURE();
        } catch (const ParamError& e) {
            EXPECT_EQ(e.field(), "device");
            EXPECT_EQ(cli::flagMessage(e).rfind("--device: cannot be cuda: ", 0), 0u) << cli::flagMessage(e);
        }
    }
    // A field without a flag keeps the library's message.
    const ParamError noFlag("render", "first_sample", "must be in 0..1");
    EXPECT_STREQ(cli::flagMessage(noFlag).c_str(), noFlag.what());
}

TEST(ParamTables, CrossFieldRulesAndTextValues) {
    SvgfParams p;
    p.levels = 2;
    p.feedbackTap = 2;
    try {
        validateSvgfParams(p);
        ADD_FAILURE();
    } catch (const ParamError& e) {
        EXPECT_EQ(e.field(), "feedback_tap");
        EXPECT_NE(std::string(e.what()).find("got 2 with levels 2"), std::string::npos) << e.what();
    }
    DenoiseOptions o;
    const auto& t = denoiseParams();
    setParamFromText(o, t, *t.find("sure_mode"), "james_stein");
    EXPECT_EQ(o.sure.mode, SureMode::JamesStein);
    EXPECT_THROW(setParamFromText(o, t, *t.find("sure_mode"), "stein"), ParamError);
    EXPECT_THROW(setParamFromText(o, t, *t.find("sure_candidates"), "0,,1"), ParamError);
    o.sure.candidates.clear();
    EXPECT_THROW(validateDenoiseOptions(o), ParamError);
    EXPECT_EQ(formatParamNumber(1e-6), "1e-6");
    EXPECT_EQ(formatParamNumber(1 << 20), "1048576");
    EXPECT_EQ(formatParamNumber(1e6), "1e6");
    EXPECT_EQ(formatParamNumber(0.9f), "0.9");
}

// ---- the docs' tables: one row per field, with its flag and the struct's default --------------

template <class S>
void docsList(const ParamTable<S>& t, const std::string& doc) {
    std::ifstream in(std::string(ATROUS_SOURCE_DIR) + "/docs/" + doc);
    ASSERT_TRUE(in) << doc;
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    S s{};
    for (const auto& f : t) {
        const std::string row =
            "| `" + std::string(f.name) + "` | `" + t.flag(f) + "` | " + paramText(f.at(s), f.choices) + " |";
        EXPECT_NE(text.find(row), std::string::npos) << doc << " lacks the row starting " << row;
    }
}

TEST(ParamTables, DocsListEveryRow) {
    docsList(denoiseParams(), "denoising.md");
    docsList(svgfParams(), "svgf.md");
    docsList(temporalParams(), "temporal.md");
}

}  // namespace

// The library's InputErrors name the value ("unknown denoise method 'x'") or the parameter
// (ParamError: the field "sigma_normal", "max_depth", "device"), since Python shares them; the CLI
// puts the flag in front so the user knows which one to fix: withFlag for a value it parsed, the
// parameter tables (params.h) for a field. No message is read to find its flag.
#pragma once
#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "atrous/device.h"
#include "atrous/error.h"
#include "atrous/param_set.h"
#include "atrous/params.h"
#include "atrous/sequence_methods.h"
#include "atrous/render.h"

namespace atrous::cli {

// "flag: message".
[[noreturn]] inline void rethrowWithFlag(const std::string& flag, const InputError& e) {
    throw InputError(flag + ": " + e.what());
}

template <class F>
auto withFlag(const std::string& flag, F&& f) -> decltype(f()) {
    try {
        return f();
    } catch (const InputError& e) {
        rethrowWithFlag(flag, e);
    }
}

// --threads N of denoise, render and bench: TBB's global_control for the command's run (every
// parallel loop of the library, the filters', the readers' and the renderer's); 0 = all cores
// (none made). The ceiling is the render table's (tbb::task_arena aborts from 65537 threads).
inline std::unique_ptr<tbb::global_control> limitThreads(int threads) {
    if (threads < 0 || threads > 4096)
        throw InputError("--threads: must be 0 (all cores) to 4096 (got " + std::to_string(threads) + ")");
    if (threads == 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

// CLI11 reads an empty value ("--max-depth ''") as 0 without a word (found by tests/fuzz).
inline const CLI::Validator kNonEmptyNumber(
    [](std::string& v) { return v.empty() ? std::string("an empty value is not a number") : std::string(); }, "",
    "non-empty");

// What the user typed for `flag` on `cmd`, or "" when it was not given.
inline std::string givenValue(const CLI::App& cmd, const std::string& flag) {
    const CLI::Option* opt = cmd.get_option_no_throw(flag);
    if (!opt || opt->count() == 0) return "";
    std::string v;
    for (const auto& r : opt->results()) v += (v.empty() ? "" : " ") + r;
    return v;
}

// A ParamError as the user typed it: "--svgf-alpha: must be in (0, 1] (got 2)". The set's table
// maps the error's field to its flag (params.h); the message is not read.
[[noreturn]] inline void rethrowAsFlag(const ParamError& e, const ParamSet& set, const CLI::App& cmd) {
    const int row = set.find(e.field());
    if (row < 0 || set.rows()[size_t(row)].flag.empty()) throw e;
    const std::string flag = set.rows()[size_t(row)].flag, got = givenValue(cmd, flag);
    throw InputError(flag + ": " + e.rule() + (got.empty() ? "" : " (got " + got + ")"));
}

// The flag of a library ParamError's field: the denoise, render and sequence methods' tables'
// rows (sequenceMethods()' params); --device, --camera-path and --scene for parseDevice's,
// parseCameraPath's and Scene::builtin's; "" when the field has none (RenderSettings::firstSample).
inline std::string flagOf(const ParamError& e) {
    auto in = [&](const auto& t) -> std::string {
        const auto* f = t.find(e.field());
        return f ? t.flag(*f) : std::string();
    };
    if (e.set() == "device") return "--device";
    if (e.set() == "camera_path") return "--camera-path";
    if (e.set() == "scene") return "--scene";
    if (e.set() == "render") return in(renderParams());
    if (e.set() == "denoise") return in(denoiseParams());
    for (const SequenceMethodInfo& m : sequenceMethods()) {
        if (m.params.empty() || e.set() != m.params.set()) continue;
        const int row = m.params.find(e.field());
        return row < 0 ? std::string() : m.params.rows()[size_t(row)].flag;
    }
    return "";
}

// "--max-depth: must be in 0..1024 (got -1)" (the library's message when the field has no flag).
inline std::string flagMessage(const ParamError& e) {
    const std::string flag = flagOf(e);
    if (flag.empty()) return e.what();
    return flag + ": " + e.rule() + (e.got().empty() ? "" : " (got " + e.got() + ")");
}

// validateParams with the flags' names in the message.
inline void checkParamFlags(const ParamSet& set, const CLI::App& cmd) {
    try {
        set.validate();
    } catch (const ParamError& e) {
        rethrowAsFlag(e, set, cmd);
    }
}
template <class S>
void checkParamFlags(const S& s, const ParamTable<S>& t, const CLI::App& cmd) {
    checkParamFlags(ParamSet::bind(t, const_cast<S&>(s)), cmd);  // read only
}

// One flag per row of the set whose group(row) is not null (rows without a flag left out), in the
// help group group(row), writing into the set's values: a bound set's (ParamSet::bind, view()),
// which must outlive the parse. The defaults shown are the values it holds now. A negated Bool is
// a --no-<name> switch, a Choice or FloatList takes its text (ParamSet::setText). Ranges are
// checked after the parse (checkParamFlags), when every flag is known.
inline void addParamOptions(CLI::App& cmd, ParamSet values, const std::function<const char*(const ParamRow&)>& group) {
    const auto set = std::make_shared<ParamSet>(std::move(values));
    for (size_t i = 0; i < set->rows().size(); ++i) {
        const ParamRow& f = set->rows()[i];
        const char* g = group(f);
        if (f.flag.empty() || !g) continue;
        const std::string flag = f.flag;
        const ParamRef r = set->at(i);
        CLI::Option* opt = nullptr;
        if (bool* const* b = std::get_if<bool*>(&r)) {
            bool* p = *b;
            opt = f.negated ? cmd.add_flag_callback(flag, [p] { *p = false; }, std::string("turn off: ") + f.doc)
                            : cmd.add_flag(flag, *p, f.doc);
        } else if (int* const* n = std::get_if<int*>(&r)) {
            opt = cmd.add_option(flag, **n, f.doc)->check(kNonEmptyNumber)->capture_default_str();
        } else if (uint32_t* const* u = std::get_if<uint32_t*>(&r)) {
            opt = cmd.add_option(flag, **u, f.doc)->check(kNonEmptyNumber)->capture_default_str();
        } else if (float* const* x = std::get_if<float*>(&r)) {
            opt = cmd.add_option(flag, **x, f.doc)->check(kNonEmptyNumber)->capture_default_str();
        } else {
            opt = cmd.add_option_function<std::string>(
                       flag,
                       [set, i, flag](const std::string& v) {
                           try {
                               set->setText(i, v);
                           } catch (const ParamError& e) {
                               std::vector<std::string> choices;  // a choice's names, for "did you mean"
                               const char* const* names = set->rows()[i].choices;
                               for (int k = 0; names && names[k]; ++k) choices.push_back(names[k]);
                               throw InputError(flag + ": " + e.rule() + " (got " + v + ")" + didYouMean(v, choices));
                           }
                       },
                       f.doc)
                      ->default_str(paramText(r, f.choices));
        }
        opt->group(g);
    }
}

// The same for a struct and its table, with group(field) (and the rows `keep` refuses left out).
template <class S, class GroupOf>
void addParamOptions(CLI::App& cmd, S& s, const ParamTable<S>& t, GroupOf&& group,
                     bool (*keep)(const ParamField<S>&) = nullptr) {
    std::string title;  // group(f) may return a std::string: held until the row's option is made
    addParamOptions(cmd, ParamSet::bind(t, s), [&](const ParamRow& row) -> const char* {
        const ParamField<S>& f = *t.find(row.name);
        if (keep && !keep(f)) return nullptr;
        title = group(f);
        return title.c_str();
    });
}

}  // namespace atrous::cli

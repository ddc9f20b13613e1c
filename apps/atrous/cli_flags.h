// The library's InputErrors name the value ("unknown device 'gpu'") or the parameter (ParamError:
// the field "sigma_normal"), since Python shares them; the CLI puts the flag in front so the user
// knows which one to fix: withFlag for a value it parsed, the parameter tables (params.h) for a
// field. Library messages that already start with a flag ("--device cuda: ...") stay as they are.
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "atrous/device.h"
#include "atrous/error.h"
#include "atrous/params.h"

namespace atrous::cli {

// "flag: message", unless the message already names a flag.
[[noreturn]] inline void rethrowWithFlag(const std::string& flag, const InputError& e) {
    const std::string msg = e.what();
    if (msg.rfind("--", 0) == 0) throw e;
    throw InputError(flag + ": " + msg);
}

template <class F>
auto withFlag(const std::string& flag, F&& f) -> decltype(f()) {
    try {
        return f();
    } catch (const InputError& e) {
        rethrowWithFlag(flag, e);
    }
}

inline Device parseDeviceFlag(const std::string& name) {
    return withFlag("--device", [&] { return parseDevice(name); });
}

// What the user typed for `flag` on `cmd`, or "" when it was not given.
inline std::string givenValue(const CLI::App& cmd, const std::string& flag) {
    const CLI::Option* opt = cmd.get_option_no_throw(flag);
    if (!opt || opt->count() == 0) return "";
    std::string v;
    for (const auto& r : opt->results()) v += (v.empty() ? "" : " ") + r;
    return v;
}

// A ParamError as the user typed it: "--svgf-alpha: must be in (0, 1] (got 2)". The table maps
// the error's field to its flag (params.h); the message is not read.
template <class S>
[[noreturn]] void rethrowAsFlag(const ParamError& e, const ParamTable<S>& t, const CLI::App& cmd) {
    const ParamField<S>* f = t.find(e.field());
    if (!f) throw e;
    const std::string flag = t.flag(*f), got = givenValue(cmd, flag);
    throw InputError(flag + ": " + e.rule() + (got.empty() ? "" : " (got " + got + ")"));
}

// validateParams with the flags' names in the message.
template <class S>
void checkParamFlags(const S& s, const ParamTable<S>& t, const CLI::App& cmd) {
    try {
        validateParams(s, t);
    } catch (const ParamError& e) {
        rethrowAsFlag(e, t, cmd);
    }
}

// One flag per row of the table, writing into `s` (which must outlive the parse), in the help
// group group(field); the defaults shown are the struct's. A negated Bool is a --no-<name> switch,
// a Choice or FloatList takes its text (setParamFromText). Ranges are checked after the parse
// (checkParamFlags), when every flag is known.
template <class S, class GroupOf>
void addParamOptions(CLI::App& cmd, S& s, const ParamTable<S>& t, GroupOf&& group) {
    for (const ParamField<S>& f : t) {
        const std::string flag = t.flag(f);
        const ParamRef r = f.at(s);
        CLI::Option* opt = nullptr;
        if (bool* const* b = std::get_if<bool*>(&r)) {
            bool* p = *b;
            opt = f.negated ? cmd.add_flag_callback(flag, [p] { *p = false; }, std::string("turn off: ") + f.doc)
                            : cmd.add_flag(flag, *p, f.doc);
        } else if (int* const* i = std::get_if<int*>(&r)) {
            opt = cmd.add_option(flag, **i, f.doc)->capture_default_str();
        } else if (float* const* x = std::get_if<float*>(&r)) {
            opt = cmd.add_option(flag, **x, f.doc)->capture_default_str();
        } else {
            const ParamField<S>* field = &f;
            const ParamTable<S>* table = &t;
            S* target = &s;
            opt = cmd.add_option_function<std::string>(
                       flag,
                       [field, table, target, flag](const std::string& v) {
                           try {
                               setParamFromText(*target, *table, *field, v);
                           } catch (const ParamError& e) {
                               throw InputError(flag + ": " + e.rule() + " (got " + v + ")");
                           }
                       },
                       f.doc)
                      ->default_str(paramText(r, f.choices));
        }
        opt->group(group(f));
    }
}

}  // namespace atrous::cli

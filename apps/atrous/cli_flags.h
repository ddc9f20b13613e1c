// The library's InputErrors name the value ("unknown device 'gpu'") or the parameter ("levels must
// be in 1..10"), since Python shares them; the CLI puts the flag in front so the user knows which
// one to fix. Library messages that already start with a flag ("--device cuda: ...") stay as they are.
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "atrous/device.h"
#include "atrous/error.h"

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

// Rewrites "<prefix><name> <rule>" into "--<flag>: <rule> (got <value>)", mapping the library's
// parameter name to its flag with flagOf(name) ("" = unknown: the message stays as it is).
template <class FlagOf>
[[noreturn]] void rethrowParameterError(const InputError& e, const std::string& prefix, const CLI::App& cmd,
                                        FlagOf&& flagOf) {
    const std::string msg = e.what();
    if (msg.rfind(prefix, 0) == 0) {
        const std::string rest = msg.substr(prefix.size());
        const size_t space = rest.find(' ');
        const std::string flag = flagOf(rest.substr(0, space));
        if (!flag.empty() && space != std::string::npos) {
            const std::string got = givenValue(cmd, flag);
            throw InputError(flag + ": " + rest.substr(space + 1) + (got.empty() ? "" : " (got " + got + ")"));
        }
    }
    throw e;
}

}  // namespace atrous::cli

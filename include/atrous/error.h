// Errors at the boundary (docs/architecture.md, principle 5). Library code throws; the CLI turns an
// exception into one line on stderr and exit code 2, Python into ValueError / RuntimeError.
#pragma once
#include <stdexcept>
#include <string>

namespace atrous {

// Bad input from the user: a file that cannot be read, a buffer of the wrong size, a parameter
// out of range. The message names the file or flag and the problem. CLI exit code 2, Python
// ValueError.
class InputError : public std::invalid_argument {
public:
    explicit InputError(const std::string& what) : std::invalid_argument(what) {}
};

// Something that went wrong outside the user's control (out of memory, a CUDA failure, a disk that
// filled up while writing). CLI exit code 2 as well (nothing was written), Python RuntimeError.
class RuntimeError : public std::runtime_error {
public:
    explicit RuntimeError(const std::string& what) : std::runtime_error(what) {}
};

// A parameter out of range (or a value that does not parse): an InputError whose what() names the
// field (`parameter sigma_normal must be 0 (off) or >= 1e-6 (got 1e-20)`); field() and rule() let
// the CLI name its flag instead (the parameter tables, atrous/params.h), without reading the message.
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

}  // namespace atrous

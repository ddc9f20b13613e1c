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

}  // namespace atrous

// What the weight-file readers share (learned_weights.cpp, refine_weights.cpp): the checksum, a
// little-endian u32, and reading a whole file with one clear line for each way it can fail.
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "atrous/error.h"

namespace atrous::filters {

inline std::uint32_t weightFnv1a(const std::uint8_t* p, size_t n) {
    std::uint32_t h = 0x811C9DC5u;
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x01000193u;
    return h;
}

inline std::uint32_t weightU32(const std::uint8_t* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

// The bytes of the weight file at `path` (`what` names the kind of file in the messages). Only
// regular files (a FIFO or /dev/zero would be read for ever), of at most 1 MiB (the parsers check
// the exact size). InputError naming the path otherwise.
inline std::vector<std::uint8_t> readWeightFile(const std::string& path, const std::string& what) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::exists(path, ec)) throw InputError(path + ": cannot open the " + what + " (not found)");
    if (fs::is_directory(path, ec)) throw InputError(path + ": is a directory, not a " + what);
    if (!fs::is_regular_file(path, ec)) throw InputError(path + ": not a regular file (a " + what + ")");
    const uintmax_t size = fs::file_size(path, ec);
    constexpr uintmax_t kMaxBytes = 1u << 20;
    if (ec || size > kMaxBytes)
        throw InputError(path + ": over-long " + what + " (" + std::to_string(size) + " bytes; a weight file is under 1 MiB)");
    std::ifstream f(path, std::ios::binary);
    if (!f) throw InputError(path + ": cannot open the " + what);
    std::vector<std::uint8_t> bytes(static_cast<size_t>(size));
    f.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size));
    if (size_t(f.gcount()) != bytes.size()) throw InputError(path + ": cannot read the " + what);
    return bytes;
}

}  // namespace atrous::filters

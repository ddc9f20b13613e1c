#include "atrous/io/paths.h"

#include <filesystem>

#include "atrous/error.h"

namespace fs = std::filesystem;

namespace atrous::io {

namespace {

fs::path normal(const std::string& p) {
    std::error_code ec;
    fs::path abs = fs::weakly_canonical(fs::absolute(p, ec), ec);
    if (ec) abs = fs::absolute(p, ec).lexically_normal();
    // "out/" and "out" are the same directory.
    if (abs.filename().empty() && abs.has_parent_path()) abs = abs.parent_path();
    return abs;
}

}  // namespace

bool samePath(const std::string& a, const std::string& b) {
    if (a.empty() || b.empty()) return false;
    std::error_code ec;
    if (fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec)) return true;
    return normal(a) == normal(b);
}

bool insidePath(const std::string& path, const std::string& dir) {
    if (path.empty() || dir.empty()) return false;
    const fs::path d = normal(dir);
    for (fs::path p = normal(path); !p.empty(); p = p.parent_path()) {
        if (p == d) return true;
        if (p == p.parent_path()) break;
    }
    return samePath(path, dir);
}

void refuseOverwrite(const std::string& flag, const std::string& out, const std::vector<std::string>& inputs) {
    for (const std::string& in : inputs)
        if (samePath(out, in))
            throw InputError(flag + " '" + out + "': is the input " + in + " (outputs never overwrite inputs: write elsewhere)");
}

void refuseOutputInside(const std::string& flag, const std::string& outDir, const std::string& inputDir) {
    if (insidePath(outDir, inputDir))
        throw InputError(flag + " '" + outDir + "': is " + (samePath(outDir, inputDir) ? "" : "inside ") + "the input directory " +
                         inputDir + " (outputs never overwrite inputs: write elsewhere)");
}

}  // namespace atrous::io

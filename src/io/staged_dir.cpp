#include "atrous/io/staged_dir.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <sstream>

#include "atrous/error.h"
#include "atrous/io/sequence.h"

namespace fs = std::filesystem;

namespace atrous::io {

StagedDir::StagedDir(const std::string& flag, const std::string& outDir) {
    mOut = fs::path(outDir).lexically_normal();
    if (mOut.filename().empty()) mOut = mOut.parent_path();  // "out/" -> "out"
    std::error_code ec;
    if (fs::exists(mOut, ec) && !fs::is_directory(mOut, ec))
        throw InputError(flag + " '" + outDir + "': exists and is not a directory");
    if (fs::is_directory(mOut, ec) && ::access(mOut.c_str(), W_OK | X_OK) != 0)
        throw InputError(flag + " '" + outDir + "': output directory is not writable");
    const fs::path parent = mOut.has_parent_path() ? mOut.parent_path() : fs::path(".");
    // Parents created here are removed again on failure (nothing is left behind).
    for (fs::path p = parent; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) mCreatedParent = p;
    // One name per process and call: runs of one process (Python threads) never share a stage.
    static std::atomic<unsigned> calls{0};
    mStage = parent / ("." + mOut.filename().string() + ".partial-" + std::to_string(::getpid()) + "-" +
                       std::to_string(calls.fetch_add(1)));
    fs::remove_all(mStage, ec);  // a leftover of a killed run with the same pid and count
    if (!fs::create_directories(mStage, ec) || ec)
        throw InputError(flag + " '" + outDir + "': cannot create the output directory (" +
                         (ec ? ec.message() : std::string("it could not be made")) + ")");
}

StagedDir::~StagedDir() {
    if (mCommitted) return;
    std::error_code ec;
    fs::remove_all(mStage, ec);
    if (!mCreatedParent.empty()) fs::remove_all(mCreatedParent, ec);
}

std::string StagedDir::commit() {
    std::error_code ec;
    bool emptyOut = !fs::exists(mOut, ec) || fs::is_empty(mOut, ec);
    if (emptyOut) {
        fs::rename(mStage, mOut, ec);
        if (!ec) {
            mCommitted = true;
            return "";
        }
        fs::create_directories(mOut, ec);  // the rename failed: move file by file instead
    }
    std::vector<std::string> written;
    for (auto it = fs::directory_iterator(mStage, ec); !ec && it != fs::directory_iterator(); it.increment(ec))
        written.push_back(it->path().filename().string());
    if (ec) throw RuntimeError(mStage.string() + ": cannot list the staged output (" + ec.message() + ")");
    for (const auto& name : written) {
        fs::rename(mStage / name, mOut / name, ec);
        if (ec) throw RuntimeError((mOut / name).string() + ": cannot move the result into place (" + ec.message() + ")");
    }
    mCommitted = true;
    fs::remove_all(mStage, ec);
    auto wrote = [&](const std::string& name) { return std::find(written.begin(), written.end(), name) != written.end(); };
    std::vector<std::string> removed;
    for (const char* ext : {".exr", ".png"}) {
        auto r = removeSequenceEntries(mOut.string(), ext, [&](int index) { return wrote(sequenceFrameName(index) + ext); });
        removed.insert(removed.end(), r.begin(), r.end());
    }
    if (!wrote("preview.mp4") && fs::is_regular_file(mOut / "preview.mp4", ec)) {
        fs::remove(mOut / "preview.mp4", ec);
        if (!ec) removed.push_back("preview.mp4");
    }
    if (removed.empty()) return "";
    std::sort(removed.begin(), removed.end());
    std::string list = removed.front();
    if (removed.size() > 1) list += (removed.size() > 2 ? ", ..., " : ", ") + removed.back();
    return "removed " + std::to_string(removed.size()) + " file" + (removed.size() == 1 ? "" : "s") +
           " of an earlier run from " + mOut.string() + " (" + list + ")";
}

std::string shellQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += (c == '\'') ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::string findOnPath(const std::string& name) {
    const char* path = std::getenv("PATH");
    if (!path) return "";
    std::stringstream ss(path);
    std::string dir;
    while (std::getline(ss, dir, ':')) {
        if (dir.empty()) continue;
        fs::path candidate = fs::path(dir) / name;
        std::error_code ec;
        if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
    return "";
}

}  // namespace atrous::io

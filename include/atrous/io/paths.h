// Outputs never overwrite inputs (docs/inputs.md, "Outputs"): every command checks, before anything
// runs, that no file it writes (or replaces, or removes as an earlier run's) is a file it reads,
// and that an output directory is neither an input directory nor inside one.
#pragma once
#include <string>
#include <vector>

namespace atrous::io {

// True when a and b name the same file or directory: the same path once made absolute and
// normal (symbolic links resolved where they exist), or the same existing file by identity.
bool samePath(const std::string& a, const std::string& b);
// True when `path` is `dir` or lies inside it (by the same rules).
bool insidePath(const std::string& path, const std::string& dir);

// InputError "<flag> '<out>': is the input <input> (...)" when `out` is one of `inputs`.
void refuseOverwrite(const std::string& flag, const std::string& out, const std::vector<std::string>& inputs);
// InputError when the output directory `outDir` is `inputDir` or inside it.
void refuseOutputInside(const std::string& flag, const std::string& outDir, const std::string& inputDir);

}  // namespace atrous::io

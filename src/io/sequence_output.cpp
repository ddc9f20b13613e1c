#include "atrous/io/sequence_output.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/io/sequence.h"

namespace fs = std::filesystem;

namespace atrous::io {

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

// A name that reads as an image file (out.exr, clean.png): refused as a sequence's --out.
bool imageExtension(const std::string& ext) {
    for (const char* e : {".exr", ".png", ".pfm", ".jpg", ".jpeg", ".tif", ".tiff", ".hdr"})
        if (ext == e) return true;
    return false;
}

// The number's place in `name`: one run of '#', or one %d / %0Nd. Sets from/to/width; returns ""
// or what is wrong.
std::string findNumber(const std::string& name, size_t& from, size_t& to, int& width) {
    const size_t hash = name.find('#'), pct = name.find('%');
    if (hash != std::string::npos && pct != std::string::npos) return "has both #'s and a %d: give one of them";
    if (hash != std::string::npos) {
        from = to = hash;
        while (to < name.size() && name[to] == '#') ++to;
        if (name.find('#', to) != std::string::npos) return "has two groups of #'s: give one (#### for 0001)";
        width = int(to - from);
        return "";
    }
    from = pct;
    to = from + 1;
    width = 0;
    if (to < name.size() && name[to] == '0') {
        ++to;
        while (to < name.size() && std::isdigit(static_cast<unsigned char>(name[to]))) width = width * 10 + (name[to++] - '0');
    }
    if (to >= name.size() || name[to] != 'd' || width > 9) return "has a % that is not %d or %0Nd (%04d for 0001)";
    ++to;
    if (name.find('%', to) != std::string::npos) return "has two %d's: give one";
    return "";
}

}  // namespace

// Declared in io/sequence.h (the frame files of an earlier run that StagedDir::commit removes).
std::vector<std::string> removeSequenceEntries(const std::string& dir, const std::string& suffix,
                                               const std::function<bool(int)>& keep) {
    std::vector<fs::path> doomed;
    std::error_code ec;
    for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) continue;
        std::error_code ec2;
        // Directories for frame_NNNN, regular files for frame_NNNN.exr: never anything else.
        if (suffix.empty() ? !it->is_directory(ec2) : !it->is_regular_file(ec2)) continue;
        const int index = parseSequenceFrameName(name.substr(0, name.size() - suffix.size()));
        if (index >= 0 && !keep(index)) doomed.push_back(it->path());
    }
    if (ec) throw RuntimeError(dir + ": cannot list the directory (" + ec.message() + ")");
    std::sort(doomed.begin(), doomed.end());
    std::vector<std::string> removed;
    for (const auto& p : doomed) {
        fs::remove_all(p, ec);
        if (ec) throw RuntimeError(p.string() + ": cannot remove a stale entry of an earlier run (" + ec.message() + ")");
        removed.push_back(p.filename().string());
    }
    return removed;
}

std::string sequenceInputStem(const std::string& frame) {
    const fs::path p(frame);
    std::error_code ec;
    if (!fs::is_directory(p, ec) && lower(p.extension().string()) == ".exr") return p.stem().string();
    return p.filename().empty() ? p.parent_path().filename().string() : p.filename().string();
}

std::string SequenceOutputNames::stem(const std::string& frame, int index) const {
    if (!pattern) return sequenceInputStem(frame);
    std::string n = std::to_string(index);
    if (int(n.size()) < width) n.insert(0, size_t(width) - n.size(), '0');
    return prefix + n + suffix.substr(0, suffix.size() - 4);  // without ".exr"
}

SequenceOutputNames parseSequenceOutput(const std::string& flag, const std::string& out) {
    if (out.empty()) throw InputError(flag + ": no output folder or pattern given");
    SequenceOutputNames n;
    const fs::path path(out);
    const std::string name = path.filename().string();
    const std::string ext = lower(path.extension().string());
    std::error_code ec;
    const bool numbered = name.find('#') != std::string::npos || name.find('%') != std::string::npos;
    if (!numbered) {
        if (imageExtension(ext) && !fs::is_directory(path, ec))
            throw InputError(flag + " '" + out + "': a sequence's output is a folder (the frames keep their names) or "
                             "a pattern with #'s for the frame number (clean/render####.exr): this names one file");
        n.dir = out;
        return n;
    }
    size_t from = 0, to = 0;
    const std::string problem = findNumber(name, from, to, n.width);
    if (!problem.empty()) throw InputError(flag + " '" + out + "': the pattern " + problem);
    n.pattern = true;
    n.prefix = name.substr(0, from);
    n.suffix = name.substr(to);
    const std::string tail = lower(n.suffix);
    if (tail.size() < 4 || tail.compare(tail.size() - 4, 4, ".exr") != 0)
        throw InputError(flag + " '" + out + "': the pattern must end in .exr (the frames are written as EXR, with "
                         ".png previews beside them)");
    n.suffix = n.suffix.substr(0, n.suffix.size() - 4) + ".exr";
    n.dir = path.has_parent_path() ? path.parent_path().string() : ".";
    return n;
}

}  // namespace atrous::io

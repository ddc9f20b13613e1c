#include "atrous/io/sequence.h"

#include <ImfHeader.h>
#include <ImfInputFile.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <utility>

#include "atrous/error.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/exr_layers.h"
#include "io/exr_limits.h"
#include "atrous/io/image_io.h"

namespace fs = std::filesystem;

namespace atrous::io {

const char* const kSequenceBuffers[10] = {"color", "albedo",   "normal",   "position", "depth",
                                          "ids",   "motion",   "emission", "variance", "reference"};

namespace {

// The io::Buffer each frame-directory file is read as (reference: as a colour).
const Buffer kFileBuffer[10] = {Buffer::Color,  Buffer::Albedo, Buffer::Normal,   Buffer::Position, Buffer::Depth,
                                Buffer::ObjectId, Buffer::Motion, Buffer::Emission, Buffer::Variance, Buffer::Color};

bool allDigits(const std::string& s) {
    return std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
}

// "<stem><sep><digits>.exr" with a known stem: the stem's buffer, and <sep><digits>.exr in *tail
// (sep one of "_", ".", "-"; one to eight digits). "" when the name is not one.
std::string perBufferName(const std::string& name, std::string* tail) {
    for (const char* buffer : kSequenceBuffers)
        for (const std::string& file : dirBufferNames(buffer)) {
            const std::string stem = file.substr(0, file.size() - 4);  // without ".exr"
            if (name.size() < stem.size() + 6 || name.compare(0, stem.size(), stem) != 0) continue;
            const char sep = name[stem.size()];
            if (sep != '_' && sep != '.' && sep != '-') continue;
            const std::string rest = name.substr(stem.size() + 1);
            if (rest.size() < 5 || rest.size() > 12 || rest.compare(rest.size() - 4, 4, ".exr") != 0) continue;
            if (!allDigits(rest.substr(0, rest.size() - 4))) continue;
            if (tail) *tail = name.substr(stem.size());
            return buffer;
        }
    return "";
}

// A frame of per-buffer numbered files is named by its colour file (color_0001.exr, RGB_0001.exr).
bool perBufferFrame(const std::string& frame, std::string* tail = nullptr) {
    return perBufferName(fs::path(frame).filename().string(), tail) == "color";
}

// The frame number of a per-buffer file's tail ("_0012.exr" -> 12).
int perBufferIndex(const std::string& tail) { return std::stoi(tail.substr(1, tail.size() - 5)); }

bool isLayeredFrame(const std::string& path) { return fs::path(path).extension() == ".exr" && !perBufferFrame(path); }

// The file of `buffer` in a frame folder (dirBufferFile) or beside a per-buffer frame's colour
// file (the same <sep><digits>.exr after one of the buffer's stems); "" when there is none.
std::string frameBufferFile(const std::string& frame, const std::string& buffer) {
    std::string tail;
    if (!perBufferFrame(frame, &tail)) return dirBufferFile(frame, buffer);
    const fs::path dir = fs::path(frame).parent_path();
    for (const std::string& file : dirBufferNames(buffer)) {
        const fs::path p = dir / (file.substr(0, file.size() - 4) + tail);
        std::error_code ec;
        if (fs::exists(p, ec)) return p.string();
    }
    return "";
}

// The path `buffer`'s file would have in `frame`, named as `like` (another frame's file of it).
std::string expectedFile(const std::string& frame, const std::string& like) {
    std::string tail, likeTail;
    if (!perBufferFrame(frame, &tail)) return (fs::path(frame) / fs::path(like).filename()).string();
    const std::string name = fs::path(like).filename().string();
    std::string stem = fs::path(name).stem().string();  // albedo.exr -> albedo
    if (!perBufferName(name, &likeTail).empty()) stem = name.substr(0, name.size() - likeTail.size());
    return (fs::path(frame).parent_path() / (stem + tail)).string();
}

// A layered frame's companion file (<stem>_motion.exr), or "" when there is none.
std::string companion(const std::string& frame, const char* what) {
    const fs::path p(frame);
    const fs::path c = p.parent_path() / (p.stem().string() + "_" + what + ".exr");
    std::error_code ec;
    return fs::is_regular_file(c, ec) ? c.string() : std::string();
}

std::string sizeText(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// `index` zero-padded to `width` digits (a missing frame named as its neighbours are: render0007).
std::string padded(int index, size_t width) {
    std::string n = std::to_string(index);
    return std::string(width > n.size() ? width - n.size() : 0, '0') + n;
}

// The image size from the EXR header alone, after the size rule of exr_limits.h.
void exrSize(const std::string& path, int& w, int& h) {
    try {
        requireExrHeadersFit(path);
        Imf::InputFile file(path.c_str());
        requireExrFits(path, {&file.header()}, {""});
        const ExrWindow win = exrImageWindow(path, file.header());
        w = win.width;
        h = win.height;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot read the EXR header (" + e.what() + ")");
    }
}

// The buffers (names of kSequenceBuffers) a layered frame gives: its passes as mapPasses finds
// them, and motion from its companion too.
std::vector<std::string> layeredBuffers(const std::string& frame, const ExrInfo& info, const SequenceOptions& o) {
    const PassMap m = mapPasses(info, o.passes, o.viewLayer);
    if (!m[Buffer::Color].found())
        throw InputError(frame + ": no colour pass (layers: " + layerList(info) + "); name one with --pass color=LAYER");
    std::vector<std::string> here;
    for (int i = 0; i < 9; ++i) {
        const Buffer b = kFileBuffer[i];
        bool found = m[b].found();
        if (b == Buffer::ObjectId) found = found || m[Buffer::MaterialId].found();
        if (b == Buffer::Motion) found = found || !companion(frame, "motion").empty();
        if (found) here.push_back(kSequenceBuffers[i]);
    }
    return here;
}

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s.empty() ? "none" : s;
}

}  // namespace

int parseSequenceFrameName(const std::string& name) {
    const std::string prefix = "frame_";
    if (name.size() < prefix.size() + 4 || name.compare(0, prefix.size(), prefix) != 0) return -1;
    std::string digits = name.substr(prefix.size());
    if (digits.size() > 8) return -1;
    for (char c : digits)
        if (!std::isdigit(static_cast<unsigned char>(c))) return -1;
    return std::stoi(digits);
}

bool isLayeredSequenceFrame(const std::string& frame) { return isLayeredFrame(frame); }

std::string sequenceFrameName(int index) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "frame_%04d", index);
    return buf;
}

int parseFolderFrameName(const std::string& name, std::string* prefix) {
    size_t i = name.size();
    while (i > 0 && std::isdigit(static_cast<unsigned char>(name[i - 1]))) --i;
    if (i == name.size() || name.size() - i > 8) return -1;
    if (prefix) *prefix = name.substr(0, i);
    return std::stoi(name.substr(i));
}

int parseLayeredFrameName(const std::string& fileName, std::string* prefix) {
    const fs::path p(fileName);
    if (p.extension() != ".exr") return -1;
    const std::string stem = p.stem().string();
    for (const char* suffix : {"_motion", "_reference"})
        if (stem.size() >= std::strlen(suffix) && stem.compare(stem.size() - std::strlen(suffix), std::string::npos, suffix) == 0)
            return -1;
    return parseFolderFrameName(stem, prefix);  // the same rule: the number last, one to eight digits
}

namespace {

// A frame pattern: DIR/<prefix><#### | %0Nd | %d><suffix> (the number's digits: at least N,
// zero-padded; any count for %d).
struct FramePattern {
    std::string dir, prefix, suffix;
    int width = 0;
};

bool parseFramePattern(const std::string& arg, FramePattern* p) {
    const fs::path path(arg);
    const std::string name = path.filename().string();
    size_t from = name.find('#'), to = from;
    if (from != std::string::npos) {
        while (to < name.size() && name[to] == '#') ++to;
        if (name.find('#', to) != std::string::npos || name.find('%') != std::string::npos) return false;
        p->width = int(to - from);
    } else {
        from = name.find('%');
        if (from == std::string::npos) return false;
        to = from + 1;
        int w = 0;
        if (to < name.size() && name[to] == '0')
            while (++to < name.size() && std::isdigit(static_cast<unsigned char>(name[to]))) w = w * 10 + (name[to] - '0');
        if (to >= name.size() || name[to] != 'd' || w > 8 || name.find('%', to) != std::string::npos) return false;
        ++to;
        p->width = w;
    }
    p->prefix = name.substr(0, from);
    p->suffix = name.substr(to);
    p->dir = path.has_parent_path() ? path.parent_path().string() : ".";
    return true;
}

// The frame number a file name gives under the pattern, or -1.
int matchFramePattern(const FramePattern& p, const std::string& name) {
    if (name.size() <= p.prefix.size() + p.suffix.size() || name.compare(0, p.prefix.size(), p.prefix) != 0 ||
        name.compare(name.size() - p.suffix.size(), p.suffix.size(), p.suffix) != 0)
        return -1;
    const std::string digits = name.substr(p.prefix.size(), name.size() - p.prefix.size() - p.suffix.size());
    if (digits.empty() || digits.size() > 8 || int(digits.size()) < p.width || !allDigits(digits)) return -1;
    if (int(digits.size()) > std::max(p.width, 1) && digits[0] == '0') return -1;  // padded wider than the pattern
    return std::stoi(digits);
}

std::string framePatternName(const FramePattern& p, int index) {
    std::string n = std::to_string(index);
    if (int(n.size()) < p.width) n.insert(0, size_t(p.width) - n.size(), '0');
    return p.prefix + n + p.suffix;
}

}  // namespace

bool isSequencePattern(const std::string& dirOrPattern) {
    std::error_code ec;
    FramePattern p;
    return !fs::is_directory(dirOrPattern, ec) && parseFramePattern(dirOrPattern, &p);
}

std::string sequenceFolder(const std::string& dirOrPattern) {
    FramePattern p;
    return isSequencePattern(dirOrPattern) && parseFramePattern(dirOrPattern, &p) ? p.dir : dirOrPattern;
}

namespace {

using NumberedPaths = std::vector<std::pair<int, std::string>>;

// A sequence's frames by number, and how a frame is named in messages (a missing one).
struct FrameListing {
    NumberedPaths frames;
    std::function<std::string(int)> label;
};

// A pattern as compositors write it: render####.exr, render%04d.exr.
FrameListing listPatternFrames(const std::string& dir, const FramePattern& pat) {
    std::error_code ec;
    if (!fs::is_directory(pat.dir, ec)) throw InputError("sequence " + dir + ": " + pat.dir + " is not a directory");
    FrameListing l;
    for (auto it = fs::directory_iterator(pat.dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        std::error_code ec2;
        const int n = matchFramePattern(pat, it->path().filename().string());
        if (n >= 0 && !it->is_regular_file(ec2))
            throw InputError("sequence " + dir + ": " + it->path().string() + " matches the pattern but is not a regular file");
        if (n >= 0) l.frames.emplace_back(n, it->path().string());
    }
    if (ec) throw InputError("sequence " + dir + ": cannot list " + pat.dir + " (" + ec.message() + ")");
    if (l.frames.empty()) throw InputError("sequence " + dir + ": no file in " + pat.dir + " matches the pattern");
    l.label = [pat](int index) { return framePatternName(pat, index) + " (the pattern's file)"; };
    return l;
}

// What a sequence directory holds, by layout: frame_NNNN directories, another renderer's numbered
// frame folders, numbered files per buffer, numbered (layered) EXR files; with the first name of
// each (for messages) and the prefix the numbered ones share.
struct DirectoryLayouts {
    NumberedPaths frameDirs, folders, perBuffer, files;
    std::string prefix, firstFile, folderPrefix, firstFolder, firstPerBuffer;

    // An entry named as a frame (render0002.exr, frame_0002, color_0002.exr) that is not what a
    // frame is (a directory named like a file, a file named like a frame folder, a socket, a
    // broken link): refused, so that a sequence is never cut short without a word.
    static void refuseOddEntry(const std::string& dir, const fs::path& path, bool isDir) {
        const std::string name = path.filename().string();
        const bool fileName = parseLayeredFrameName(name) >= 0 || !perBufferName(name, nullptr).empty();
        const bool folderName = parseSequenceFrameName(name) >= 0;
        if (isDir ? fileName : (fileName || folderName))
            throw InputError("sequence " + dir + ": " + path.string() + " is named as a frame but is " +
                             (isDir ? "a directory" : "not a regular file") + " (remove or rename it)");
    }

    void addDirectory(const std::string& dir, const fs::path& path) {
        const std::string name = path.filename().string();
        const int index = parseSequenceFrameName(name);
        if (index >= 0) {
            frameDirs.emplace_back(index, path.string());
            return;
        }
        // Another renderer's numbered frame folders (LuxCore's 0001/, frame0001/ ...): one prefix,
        // the number last, a colour file inside (dirBufferFile's names).
        std::string pre;
        const int n = parseFolderFrameName(name, &pre);
        if (n < 0 || dirBufferFile(path.string(), "color").empty()) return;
        if (!folders.empty() && pre != folderPrefix)
            throw InputError("sequence " + dir + ": numbered frame folders with two prefixes ('" + firstFolder + "' and '" +
                             name + "'): keep one sequence per directory");
        folderPrefix = pre;
        if (firstFolder.empty()) firstFolder = name;
        folders.emplace_back(n, path.string());
    }

    void addFile(const std::string& dir, const fs::path& path) {
        const std::string name = path.filename().string();
        // Per-buffer numbered files (color_0001.exr, albedo_0001.exr, ...): a frame per colour file;
        // the other buffers' files are found beside it.
        std::string tail;
        const std::string buffer = perBufferName(name, &tail);
        if (buffer == "color") {
            perBuffer.emplace_back(perBufferIndex(tail), path.string());
            if (firstPerBuffer.empty()) firstPerBuffer = name;
            return;
        }
        if (!buffer.empty()) return;
        std::string pre;
        const int index = parseLayeredFrameName(name, &pre);
        if (index < 0) return;
        if (!files.empty() && pre != prefix)
            throw InputError("sequence " + dir + ": numbered EXR files with two prefixes ('" + firstFile + "' and '" + name +
                             "'): keep one sequence per directory");
        prefix = pre;
        if (firstFile.empty()) firstFile = name;
        files.emplace_back(index, path.string());
    }

    // The one layout the directory holds (two are an error), its frames and their names.
    FrameListing choose(const std::string& dir) const {
        FrameListing l;
        l.frames = frameDirs;
        if (!frameDirs.empty() && !files.empty())
            throw InputError("sequence " + dir + ": holds both frame_NNNN directories and numbered EXR files (" + firstFile +
                             "): keep one layout per directory");
        if (!perBuffer.empty() && (!frameDirs.empty() || !files.empty()))
            throw InputError("sequence " + dir + ": holds numbered files per buffer (" + firstPerBuffer + ") and " +
                             (frameDirs.empty() ? "numbered EXR files (" + firstFile + ")" : std::string("frame_NNNN directories")) +
                             ": keep one layout per directory");
        const bool byBuffer = !perBuffer.empty();
        if (byBuffer) l.frames = perBuffer;
        const bool byFolder = l.frames.empty() && !folders.empty();
        if (byFolder && !files.empty())
            throw InputError("sequence " + dir + ": holds both numbered frame folders (" + firstFolder +
                             ") and numbered EXR files (" + firstFile + "): keep one layout per directory");
        if (byFolder) l.frames = folders;
        const bool layered = l.frames.empty();
        if (layered) l.frames = files;
        if (l.frames.empty())
            throw InputError("sequence " + dir + ": no frame_NNNN directories, numbered frame folders with a colour file "
                             "(color.exr or RGB.exr), numbered files per buffer (color_0001.exr ...) or numbered EXR files");
        // A missing frame is named as the file or folder expected, its number padded as the first's.
        std::string tail;
        if (byBuffer) perBufferName(firstPerBuffer, &tail);  // "_0001.exr"
        const size_t width = layered ? fs::path(firstFile).stem().string().size() - prefix.size()
                                     : byFolder ? firstFolder.size() - folderPrefix.size() : tail.size() ? tail.size() - 5 : 4;
        const std::string head = byBuffer ? firstPerBuffer.substr(0, firstPerBuffer.size() - tail.size() + 1) : "";
        const std::string ext = layered ? fs::path(firstFile).extension().string() : ".exr";
        l.label = [layered, byFolder, byBuffer, width, head, ext, prefix = prefix, folderPrefix = folderPrefix](int index) {
            if (layered) return prefix + padded(index, width) + ext;
            if (byFolder) return folderPrefix + padded(index, width) + " (a numbered frame folder)";
            if (byBuffer) return head + padded(index, width) + ext;
            return sequenceFrameName(index);
        };
        return l;
    }
};

FrameListing listDirectoryFrames(const std::string& dir) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw InputError("sequence " + dir + ": not a directory");
    DirectoryLayouts layouts;
    for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        std::error_code ec2;
        if (it->is_directory(ec2)) {
            DirectoryLayouts::refuseOddEntry(dir, it->path(), true);
            layouts.addDirectory(dir, it->path());
        } else if (it->is_regular_file(ec2)) {
            layouts.addFile(dir, it->path());
        } else {
            DirectoryLayouts::refuseOddEntry(dir, it->path(), false);
        }
    }
    if (ec) throw InputError("sequence " + dir + ": cannot list the directory (" + ec.message() + ")");
    return layouts.choose(dir);
}

// The frames in order, each number once; then --start, --end, --step: the frames from start to
// end, every step-th, none missing.
std::vector<std::string> keepFrameRange(const std::string& dir, FrameListing l, const FrameRange& range) {
    NumberedPaths& frames = l.frames;
    std::sort(frames.begin(), frames.end());
    for (size_t i = 1; i < frames.size(); ++i)
        if (frames[i].first == frames[i - 1].first)
            throw InputError("sequence " + dir + ": frame " + std::to_string(frames[i].first) + " appears twice (" +
                             frames[i - 1].second + ", " + frames[i].second + ")");
    const int first = range.start >= 0 ? range.start : frames.front().first;
    const int last = range.end >= 0 ? range.end : frames.back().first;
    NumberedPaths kept;
    for (const auto& f : frames)
        if (f.first >= first && f.first <= last && (f.first - first) % range.step == 0) kept.push_back(f);
    if (kept.empty())
        throw InputError("sequence " + dir + ": no frame from " + std::to_string(first) + " to " + std::to_string(last) +
                         " (its frames: " + std::to_string(frames.front().first) + " to " + std::to_string(frames.back().first) + ")");
    if (range.start >= 0 && kept.front().first != first)
        throw InputError("sequence " + dir + ": " + l.label(first) + " is missing (--start " + std::to_string(first) + ")");
    std::vector<std::string> out;
    for (size_t i = 0; i < kept.size(); ++i) {
        if (i > 0 && kept[i].first != kept[i - 1].first + range.step)
            throw InputError("sequence " + dir + ": " + l.label(kept[i - 1].first + range.step) + " is missing (gap between " +
                             fs::path(kept[i - 1].second).filename().string() + " and " +
                             fs::path(kept[i].second).filename().string() +
                             "; --start and --end pick a range of frames)");
        out.push_back(kept[i].second);
    }
    if (range.end >= 0 && kept.back().first + range.step <= last)
        throw InputError("sequence " + dir + ": " + l.label(kept.back().first + range.step) + " is missing (--end " +
                         std::to_string(last) + ")");
    return out;
}

}  // namespace

std::vector<std::string> listSequenceFrames(const std::string& dir, const FrameRange& range) {
    if (range.step < 1) throw InputError("--step: must be at least 1 (got " + std::to_string(range.step) + ")");
    if (range.start >= 0 && range.end >= 0 && range.end < range.start)
        throw InputError("--end " + std::to_string(range.end) + " is before --start " + std::to_string(range.start));
    FramePattern pat;
    const bool pattern = isSequencePattern(dir) && parseFramePattern(dir, &pat);
    return keepFrameRange(dir, pattern ? listPatternFrames(dir, pat) : listDirectoryFrames(dir), range);
}

std::vector<std::string> validateSequence(const std::vector<std::string>& frames, int& width, int& height,
                                         const SequenceOptions& options) {
    std::string firstFile;
    width = height = 0;
    auto checkSize = [&](const std::string& path, int w, int h) {
        if (firstFile.empty()) {
            firstFile = path;
            width = w;
            height = h;
        } else if (w != width || h != height) {
            throw InputError("sequence frames differ in size: " + path + " is " + sizeText(w, h) + " but " + firstFile +
                             " is " + sizeText(width, height));
        }
    };
    auto checkFile = [&](const std::string& path) {
        int w = 0, h = 0;
        exrSize(path, w, h);
        checkSize(path, w, h);
    };
    std::vector<std::string> present;
    for (size_t i = 0; i < frames.size(); ++i) {
        const std::string& frame = frames[i];
        const bool layered = isLayeredFrame(frame);
        std::error_code ec;
        if (!layered && (!options.passes.empty() || !options.viewLayer.empty()))
            throw InputError(std::string(options.passes.empty() ? "--layer" : "--pass") + ": picks a layer of a layered EXR, and " +
                             frame + " is a frame of plain EXRs");
        std::vector<std::string> here;
        if (layered) {
            const ExrInfo info = inspectExr(frame);
            checkSize(frame, info.width, info.height);
            const std::string motion = companion(frame, "motion");
            if (!motion.empty()) checkFile(motion);
            here = layeredBuffers(frame, info, options);
        } else {
            for (const char* name : kSequenceBuffers) {
                const std::string path = frameBufferFile(frame, name);
                if (!path.empty() && fs::is_regular_file(path, ec)) {
                    checkFile(path);
                    here.push_back(name);
                } else if (std::string(name) == "color") {
                    throw InputError((fs::path(frame) / "color.exr").string() +
                                     ": missing (every frame needs a colour: color.exr, or RGB.exr as LuxCore names it)");
                }
            }
        }
        if (i == 0) {
            present = here;
            continue;
        }
        // A buffer in every frame or in none: the message names the frame's file (or folder).
        auto missingIn = [&](const std::string& where, const std::string& name, const std::string& has) {
            if (layered)
                return InputError(where + ": has no " + name + " (its buffers: " + joined(where == frame ? here : present) +
                                  "), but " + has + " has one (a buffer must be in every frame or in none)");
            const std::string hasFile = frameBufferFile(has, name);
            return InputError(expectedFile(where, hasFile) + ": missing, but " + has + " has " +
                              fs::path(hasFile).filename().string() + " (a buffer must be in every frame or in none)");
        };
        for (const auto& name : present)
            if (std::find(here.begin(), here.end(), name) == here.end()) throw missingIn(frame, name, frames[0]);
        for (const auto& name : here)
            if (std::find(present.begin(), present.end(), name) == present.end()) throw missingIn(frames[0], name, frame);
    }
    return present;
}

std::string SequenceFrame::fileOf(const std::string& buffer) const {
    for (int i = 0; i < 10; ++i)
        if (buffer == kSequenceBuffers[i] && !files[i].empty()) return files[i];
    return dir;
}

SequenceFrame loadSequenceFrame(const std::string& frame, const std::vector<std::string>& expected,
                                const SequenceOptions& options) {
    SequenceFrame f;
    f.dir = frame;
    Image* slot[10] = {&f.color, &f.albedo, &f.normal, &f.position, &f.depth, &f.ids, &f.motion, &f.emission, &f.variance,
                       &f.reference};
    if (isLayeredFrame(frame)) {
        f.index = parseLayeredFrameName(fs::path(frame).filename().string());
        BufferFiles files;
        files.in = frame;
        files.passes = options.passes;
        files.viewLayer = options.viewLayer;
        files.file[int(Buffer::Motion)] = companion(frame, "motion");
        BufferSet set = loadBuffers(files);
        f.layered = set.layered;
        for (int i = 0; i < 9; ++i) {
            *slot[i] = std::move(set.image[int(kFileBuffer[i])]);
            if (!slot[i]->empty()) f.files[i] = kFileBuffer[i] == Buffer::Motion && !files.file[int(Buffer::Motion)].empty()
                                                    ? files.file[int(Buffer::Motion)] : frame;
        }
        for (const std::string& name : expected)
            for (int i = 0; i < 9; ++i)
                if (name == kSequenceBuffers[i] && slot[i]->empty())
                    throw InputError(frame + ": has no " + name + " (every frame of this sequence has one)");
        return f;
    }
    if (!options.passes.empty() || !options.viewLayer.empty())
        throw InputError(std::string(options.passes.empty() ? "--layer" : "--pass") + ": picks a layer of a layered EXR, and " +
                         frame + " is a frame of plain EXRs");
    const std::string folderName = fs::path(frame).filename().string();
    std::string tail;
    f.index = parseSequenceFrameName(folderName);
    if (perBufferFrame(frame, &tail)) f.index = perBufferIndex(tail);
    else if (f.index < 0) f.index = parseFolderFrameName(folderName);
    std::string firstPath;
    for (int i = 0; i < 10; ++i) {
        const std::string name = kSequenceBuffers[i];
        const std::string path = frameBufferFile(frame, name);
        std::error_code ec;
        if (path.empty() || !fs::is_regular_file(path, ec)) {
            const bool wanted = i == 0 || std::find(expected.begin(), expected.end(), name) != expected.end();
            if (wanted)
                throw InputError(expectedFile(frame, dirBufferNames(name)[0]) + ": missing (every frame of this sequence has " +
                                 name + ")");
            continue;
        }
        Image& dst = *slot[i];
        int channels = 3;
        const Buffer b = kFileBuffer[i];
        dst = readImage(path, &channels, i == 9 ? 3 : b == Buffer::ObjectId ? 2 : bufferChannels(b));
        if (i != 9) requireComponents(kFileBuffer[i], channels, path);
        conformBuffer(kFileBuffer[i], dst);
        f.files[i] = path;
        if (firstPath.empty()) {
            firstPath = path;
        } else if (dst.width() != f.color.width() || dst.height() != f.color.height()) {
            throw InputError("frame buffers differ in size: " + path + " is " + sizeText(dst.width(), dst.height()) + " but " +
                             firstPath + " is " + sizeText(f.color.width(), f.color.height()));
        }
    }
    return f;
}

}  // namespace atrous::io

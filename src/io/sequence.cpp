#include "io/sequence.h"

#include <ImfHeader.h>
#include <ImfInputFile.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "atrous/error.h"
#include "io/image_io.h"

namespace fs = std::filesystem;

namespace atrous::io {

const char* const kSequenceBuffers[7] = {"color", "albedo", "normal", "position", "depth", "ids", "motion"};

namespace {

const char* const kOptionalBuffers[3] = {"reference", "emission", "variance"};

std::string sizeText(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// Data-window size from the EXR header alone.
void exrSize(const std::string& path, int& w, int& h) {
    try {
        Imf::InputFile file(path.c_str());
        const auto& dw = file.header().dataWindow();
        w = dw.max.x - dw.min.x + 1;
        h = dw.max.y - dw.min.y + 1;
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot read the EXR header (" + e.what() + ")");
    }
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

std::string sequenceFrameName(int index) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "frame_%04d", index);
    return buf;
}

std::vector<std::string> listSequenceFrames(const std::string& dir) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw InputError("sequence " + dir + ": not a directory");
    std::vector<std::pair<int, std::string>> frames;
    for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        std::error_code ec2;
        if (!it->is_directory(ec2)) continue;
        int index = parseSequenceFrameName(it->path().filename().string());
        if (index >= 0) frames.emplace_back(index, it->path().string());
    }
    if (ec) throw InputError("sequence " + dir + ": cannot list the directory (" + ec.message() + ")");
    if (frames.empty()) throw InputError("sequence " + dir + ": no frame_NNNN directories");
    std::sort(frames.begin(), frames.end());
    std::vector<std::string> out;
    for (size_t i = 0; i < frames.size(); ++i) {
        if (i > 0 && frames[i].first == frames[i - 1].first)
            throw InputError("sequence " + dir + ": frame " + std::to_string(frames[i].first) + " appears twice (" +
                             frames[i - 1].second + ", " + frames[i].second + ")");
        if (i > 0 && frames[i].first != frames[i - 1].first + 1)
            throw InputError("sequence " + dir + ": " + sequenceFrameName(frames[i - 1].first + 1) + " is missing (gap between " +
                             fs::path(frames[i - 1].second).filename().string() + " and " +
                             fs::path(frames[i].second).filename().string() + ")");
        out.push_back(frames[i].second);
    }
    return out;
}

void validateSequence(const std::vector<std::string>& frameDirs, int& width, int& height) {
    std::string firstFile;
    width = height = 0;
    for (const auto& dir : frameDirs) {
        auto checkFile = [&](const std::string& path) {
            int w = 0, h = 0;
            exrSize(path, w, h);
            if (firstFile.empty()) {
                firstFile = path;
                width = w;
                height = h;
            } else if (w != width || h != height) {
                throw InputError("sequence frames differ in size: " + path + " is " + sizeText(w, h) + " but " + firstFile +
                                 " is " + sizeText(width, height));
            }
        };
        std::error_code ec;
        for (const char* name : kSequenceBuffers) {
            std::string path = (fs::path(dir) / (std::string(name) + ".exr")).string();
            if (!fs::is_regular_file(path, ec)) throw InputError(path + ": missing (every frame needs " + name + ".exr)");
            checkFile(path);
        }
        for (const char* name : kOptionalBuffers) {
            std::string path = (fs::path(dir) / (std::string(name) + ".exr")).string();
            if (fs::exists(path, ec)) checkFile(path);
        }
    }
}

SequenceFrame loadSequenceFrame(const std::string& frameDir) {
    SequenceFrame f;
    f.dir = frameDir;
    f.index = parseSequenceFrameName(fs::path(frameDir).filename().string());
    Image* required[7] = {&f.color, &f.albedo, &f.normal, &f.position, &f.depth, &f.ids, &f.motion};
    std::string firstPath;
    auto load = [&](const std::string& name, Image& dst) {
        std::string path = (fs::path(frameDir) / (name + ".exr")).string();
        std::error_code ec;
        if (!fs::is_regular_file(path, ec)) throw InputError(path + ": missing (every frame needs " + name + ".exr)");
        dst = readImage(path);
        if (firstPath.empty()) {
            firstPath = path;
        } else if (dst.width() != f.color.width() || dst.height() != f.color.height()) {
            throw InputError("frame buffers differ in size: " + path + " is " + sizeText(dst.width(), dst.height()) + " but " +
                             firstPath + " is " + sizeText(f.color.width(), f.color.height()));
        }
    };
    for (int i = 0; i < 7; ++i) load(kSequenceBuffers[i], *required[i]);
    Image* optional[3] = {&f.reference, &f.emission, &f.variance};
    for (int i = 0; i < 3; ++i) {
        std::error_code ec;
        if (fs::exists(fs::path(frameDir) / (std::string(kOptionalBuffers[i]) + ".exr"), ec)) load(kOptionalBuffers[i], *optional[i]);
    }
    return f;
}

}  // namespace atrous::io

// EXR files made in tests, part by part: any data window and display window, parts written without
// their pixels (a header that lies), and the CLI run with its peak memory measured (wait4).
#pragma once
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"

namespace atrous::test {

struct ExrPart {
    std::string name;                   // the part's name ("" only for a single-part file)
    Imath::Box2i dataWindow, displayWindow;  // the first part's display window is every part's
    std::vector<std::string> channels;  // full channel names ("ViewLayer.Combined.R" or "R")
    // The value of channel c at file pixel (x, y); when empty, no pixels are written (the
    // header claims a data window its file does not hold).
    std::function<float(int x, int y, int c)> value;
    Imf::Compression compression = Imf::ZIP_COMPRESSION;
};

inline Imath::Box2i box(int x0, int y0, int x1, int y1) { return Imath::Box2i(Imath::V2i(x0, y0), Imath::V2i(x1, y1)); }

// A part of w x h at the origin named `name` with components `comps` ("R,G,B" -> name.R, ...).
inline ExrPart simplePart(const std::string& name, int w, int h, const std::vector<std::string>& comps,
                          std::function<float(int, int, int)> value) {
    ExrPart p;
    p.name = name;
    p.dataWindow = p.displayWindow = box(0, 0, w - 1, h - 1);
    for (const auto& c : comps) p.channels.push_back(name.empty() ? c : name + "." + c);
    p.value = std::move(value);
    return p;
}

inline void writeExrParts(const std::string& path, const std::vector<ExrPart>& parts) {
    std::vector<Imf::Header> headers;
    for (const ExrPart& p : parts) {
        // A multipart file's parts share the first part's display window (OpenEXR refuses others).
        Imf::Header h(parts[0].displayWindow, p.dataWindow);
        h.compression() = p.compression;
        for (const auto& c : p.channels) h.channels().insert(c, Imf::Channel(Imf::FLOAT));
        h.setType(Imf::SCANLINEIMAGE);
        if (!p.name.empty() || parts.size() > 1) h.setName(p.name.empty() ? "part" + std::to_string(headers.size()) : p.name);
        headers.push_back(h);
    }
    Imf::MultiPartOutputFile file(path.c_str(), headers.data(), int(headers.size()));
    for (size_t i = 0; i < parts.size(); ++i) {
        const ExrPart& p = parts[i];
        if (!p.value) continue;
        const Imath::Box2i dw = p.dataWindow;
        const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
        std::vector<std::vector<float>> planes(p.channels.size(), std::vector<float>(size_t(w) * size_t(h)));
        Imf::FrameBuffer fb;
        for (size_t c = 0; c < p.channels.size(); ++c) {
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) planes[c][size_t(y) * size_t(w) + size_t(x)] = p.value(x + dw.min.x, y + dw.min.y, int(c));
            char* base = reinterpret_cast<char*>(planes[c].data()) - long(dw.min.x) * 4 - long(dw.min.y) * long(w) * 4;
            fb.insert(p.channels[c], Imf::Slice(Imf::FLOAT, base, 4, size_t(w) * 4));
        }
        Imf::OutputPart out(file, int(i));
        out.setFrameBuffer(fb);
        out.writePixels(h);
    }
}

inline std::string fileBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

struct CliRun {
    int exitCode = -1;
    std::string output;  // stdout and stderr
    long peakMb = 0;     // the child's peak resident memory
};

// Runs the CLI under test with `args` (a shell command line's arguments) and measures its peak RSS.
inline CliRun runCliMeasured(const std::string& args) {
    TempDir tmp;
    const std::string log = tmp / "out.txt";
    const std::string cmd = cliPath() + " " + args + " > '" + log + "' 2>&1";
    CliRun r;
    const pid_t pid = fork();
    if (pid == 0) {
        execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    int status = 0;
    rusage ru{};
    if (pid > 0 && wait4(pid, &status, 0, &ru) == pid) {
        r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        r.peakMb = ru.ru_maxrss / 1024;
    }
    r.output = fileBytes(log);
    return r;
}

// One line (a single '\n' at the end).
inline bool oneLine(const std::string& s) { return !s.empty() && s.find('\n') == s.size() - 1; }

}  // namespace atrous::test

// libFuzzer target: the pass/layer resolver of layered EXR files (io/pass_map.h) without a file:
// io::parsePassRequest (--pass BUFFER=NAME), io::mapPasses (--in FILE.exr, with --layer) and
// io::passForFile (--albedo FILE.exr, ...) on an ExrInfo built from the input, then layerList and
// describeLayer. The input is text, one item per line, the first character saying what:
//   P<name>   a new part (no name: an unnamed part)      S<w> <h>  the current part's size
//   T<type>   the current part's type                    C/H/U<name>  a float/half/uint channel
//   L<name>   the view layer (--layer)                   R<spec>   a --pass request (BUFFER=NAME)
//   B<name>   a buffer to run passForFile for (none: every buffer)
// The ExrInfo is built the way inspectExr builds it (channels of a part in OpenEXR's sorted order,
// the part's name in front in a multipart file, layers by the full name without its last
// component); what OpenEXR would refuse (no part, an empty or repeated channel or part name, a size
// outside 1..16384) is skipped.
//
// Contract (fuzz_common.h): each call returns or throws InputError; every choice is one mapPasses
// promises (checkPassChoice); a rule's choice is a layer inside the view layer (or a root layer);
// a buffer named by --pass is chosen by --pass.
#include <algorithm>
#include <map>
#include <set>
#include <sstream>

#include "fuzz_common.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/pass_map.h"

using namespace atrous_fuzz;
using namespace atrous::io;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    targetName() = "pass_resolver";
    return 0;
}

namespace {

struct Input {
    struct Part {
        ExrPartInfo info;
        std::map<std::string, std::string> channels;  // name -> type, sorted as OpenEXR's ChannelList
    };
    std::vector<Part> parts;
    std::string viewLayer;
    std::vector<std::string> requests, buffers;
};

bool parse(const std::string& text, Input& in) {
    std::istringstream lines(text);
    std::string line;
    std::set<std::string> partNames;
    auto part = [&]() -> Input::Part& {
        if (in.parts.empty()) in.parts.emplace_back();
        return in.parts.back();
    };
    size_t channels = 0;
    while (std::getline(lines, line)) {
        if (line.empty()) continue;
        const char op = line[0];
        const std::string arg = line.substr(1);
        if ((op == 'P' || op == 'C' || op == 'H' || op == 'U') && (arg.find('\0') != std::string::npos || arg.size() > 255))
            return false;
        switch (op) {
            case 'P':
                if (!arg.empty() && !partNames.insert(arg).second) return false;
                if (in.parts.size() >= 64) return false;
                in.parts.emplace_back();
                in.parts.back().info.name = arg;
                break;
            case 'S': {
                std::istringstream wh(arg);
                long w = 0, h = 0;
                if (!(wh >> w >> h) || w <= 0 || h <= 0 || w > atrous::kMaxImageDim || h > atrous::kMaxImageDim) return false;
                part().info.width = int(w), part().info.height = int(h);
                break;
            }
            case 'T': part().info.type = arg; break;
            case 'C':
            case 'H':
            case 'U':
                if (arg.empty() || ++channels > 512) return false;
                if (!part().channels.emplace(arg, op == 'C' ? "float" : op == 'H' ? "half" : "uint").second) return false;
                break;
            case 'L': in.viewLayer = arg; break;
            case 'R': in.requests.push_back(arg); break;
            case 'B': in.buffers.push_back(arg); break;
            default: break;
        }
    }
    return !in.parts.empty();
}

// inspectExr's flattening and grouping (exr_layers.cpp).
ExrInfo build(const Input& in) {
    ExrInfo info;
    info.path = "fuzz.exr";
    const size_t parts = in.parts.size();
    for (size_t p = 0; p < parts; ++p) {
        ExrPartInfo pi = in.parts[p].info;
        if (pi.width == 0) pi.width = 64, pi.height = 32;
        if (pi.type.empty()) pi.type = "scanlineimage";
        for (const auto& [name, type] : in.parts[p].channels) {
            ExrChannelInfo ch;
            ch.part = int(p);
            ch.name = name;
            ch.type = type;
            const bool qualified = parts > 1 && !pi.name.empty() && name.rfind(pi.name + ".", 0) != 0;
            ch.fullName = qualified ? pi.name + "." + name : name;
            info.channels.push_back(ch);
        }
        info.parts.push_back(pi);
    }
    info.width = info.parts[0].width;
    info.height = info.parts[0].height;
    std::map<std::string, size_t> index;
    for (size_t i = 0; i < info.channels.size(); ++i) {
        const std::string& full = info.channels[i].fullName;
        const size_t dot = full.rfind('.');
        const std::string layer = dot == std::string::npos ? std::string() : full.substr(0, dot);
        auto it = index.find(layer);
        if (it == index.end()) {
            it = index.emplace(layer, info.layers.size()).first;
            info.layers.push_back(ExrLayer{layer, {}, {}});
        }
        info.layers[it->second].channels.push_back(int(i));
        info.layers[it->second].components.push_back(dot == std::string::npos ? full : full.substr(dot + 1));
    }
    return info;
}

bool byRequest(const PassChoice& c) { return c.rule.rfind("--pass ", 0) == 0; }

void checkViewLayer(const ExrInfo& info, Buffer b, const PassChoice& c, const std::string& viewLayer, const std::string& what) {
    if (!c.found() || byRequest(c) || c.rule == "the file's only layer") return;
    if (c.layer < 0) finding(what + " (" + bufferName(b) + "): a rule's choice without a layer");
    const ExrLayer& l = info.layers[size_t(c.layer)];
    if (!viewLayer.empty() && !l.prefix().empty() && l.prefix() != viewLayer)
        finding(what + " (" + bufferName(b) + "): layer '" + l.name + "' is outside the view layer '" + viewLayer + "'");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Input in;
    if (!parse(std::string(reinterpret_cast<const char*>(data), size), in)) return 0;
    const ExrInfo info = build(in);
    if (info.channels.empty()) return 0;  // inspectExr's callers never see a file without channels as layered
    checkExrInfo(info, "the synthesised ExrInfo");

    std::vector<PassRequest> requests;
    for (const std::string& spec : in.requests) {
        PassRequest r{Buffer::Color, ""};
        if (!returnsOrInputError("parsePassRequest", [&] { r = parsePassRequest(spec); })) continue;
        const size_t eq = spec.find('=');
        if (eq == std::string::npos || r.name != spec.substr(eq + 1) || r.name.empty())
            finding("parsePassRequest('" + spec + "') gave name '" + r.name + "'");
        requests.push_back(r);
    }
    auto requested = [&](Buffer b) {
        return std::any_of(requests.begin(), requests.end(), [&](const PassRequest& r) { return r.buffer == b; });
    };

    PassMap m;
    if (returnsOrInputError("mapPasses", [&] { m = mapPasses(info, requests, in.viewLayer); })) {
        for (int b = 0; b < kBufferCount; ++b) {
            const PassChoice& c = m.pass[size_t(b)];
            checkPassChoice(info, Buffer(b), c, "mapPasses");
            checkViewLayer(info, Buffer(b), c, in.viewLayer, "mapPasses");
            if (requested(Buffer(b)) && !byRequest(c)) finding(std::string("mapPasses: ") + bufferName(Buffer(b)) + " was requested but chosen by '" + c.rule + "'");
        }
    }

    std::vector<Buffer> buffers;
    for (const std::string& name : in.buffers) {
        Buffer b = Buffer::Color;
        if (returnsOrInputError("parseBufferName", [&] { b = parseBufferName(name); })) buffers.push_back(b);
    }
    if (in.buffers.empty())
        for (int b = 0; b < kBufferCount; ++b) buffers.push_back(Buffer(b));
    for (Buffer b : buffers) {
        PassChoice c;
        if (!returnsOrInputError("passForFile", [&] { c = passForFile(info, b, requests, in.viewLayer); })) continue;
        if (!c.found()) finding(std::string("passForFile: returned no channels for ") + bufferName(b));
        checkPassChoice(info, b, c, "passForFile");
        checkViewLayer(info, b, c, in.viewLayer, "passForFile");
        if (requested(b) && !byRequest(c)) finding(std::string("passForFile: ") + bufferName(b) + " was requested but chosen by '" + c.rule + "'");
    }
    (void)layerList(info);
    for (const ExrLayer& l : info.layers) (void)describeLayer(info, l);
    return 0;
}

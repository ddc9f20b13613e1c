// `atrous inspect FILE.exr`: the parts, layers and channels of an EXR, and which of them
// `atrous denoise --in FILE.exr` would take for each buffer (the same io::mapPasses).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "cli_flags.h"
#include "commands.h"
#include "io/exr_layers.h"
#include "io/pass_map.h"

namespace atrous::cli {

namespace {

struct InspectArgs {
    std::string file, layer;
    std::vector<std::string> passes;
};

void run(const InspectArgs& a) {
    const io::ExrInfo info = io::inspectExr(a.file);
    std::vector<io::PassRequest> requests;
    for (const std::string& p : a.passes)
        requests.push_back(withFlag("--pass", [&] { return io::parsePassRequest(p); }));
    std::printf("%s: %dx%d, %zu part%s, %zu channels\n", a.file.c_str(), info.width, info.height, info.parts.size(),
                info.parts.size() == 1 ? "" : "s", info.channels.size());
    for (size_t p = 0; p < info.parts.size(); ++p)
        std::printf("  part %zu: '%s' %s %dx%d\n", p, info.parts[p].name.c_str(), info.parts[p].type.c_str(),
                    info.parts[p].width, info.parts[p].height);
    std::printf("layers:\n");
    for (const io::ExrLayer& l : info.layers) std::printf("  %s\n", io::describeLayer(info, l).c_str());
    const io::PassMap m = io::mapPasses(info, requests, a.layer);
    std::printf("atrous denoise --in %s takes:\n", a.file.c_str());
    for (int b = 0; b < io::kBufferCount; ++b) {
        const io::PassChoice& c = m.pass[size_t(b)];
        std::string what = "-";
        if (c.found()) {
            what.clear();
            for (int ch : c.channels) what += (what.empty() ? "" : ",") + info.channels[size_t(ch)].fullName;
            what += "  (" + c.rule + ")";
        }
        std::printf("  %-12s %s\n", io::bufferName(io::Buffer(b)), what.c_str());
    }
    if (!m.pass[size_t(io::Buffer::Color)].found())
        std::printf("no colour pass: name one with --pass color=LAYER\n");
}

}  // namespace

void addInspectCommand(CLI::App& app) {
    auto a = std::make_shared<InspectArgs>();
    auto* cmd = app.add_subcommand("inspect", "List the parts, layers and channels of an EXR and the passes atrous denoise takes");
    cmd->add_option("file", a->file, "EXR file")->required();
    cmd->add_option("--pass", a->passes, "BUFFER=NAME, as for atrous denoise (repeatable)");
    cmd->add_option("--layer", a->layer, "View layer, as for atrous denoise");
    cmd->callback([a] { run(*a); });
}

}  // namespace atrous::cli

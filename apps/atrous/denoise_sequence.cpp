#include "denoise_sequence.h"

#include <cstdio>

#include "cli_flags.h"

namespace atrous::cli {

std::string sequenceGroup(const SequenceMethodInfo& m, bool sequenceDefault) {
    const bool first = sequenceDefault && &m == &sequenceMethods().front();
    return std::string(m.label) + " (--method " + m.name + (first ? ", the default with --sequence" : "") + ")";
}

void addSequenceOptions(CLI::App& cmd, std::deque<ParamSet>& params, bool (*keep)(const SequenceMethodInfo&),
                        bool sequenceDefault) {
    params.clear();
    for (const SequenceMethodInfo& m : sequenceMethods()) {
        params.push_back(m.params);
        if (keep && !keep(m)) continue;
        const std::string group = sequenceGroup(m, sequenceDefault);
        addParamOptions(cmd, params.back().view(), [&](const ParamRow&) { return group.c_str(); });
    }
}

int runSequenceDenoise(const SequenceDenoiseArgs& args) {
    SequenceEvents events;
    events.note = [](const std::string& line) {
        std::printf("%s\n", line.c_str());
        std::fflush(stdout);
    };
    events.warning = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
    if (!args.quiet)
        events.frame = [](const SequenceFrameReport& f) {
            std::printf("%s\n", f.line.c_str());
            std::fflush(stdout);
        };
    const SequenceReport r = denoiseSequence(args.sequenceDir, args.outDir, args.options, events);
    if (!args.quiet) {
        std::printf("sequence: %zu frames, filter %.1f ms per frame, %.1f ms per frame in all (reading and writing "
                    "overlapped with filtering)\n",
                    r.frames.size(), r.filterMsPerFrame, r.wallMsPerFrame);
        if (!r.preview.empty()) std::printf("animated preview: %s\n", r.preview.c_str());
    }
    return 0;
}

}  // namespace atrous::cli

#include "denoise_sequence.h"

#include <cstdio>

#include "cli_flags.h"
#include "progress.h"

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
    // The frame lines and the summary are results (stdout); notes, warnings and the k/N counter
    // are the log (stderr); --quiet silences all of them (progress.h).
    FrameCounter counter("denoise", !quiet());
    SequenceEvents events;
    events.note = [&](const std::string& line) { counter.above([&] { logLine("%s\n", line.c_str()); }); };
    events.warning = events.note;
    events.frame = [&](const SequenceFrameReport& f) {
        counter.above([&] { resultLine("%s\n", f.line.c_str()); });
        counter.frameDone(f.position, f.count);
    };
    const SequenceReport r = denoiseSequence(args.sequenceDir, args.outDir, args.options, events);
    counter.finish();
    resultLine("sequence: %zu frames, filter %.1f ms per frame, %.1f ms per frame in all (reading and writing overlapped "
           "with filtering)\n",
           r.frames.size(), r.filterMsPerFrame, r.wallMsPerFrame);
    if (!r.preview.empty()) resultLine("animated preview: %s\n", r.preview.c_str());
    return 0;
}

}  // namespace atrous::cli

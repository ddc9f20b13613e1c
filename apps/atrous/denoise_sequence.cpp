#include "denoise_sequence.h"

#include <cstdio>

#include "cli_flags.h"

namespace atrous::cli {

void addSvgfOptions(CLI::App& cmd, SvgfParams& p) {
    addParamOptions(cmd, p, svgfParams(), [](const ParamField<SvgfParams>&) { return "SVGF (--method svgf)"; });
}

void addTemporalOptions(CLI::App& cmd, TemporalParams& p) {
    addParamOptions(cmd, p, temporalParams(), [](const ParamField<TemporalParams>&) {
        return "Temporal (--method temporal, the default with --sequence)";
    });
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

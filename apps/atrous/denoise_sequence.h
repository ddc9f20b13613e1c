// `atrous denoise --sequence DIR --out OUTDIR [--method a sequence or still method]`: the CLI's
// side of the library's sequence session (include/atrous/sequence.h): it prints one line per frame
// and a summary (stdout), the session's notes and a k/N counter with an ETA (stderr; progress.h).
#pragma once
#include <CLI/CLI.hpp>

#include <deque>
#include <string>

#include "atrous/param_set.h"
#include "atrous/sequence.h"
#include "atrous/sequence_methods.h"

namespace atrous::cli {

struct SequenceDenoiseArgs {
    std::string sequenceDir;        // --sequence: a folder or a frame pattern
    std::string outDir;             // --out
    SequenceDenoiseOptions options;  // everything else
};

// Runs the session and prints as it goes. Throws InputError for bad input (the CLI turns it into
// exit code 2). Returns 0.
int runSequenceDenoise(const SequenceDenoiseArgs& args);

// The help group of a sequence method's flags: "SVGF (--method svgf)"; with sequenceDefault, the
// first row's says it is the default with --sequence.
std::string sequenceGroup(const SequenceMethodInfo& method, bool sequenceDefault);
// One set per row of sequenceMethods() (its defaults), in the registry's order, into `params`, and
// for each row that `keep` takes (all when null) one flag per row of its table in its help group:
// --svgf-<name> (--svgf-sigma-l, ...; --svgf-depth-tolerance, --svgf-normal-cos, --taa and
// --taa-alpha keep their spellings), --temporal-<name>, a plugin's. The defaults shown are the
// row's. Ranges are checked later (checkParamFlags, or the method's factory: a ParamError naming
// the field).
void addSequenceOptions(CLI::App& cmd, std::deque<ParamSet>& params, bool (*keep)(const SequenceMethodInfo&) = nullptr,
                        bool sequenceDefault = true);

}  // namespace atrous::cli

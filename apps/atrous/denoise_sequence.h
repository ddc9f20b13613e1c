// `atrous denoise --sequence DIR --out OUTDIR [--method temporal|svgf|a still method]`: the CLI's
// side of the library's sequence session (include/atrous/sequence.h): it prints the session's
// notes and one line per frame, then a summary.
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "atrous/sequence.h"

namespace atrous::cli {

struct SequenceDenoiseArgs {
    std::string sequenceDir;        // --sequence: a folder or a frame pattern
    std::string outDir;             // --out
    SequenceDenoiseOptions options;  // everything else
    bool quiet = false;             // no per-frame lines or summary on stdout (notes still print)
};

// Runs the session and prints as it goes. Throws InputError for bad input (the CLI turns it into
// exit code 2). Returns 0.
int runSequenceDenoise(const SequenceDenoiseArgs& args);

// Registers one flag per row of svgfParams() (params.h) on `cmd`: --svgf-<name> (--svgf-sigma-l,
// --svgf-alpha, --svgf-depth-tolerance, ...; --taa and --taa-alpha keep their spellings), writing
// into `params`; the defaults shown are the struct's. Ranges are checked later
// (checkParamFlags, or validateSvgfParams: a ParamError naming the field).
void addSvgfOptions(CLI::App& cmd, SvgfParams& params);
// The same for temporalParams(): --temporal-radius, --temporal-color-sigmas, ...
void addTemporalOptions(CLI::App& cmd, TemporalParams& params);

}  // namespace atrous::cli

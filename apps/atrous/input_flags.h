// The input flags of a still, as `atrous denoise` and `atrous view` take them: --in (a render
// folder or a layered EXR), one file per buffer (--color, --albedo, ...), --pass BUFFER=NAME and
// --layer NAME; the BufferFiles they name (io::loadBuffers reads them), and the same flags as a
// command line again (the viewer's printed `atrous denoise` command). One place for the flags, so
// both commands read a user's render alike.
#pragma once
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "atrous/io/buffer_set.h"

namespace atrous::cli {

struct InputFlags {
    std::string in;                       // --in: a render folder or a layered EXR
    std::string file[io::kBufferCount];   // --color, --variance, --albedo, ... by buffer (object_id: --ids)
    std::vector<std::string> passes;      // --pass BUFFER=NAME
    std::string layer;                    // --layer NAME
    bool any() const;                     // whether any input flag was given
};

// The input flags: --in/-i, --pass, --layer and --color/--hdr in the help group `group` ("": the
// command's own options), the other buffers' files (--variance, --albedo/--alb, --normal/--nrm,
// --position, --depth, --ids, --emission) in `bufferGroup`.
void addInputFlags(CLI::App& cmd, InputFlags& f, const std::string& group, const std::string& bufferGroup);

// The flag of buffer b's own file ("--color", ..., "--ids"); "" for one without (material_id, motion).
const char* bufferFlag(io::Buffer b);

// The files they name (the --pass specs parsed: InputError naming --pass).
io::BufferFiles bufferFiles(const InputFlags& f);

// The flags again, as a shell command line's words (each quoted where needed): " --in 'my render.exr' --pass ...".
std::string inputCommandLine(const InputFlags& f);

// A word for a POSIX shell: unchanged when it holds only safe characters, else single-quoted.
std::string shellQuote(const std::string& word);

}  // namespace atrous::cli

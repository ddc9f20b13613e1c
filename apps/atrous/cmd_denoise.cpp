// Placeholder until the denoise subcommand lands (replaced by its own commit).
#include "commands.h"
#include "atrous/error.h"

namespace atrous::cli {

void addDenoiseCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("denoise", "(not built yet)");
    cmd->callback([] { throw InputError("'denoise' is not built yet"); });
}

}  // namespace atrous::cli

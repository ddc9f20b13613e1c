// Placeholder until the bench subcommand lands (replaced by its own commit).
#include "commands.h"
#include "atrous/error.h"

namespace atrous::cli {

void addBenchCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("bench", "(not built yet)");
    cmd->callback([] { throw InputError("'bench' is not built yet"); });
}

}  // namespace atrous::cli

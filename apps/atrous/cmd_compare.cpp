// Placeholder until the compare subcommand lands (replaced by its own commit).
#include "commands.h"
#include "atrous/error.h"

namespace atrous::cli {

void addCompareCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("compare", "(not built yet)");
    cmd->callback([] { throw InputError("'compare' is not built yet"); });
}

}  // namespace atrous::cli

// Placeholder until the render subcommand lands (replaced by its own commit).
#include "commands.h"
#include "atrous/error.h"

namespace atrous::cli {

void addRenderCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("render", "(not built yet)");
    cmd->callback([] { throw InputError("'render' is not built yet"); });
}

}  // namespace atrous::cli

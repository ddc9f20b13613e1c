// Each subcommand lives in its own cmd_<name>.cpp and registers itself on the CLI11 app. The
// callback it installs runs after parsing; any exception it throws becomes one line on stderr and
// exit code 2 (main.cpp).
#pragma once
#include <CLI/CLI.hpp>

namespace atrous::cli {

void addRenderCommand(CLI::App& app);
void addDenoiseCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addBenchCommand(CLI::App& app);
void addViewCommand(CLI::App& app);
void addInspectCommand(CLI::App& app);

}  // namespace atrous::cli

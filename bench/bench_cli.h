// Command-line parsing shared by the benchmark programs (CLI11, as apps/atrous): --help prints the
// usage and exits 0; an unknown flag or a bad value is one line on stderr and exit code 2, before
// any timing starts.
#pragma once
#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace atrous::bench {

// Returns -1 when the program should go on, else the exit code to return from main.
inline int parseArgs(CLI::App& app, int argc, char** argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);  // usage on stdout, 0
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "%s: error: %s (see --help)\n", app.get_name().c_str(), e.what());
        return 2;
    }
    return -1;
}

// "512x512" -> 512, 512; throws CLI::ValidationError (exit 2) otherwise.
inline void parseSize(const std::string& text, int& w, int& h) {
    char tail = 0;
    if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 1 || h < 1)
        throw CLI::ValidationError("--size", "expects WxH with positive numbers, e.g. 512x512 (got '" + text + "')");
}

// --size WxH: replaces `sizes` (the program's default list) by that one size; a bad value is a
// ValidationError from parseArgs (exit 2).
inline void addSizeOption(CLI::App& app, std::vector<std::pair<int, int>>& sizes) {
    app.add_option_function<std::string>(
        "--size",
        [&sizes](const std::string& text) {
            int w = 0, h = 0;
            parseSize(text, w, h);
            sizes = {{w, h}};
        },
        "time only this size, WxH (default: 512x512 and 1920x1080)");
}

}  // namespace atrous::bench

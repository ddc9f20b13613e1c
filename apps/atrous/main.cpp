// atrous: render noisy images with denoiser buffers, denoise them, compare against references.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/params.h"
#include "atrous/plugins.h"
#include "cli_flags.h"
#include "commands.h"

namespace {

// Error messages are one line: control characters that a file's bytes put into a message (a
// mangled EXR channel name with a newline) are written as '?' (found by tests/fuzz).
std::string oneLine(std::string s) {
    for (char& c : s)
        if ((unsigned char)c < 0x20 || c == 0x7f) c = '?';
    return s;
}

// `--plugin FILE.so` before the command (include/atrous/plugins.h): loaded before the commands are
// made, so that the methods it registers are in their choices and help.
std::vector<std::string> pluginArgs(int argc, char** argv) {
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--plugin" && i + 1 < argc) files.push_back(argv[++i]);
        else if (a.rfind("--plugin=", 0) == 0) files.push_back(a.substr(9));
        else if (!a.empty() && a[0] != '-') break;  // the command: its own flags follow
    }
    return files;
}

// " (did you mean --levels?)" for the first --flag of the command line that its command does not
// take, when one of the command's flags is a slip away (param_table.h, closestName); else "".
std::string flagSuggestion(CLI::App& app, int argc, char** argv) {
    CLI::App* cmd = nullptr;
    for (int i = 1; i < argc && !cmd; ++i) {
        if (argv[i][0] == '-') continue;
        try {
            cmd = app.get_subcommand(argv[i]);
        } catch (const CLI::OptionNotFound&) {
        }
    }
    if (!cmd) return "";
    std::vector<std::string> names;
    for (const CLI::Option* o : cmd->get_options())
        for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a.rfind("--", 0) != 0) continue;
        a = a.substr(0, a.find('='));
        if (a == "--plugin" || std::find(names.begin(), names.end(), a) != names.end()) continue;
        const std::string n = atrous::closestName(a, names);
        if (!n.empty()) return " (did you mean " + n + "?)";
    }
    return "";
}

}  // namespace

int main(int argc, char** argv) {
    try {
        for (const std::string& f : pluginArgs(argc, argv)) atrous::loadPlugin(f);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "atrous: error: --plugin %s\n", oneLine(e.what()).c_str());
        return 2;
    }
    CLI::App app{"atrous: Monte Carlo path tracing and fast wavelet denoising (EAW, SURE, SVGF)"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "atrous 0.1.0");
    std::vector<std::string> plugins;  // loaded above; declared here for --help and parsing
    app.add_option("--plugin", plugins,
                   "A shared library that adds denoising methods (include/atrous/plugins.h), before the command; "
                   "repeat for more");
    atrous::cli::addRenderCommand(app);
    atrous::cli::addDenoiseCommand(app);
    atrous::cli::addCompareCommand(app);
    atrous::cli::addBenchCommand(app);
    atrous::cli::addViewCommand(app);
    atrous::cli::addInspectCommand(app);
    // CLI11 reads an empty value as 0 ("--sigma-depth ''") or as if the flag were absent ("inspect
    // --export ''") without a word (found by tests/fuzz): every option of every command that takes
    // a value refuses an empty one.
    static const CLI::Validator kNonEmpty(
        [](std::string& v) { return v.empty() ? std::string("an empty value") : std::string(); }, "", "non-empty");
    // (denoise's positionals IN OUT refuse an empty one themselves, after CLI11 has named an
    // unknown flag whose empty value it took: `denoise --export ''` is about --export.)
    for (CLI::App* cmd : app.get_subcommands({}))
        for (CLI::Option* opt : cmd->get_options())
            if (opt->get_expected_min() > 0 && !(opt->get_positional() && cmd->get_name() == "denoise")) opt->check(kNonEmpty);
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ExtrasError& e) {
        // An unknown flag: one line, the nearest flag of the command when it is a slip away.
        std::fprintf(stderr, "atrous: error: %s%s (see --help)\n", oneLine(e.what()).c_str(),
                     flagSuggestion(app, argc, argv).c_str());
        return 2;
    } catch (const CLI::ParseError& e) {
        // Bad flags are bad input: one line, exit code 2.
        std::fprintf(stderr, "atrous: error: %s (see --help)\n", oneLine(e.what()).c_str());
        return 2;
    } catch (const atrous::ParamError& e) {
        // A library setting out of range (--device, --width, ...): the error names the field and
        // the parameter tables its flag (cli_flags.h); the message is not read.
        std::fprintf(stderr, "atrous: error: %s\n", oneLine(atrous::cli::flagMessage(e)).c_str());
        return 2;
    } catch (const atrous::InputError& e) {
        std::fprintf(stderr, "atrous: error: %s\n", oneLine(e.what()).c_str());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "atrous: error: %s\n", oneLine(e.what()).c_str());
        return 2;
    } catch (...) {  // a plug-in may throw anything
        std::fprintf(stderr, "atrous: error: an exception that is not a std::exception\n");
        return 2;
    }
    return 0;
}

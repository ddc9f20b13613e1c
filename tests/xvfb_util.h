// The viewer's headless runs under Xvfb, for the tests that open its window (view_test.cpp,
// view_files_test.cpp): whether the viewer is built and xvfb-run installed (the tests skip, saying
// which, where not), and the CLI run under xvfb-run in a hard time limit.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "test_util.h"

namespace atrous::test {

inline bool viewerBuilt() {
    static const bool built = runCli("view --help").output.find("--screenshot") != std::string::npos;
    return built;
}

inline bool haveXvfb() { return std::system("command -v xvfb-run > /dev/null 2>&1") == 0; }

// runCli's shape, with the CLI started by xvfb-run inside a hard time limit. ctest runs test
// processes in parallel, and two `xvfb-run -a` starting at once can race for the same display
// number: each process starts its search at its own number, and a run whose X server failed to
// start is retried once.
inline CliResult runUnderXvfb(const std::string& args) {
    static int calls = 0;
    CliResult r;
    for (int attempt = 0; attempt < 2; ++attempt) {
        const int display = 100 + int((unsigned(getpid()) * 37u + unsigned(calls++) * 7u) % 4000u);
        std::string cmd = "timeout -k 5 120 xvfb-run -a -n " + std::to_string(display) +
                          " -s '-screen 0 1024x768x24' " + std::string(ATROUS_CLI) + " " + args;
        r = runShell(cmd);
        if (r.exitCode == 0 || r.output.find("Xvfb failed to start") == std::string::npos) break;
    }
    return r;
}

}  // namespace atrous::test

#define REQUIRE_VIEWER_AND_XVFB()                                                                            \
    do {                                                                                                     \
        if (!atrous::test::viewerBuilt()) GTEST_SKIP() << "atrous built without the viewer";                 \
        if (!atrous::test::haveXvfb())                                                                       \
            GTEST_SKIP() << "xvfb-run (Xvfb) is not installed: the viewer's headless runs need an X server"; \
    } while (0)

// The benchmark programs' command lines (UX audit, item 4): --help prints a usage and exits 0,
// an unknown flag or a bad value exits 2 with one line, and neither starts a (multi-minute) run.
// `timeout` turns "started timing anyway" into a failure (exit 124) instead of a hung test.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "test_util.h"

namespace {

namespace fs = std::filesystem;
using atrous::test::runShell;

std::string benchPath(const std::string& name) { return (fs::path(ATROUS_CLI).parent_path() / "bench" / name).string(); }

int lines(const std::string& s) {
    int n = 0;
    for (char c : s) n += c == '\n';
    return n;
}

TEST(BenchCli, HelpUnknownFlagsAndBadValues) {
#if !ATROUS_HAVE_BENCH
    GTEST_SKIP() << "the bench programs are not built (ATROUS_BUILD_BENCH=OFF)";
#endif
    struct Case {
        const char* program;
        std::vector<std::string> badArgs;  // each must exit 2 at once
    };
    const Case cases[] = {
        {"bench_bvh", {"--bogus", "--runs 0", "--rays -5", "--threads x"}},
        {"bench_render", {"--bogus", "--runs 0", "--spp 0", "--width -1", "--scene nosuch"}},
        {"bench_gpu_render", {"--bogus", "--runs -1", "--spp 0", "--skip-cpu 2"}},
        {"bench_denoise", {"--bogus", "--runs -3", "--size 0x5", "--size 64", "--method foo", "--device gpu"}},
    };
    for (const Case& c : cases) {
        const std::string exe = benchPath(c.program);
        ASSERT_TRUE(fs::exists(exe)) << exe << " is not built (ATROUS_BUILD_BENCH is ON: it should be)";
        auto r = runShell("timeout 60 " + exe + " --help");
        EXPECT_EQ(r.exitCode, 0) << c.program << "\n" << r.output;
        EXPECT_NE(r.output.find("Usage"), std::string::npos) << c.program << "\n" << r.output;
        EXPECT_EQ(r.output.find("\"benchmark\""), std::string::npos) << c.program << ": --help ran the benchmark\n" << r.output;
        for (const std::string& bad : c.badArgs) {
            r = runShell("timeout 60 " + exe + " " + bad);
            EXPECT_EQ(r.exitCode, 2) << c.program << " " << bad << "\n" << r.output;
            EXPECT_EQ(lines(r.output), 1) << c.program << " " << bad << "\n" << r.output;
        }
    }
    auto r = runShell("timeout 60 " + benchPath("svgf_sequence_tool") + " --help");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("usage"), std::string::npos) << r.output;
}

// `atrous bench` rejects negative --runs/--warmup instead of taking the default.
TEST(BenchCli, AtrousBenchRejectsNegativeRuns) {
    for (const char* bad : {"--runs -1", "--warmup -2"}) {
        auto r = atrous::test::runCli(std::string("bench --sizes 16x16 --what eaw ") + bad);
        EXPECT_EQ(r.exitCode, 2) << bad << "\n" << r.output;
        EXPECT_EQ(r.output.find("median"), std::string::npos) << r.output;
    }
}

}  // namespace

// Every subcommand's --device error names the flag (main.cpp adds it where a command does not).
TEST(BenchCli, UnknownDeviceNamesTheFlagInEveryCommand) {
    for (const char* args : {"bench --sizes 16x16 --what eaw --device gpu"}) {
        auto r = atrous::test::runCli(args);
        EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
        EXPECT_NE(r.output.find("--device: must be cpu, cuda or auto (got 'gpu')"), std::string::npos) << args << "\n" << r.output;
    }
}

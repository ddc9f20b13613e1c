// The CPU ISA dispatch (src/core/cpu_isa.h): every ISA this CPU has gives the same EAW, SURE,
// SVGF and render outputs; the ATROUS_CPU_ISA override and its errors; and, under qemu-user on a
// CPU model without AVX, that the binary runs, picks the baseline loops by itself and gives the
// bits the baseline loops give natively.
//
// Equality between ISAs. AVX2 and AVX-512 both have FMA, and GCC contracts the same a*b+c into
// FMAs for both (contraction is decided per expression, before vectorisation, and no
// reassociation is allowed), so AVX-512 must equal AVX2 bit for bit. The baseline target has no
// FMA: there a*b+c is a rounded product plus a rounded sum (explicit fmaf calls stay fused, through
// libm), so baseline differs from AVX2 in the last bits of every contracted expression. Those
// differences pass through the edge-stop exponentials and the SURE/SVGF selections: measured
// here at most 3e-7 (EAW, SURE) and 1e-6 (SVGF) on outputs of order 1, so 1e-5 (10x margin; the
// bound eaw_test puts between the row engine and the functor, which differ in contraction too).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/io.h"
#include "atrous/render.h"
#include "core/cpu_isa.h"
#include "denoise_test_util.h"
#include "filters/atrous_level.h"
#include "svgf_test_util.h"
#include "test_util.h"

using namespace atrous;
using namespace atrous::test;
using cpu::Isa;

namespace {

std::vector<Isa> supportedIsas() {
    std::vector<Isa> v;
    for (Isa i : {Isa::Baseline, Isa::Avx2, Isa::Avx512})
        if (cpu::isaSupported(i)) v.push_back(i);
    return v;
}

// Restores the ISA in use when a test ends.
struct IsaScope {
    Isa saved = cpu::activeIsa();
    ~IsaScope() { cpu::setActiveIsa(saved); }
};

struct Outputs {
    Image eaw, sure, svgf, render;
};

Outputs runAll(bool withRender) {
    Outputs o;
    SyntheticScene s = makeScene(70, 45, 0.4f, 4);
    DenoiseOptions e;
    e.method = DenoiseMethod::Eaw;
    e.eaw.sigmaDepth = 0.1f;  // every EAW term on
    o.eaw = denoise(s.inputs(), e);
    DenoiseOptions su;
    su.method = DenoiseMethod::Sure;
    o.sure = denoise(s.inputs(), su);
    svgf_test::SceneOptions so;
    so.noiseSigma = 0.1f;
    so.emitter = true;
    o.svgf = svgf_test::runSequence(SvgfParams{}, so, 4);
    if (withRender) {
        RenderSettings rs;
        rs.width = 24;
        rs.height = 16;
        rs.spp = 2;
        rs.maxDepth = 4;
        o.render = std::move(render(Scene::builtin("cornell"), rs).color);
    }
    return o;
}

bool bitEqual(const Image& a, const Image& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (std::memcmp(&a.data()[i], &b.data()[i], sizeof(float)) != 0) return false;
    return true;
}

}  // namespace

TEST(CpuIsa, NamesParseAndOrder) {
    for (Isa i : {Isa::Baseline, Isa::Avx2, Isa::Avx512}) EXPECT_EQ(cpu::parseIsa(cpu::isaName(i), "X"), i);
    try {
        cpu::parseIsa("sse9", "ATROUS_CPU_ISA");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("ATROUS_CPU_ISA=sse9"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("baseline, avx2 or avx512"), std::string::npos) << e.what();
    }
    // Baseline always; AVX-512 only with AVX2; the best one is supported.
    EXPECT_TRUE(cpu::isaSupported(Isa::Baseline));
    if (cpu::isaSupported(Isa::Avx512)) EXPECT_TRUE(cpu::isaSupported(Isa::Avx2));
    EXPECT_TRUE(cpu::isaSupported(cpu::bestIsa()));
    // Without ATROUS_CPU_ISA (ctest does not set it) the best one is in use.
    if (!std::getenv("ATROUS_CPU_ISA")) EXPECT_EQ(cpu::activeIsa(), cpu::bestIsa());
}

TEST(CpuIsa, SetActiveIsaSetsTheRowEngineSwitch) {
    IsaScope scope;
    for (Isa i : supportedIsas()) {
        cpu::setActiveIsa(i);
        EXPECT_EQ(cpu::activeIsa(), i);
        EXPECT_EQ(filters::atrousCpuAvx512(), i == Isa::Avx512);
        EXPECT_NE(cpu::isaDescription().find(cpu::isaName(i)), std::string::npos);
    }
    // An ISA this CPU lacks: one InputError, the ISA in use unchanged.
    for (Isa i : {Isa::Avx2, Isa::Avx512}) {
        if (cpu::isaSupported(i)) continue;
        const Isa before = cpu::activeIsa();
        EXPECT_THROW(cpu::setActiveIsa(i), InputError);
        EXPECT_EQ(cpu::activeIsa(), before);
    }
}

TEST(CpuIsa, EveryIsaGivesTheSameOutputs) {
    IsaScope scope;
    const std::vector<Isa> isas = supportedIsas();
    if (isas.size() < 2) GTEST_SKIP() << "this CPU runs only the baseline loops";
    std::vector<Outputs> outs;
    for (Isa i : isas) {
        cpu::setActiveIsa(i);
        outs.push_back(runAll(true));
    }
    const Outputs& ref = outs[0];  // baseline
    for (size_t k = 1; k < isas.size(); ++k) {
        const Outputs& o = outs[k];
        const std::string name = cpu::isaName(isas[k]);
        // Baseline against AVX2/AVX-512: no FMA contraction on baseline (header comment).
        EXPECT_LT(maxAbsDiff(o.eaw, ref.eaw), 1e-5) << name;
        EXPECT_LT(maxAbsDiff(o.sure, ref.sure), 1e-5) << name;
        EXPECT_LT(svgf_test::maxAbsDiff(o.svgf, ref.svgf), 1e-5) << name;
        // The path tracer's contracted expressions feed the sampling decisions of later bounces;
        // a different decision changes a sample of one pixel, so compare the image means (2 spp
        // values ~1: 1e-3 relative is one changed path in ~400 pixels).
        double a = 0, b = 0;
        for (size_t i = 0; i < ref.render.size(); ++i) {
            a += ref.render.data()[i];
            b += o.render.data()[i];
        }
        EXPECT_NEAR(b / a, 1.0, 1e-3) << name;
        // The baseline loops differ at all from the FMA ones: the ISA switch really switches.
        EXPECT_FALSE(bitEqual(o.eaw, ref.eaw)) << name << ": the same bits as baseline (no dispatch?)";
    }
    // AVX-512 against AVX2: the same contraction, so the same bits.
    if (isas.size() == 3) {
        EXPECT_TRUE(bitEqual(outs[2].eaw, outs[1].eaw));
        EXPECT_TRUE(bitEqual(outs[2].sure, outs[1].sure));
        EXPECT_TRUE(bitEqual(outs[2].svgf, outs[1].svgf));
        EXPECT_TRUE(bitEqual(outs[2].render, outs[1].render));
    }
}

// ATROUS_CPU_ISA through the CLI: an unknown name is one line and exit 2; a valid one is used.
TEST(CpuIsa, EnvironmentOverrideInTheCli) {
    TempDir tmp;
    ASSERT_EQ(runCli("render --scene cornell --width 24 --height 16 --spp 2 --seed 3 --max-depth 3 --out " +
                     (tmp / "r")).exitCode, 0);
    const CliResult bad = runShell("ATROUS_CPU_ISA=sse9 " + std::string(ATROUS_CLI) + " denoise --in " + (tmp / "r") +
                                   " --out " + (tmp / "bad.exr"));
    EXPECT_EQ(bad.exitCode, 2) << bad.output;
    EXPECT_NE(bad.output.find("ATROUS_CPU_ISA=sse9"), std::string::npos) << bad.output;
    EXPECT_EQ(countEntries(tmp.str()), 1) << "a failed denoise wrote something";
    std::vector<Image> outs;
    for (Isa i : supportedIsas()) {
        const std::string out = tmp / (std::string(cpu::isaName(i)) + ".pfm");
        const CliResult r = runShell(std::string("ATROUS_CPU_ISA=") + cpu::isaName(i) + " " + ATROUS_CLI +
                                     " denoise --in " + (tmp / "r") + " --out " + out);
        ASSERT_EQ(r.exitCode, 0) << r.output;
        outs.push_back(readImage(out));
    }
    // Each run used the ISA it was given: the baseline output differs from the FMA ones (see the
    // header comment), which equal each other.
    // 1e-4: the header's 1e-5 on a render whose radiance reaches ~10.
    for (size_t k = 1; k < outs.size(); ++k) {
        EXPECT_LT(maxAbsDiff(outs[k], outs[0]), 1e-4);
        EXPECT_FALSE(bitEqual(outs[k], outs[0])) << cpu::isaName(supportedIsas()[k]);
    }
    if (outs.size() == 3) EXPECT_TRUE(bitEqual(outs[2], outs[1]));
}

// ---- without AVX, under qemu-user (Debian's qemu-user; scripts/setup.sh installs it) ----

namespace {

// A CPU model without AVX (SSE4.2 is its best): the baseline loops are all it may run.
constexpr const char* kQemuCpu = "Westmere";
constexpr const char* kChildOut = "ATROUS_ISA_TEST_OUT";

std::string selfExe() {
    std::error_code ec;
    return std::filesystem::read_symlink("/proc/self/exe", ec).string();
}

std::string qemu() {
    const CliResult r = runShell("command -v qemu-x86_64");
    if (r.exitCode != 0) return "";
    return std::string("qemu-x86_64 -cpu ") + kQemuCpu;
}

}  // namespace

// The emulated half of CpuIsa.RunsWithoutAvxUnderQemu (skipped when run directly).
TEST(CpuIsaEmulated, Child) {
    const char* dir = std::getenv(kChildOut);
    if (!dir) GTEST_SKIP() << "run under qemu by CpuIsa.RunsWithoutAvxUnderQemu";
    // Chosen by CPUID alone (no ATROUS_CPU_ISA in the child's environment).
    ASSERT_EQ(std::getenv("ATROUS_CPU_ISA"), nullptr);
    EXPECT_FALSE(cpu::isaSupported(Isa::Avx2));
    EXPECT_FALSE(cpu::isaSupported(Isa::Avx512));
    EXPECT_EQ(cpu::bestIsa(), Isa::Baseline);
    EXPECT_EQ(cpu::activeIsa(), Isa::Baseline);
    EXPECT_FALSE(filters::atrousCpuAvx512());
    EXPECT_THROW(cpu::setActiveIsa(Isa::Avx2), InputError);
    EXPECT_THROW(cpu::setActiveIsa(Isa::Avx512), InputError);
    const Outputs o = runAll(false);
    writeImage(std::string(dir) + "/eaw.pfm", o.eaw);
    writeImage(std::string(dir) + "/sure.pfm", o.sure);
    writeImage(std::string(dir) + "/svgf.pfm", o.svgf);
}

TEST(CpuIsa, RunsWithoutAvxUnderQemu) {
#if defined(__SANITIZE_ADDRESS__)
    // ASan's shadow memory (terabytes of reserved address space) does not map under qemu-user:
    // the emulated process grows until it is killed.
    GTEST_SKIP() << "an ASan build does not run under qemu-user";
#endif
    const std::string q = qemu();
    if (q.empty()) GTEST_SKIP() << "qemu-x86_64 not found (Debian package qemu-user)";
    TempDir tmp;
    // The test program itself on the emulated CPU: it picks the baseline loops, and its outputs are
    // the bits the baseline loops give here (the same instructions; fmaf is correctly rounded
    // whichever way libm computes it).
    const CliResult child = runShell("env -u ATROUS_CPU_ISA " + std::string(kChildOut) + "=" + tmp.str() + " " + q +
                                     " " + selfExe() + " --gtest_filter=CpuIsaEmulated.Child");
    ASSERT_EQ(child.exitCode, 0) << child.output;
    ASSERT_EQ(child.output.find("SKIPPED"), std::string::npos) << child.output;
    {
        IsaScope scope;
        cpu::setActiveIsa(Isa::Baseline);
        const Outputs ref = runAll(false);
        EXPECT_TRUE(bitEqual(readImage(tmp / "eaw.pfm"), ref.eaw));
        EXPECT_TRUE(bitEqual(readImage(tmp / "sure.pfm"), ref.sure));
        EXPECT_TRUE(bitEqual(readImage(tmp / "svgf.pfm"), ref.svgf));
    }
    // The CLI: `atrous denoise` of a tiny render runs, and gives the native baseline bits.
    ASSERT_EQ(runCli("render --scene cornell --width 24 --height 16 --spp 2 --seed 3 --max-depth 3 --out " +
                     (tmp / "r")).exitCode, 0);
    for (const char* m : {"eaw", "sure"}) {
        const std::string args = std::string(" denoise --method ") + m + " --in " + (tmp / "r") + " --out ";
        const CliResult emu = runShell("env -u ATROUS_CPU_ISA " + q + " " + ATROUS_CLI + args + (tmp / "emu.pfm"));
        ASSERT_EQ(emu.exitCode, 0) << emu.output;
        const CliResult nat = runShell(std::string("ATROUS_CPU_ISA=baseline ") + ATROUS_CLI + args + (tmp / "nat.pfm"));
        ASSERT_EQ(nat.exitCode, 0) << nat.output;
        EXPECT_TRUE(bitEqual(readImage(tmp / "emu.pfm"), readImage(tmp / "nat.pfm"))) << m;
    }
    // Asking the emulated CPU for AVX2: one line naming the variable, exit 2, no crash.
    const CliResult bad = runShell("ATROUS_CPU_ISA=avx2 " + q + " " + ATROUS_CLI + " denoise --in " + (tmp / "r") +
                                   " --out " + (tmp / "bad.pfm"));
    EXPECT_EQ(bad.exitCode, 2) << bad.output;
    EXPECT_NE(bad.output.find("ATROUS_CPU_ISA=avx2: this CPU cannot run the avx2 loops"), std::string::npos)
        << bad.output;
    EXPECT_FALSE(std::filesystem::exists(tmp / "bad.pfm"));
}

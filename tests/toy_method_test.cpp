// A new still method is one registry row plus its policy (issue 31): tests/toy_method.cpp registers
// "toy" (the toy edge-stop policy of tests/toy_policy.h as a three-level cascade) and nothing else
// is edited. Linked into this test, the viewer's pipeline lists and runs it; linked with the CLI's
// objects (atrous_toy), `denoise --help` lists it and `denoise --method toy` runs it, while the
// CLI without it refuses the name. denoise() with it is the cascade on the prepared planes, then
// the remodulation, bit for bit. Python's registry (atrous.register_method) and the farm's
// --plugin are tests/python/test_methods.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/render.h"
#include "filters/denoise_internal.h"
#include "atrous/io/image_io.h"
#include "denoise_test_util.h"
#include "render_test_util.h"
#include "test_util.h"
#include "toy_method.h"
#include "atrous/view_pipeline.h"

namespace atrous {
namespace {

struct Rendered : test::RenderedInputs {
    Rendered() : RenderedInputs("cornell", 32, 24, 4, 3) {}
};

// The render's colour, albedo and normal as a render folder dir/r (what `denoise --in` reads).
std::string renderFolder(const test::TempDir& dir) {
    const Rendered r;
    const std::string in = dir / "r";
    std::filesystem::create_directories(in);
    atrous::writeImage(in + "/color.exr", r.b.color);
    atrous::writeImage(in + "/albedo.exr", r.b.albedo);
    atrous::writeImage(in + "/normal.exr", r.b.normal);
    return in;
}

TEST(ToyMethod, IsARowOfTheRegistry) {
    const DenoiseMethodInfo* m = findDenoiseMethod("toy");
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->method, toy::toyMethod());
    EXPECT_TRUE(m->registered());
    EXPECT_FALSE(m->usesWeights);
    EXPECT_EQ(parseDenoiseMethod("toy"), toy::toyMethod());
    EXPECT_STREQ(denoiseMethodName(toy::toyMethod()), "toy");
    EXPECT_NE(denoiseMethodNames().find("toy"), std::string::npos);
    // The built-in rows keep their order and come first.
    EXPECT_STREQ(denoiseMethods().front().name, "eaw");
    EXPECT_EQ(&denoiseMethodInfo(toy::toyMethod()), m);
    // A taken or malformed name, no cascade, or the weights: an InputError, nothing added.
    const size_t n = denoiseMethods().size();
    EXPECT_THROW(registerDenoiseMethod({DenoiseMethod::Eaw, "toy", "again", false, toy::toyCascade}), InputError);
    EXPECT_THROW(registerDenoiseMethod({DenoiseMethod::Eaw, "sure", "again", false, toy::toyCascade}), InputError);
    EXPECT_THROW(registerDenoiseMethod({DenoiseMethod::Eaw, "a b", "", false, toy::toyCascade}), InputError);
    EXPECT_THROW(registerDenoiseMethod({DenoiseMethod::Eaw, "", "", false, toy::toyCascade}), InputError);
    EXPECT_THROW(registerDenoiseMethod({DenoiseMethod::Eaw, "bare", "", false}), InputError);
    EXPECT_THROW(registerDenoiseMethod({DenoiseMethod::Eaw, "weighted", "", true, toy::toyCascade}), InputError);
    for (const char* reserved : {"temporal", "svgf", "none", "noisy", "oidn"})
        EXPECT_THROW(registerDenoiseMethod({DenoiseMethod::Eaw, reserved, "", false, toy::toyCascade}), InputError)
            << reserved;
    EXPECT_EQ(denoiseMethods().size(), n);
    // What a row reads tells a reader what to decode (the preparation's buffers always).
    DenoiseMethodInfo normalOnly{DenoiseMethod::Eaw, "toy-normal-only", "", false, toy::toyCascade};
    normalOnly.reads = DenoiseBufferUse{false, false, true, false, false, false, false};
    const DenoiseBufferUse use = denoiseBufferUse(DenoiseOptions{}, registerDenoiseMethod(normalOnly));
    EXPECT_TRUE(use.normal && use.variance && use.emission && use.albedo && use.depth);
    EXPECT_FALSE(use.position || use.ids);
    EXPECT_TRUE(denoiseBufferUse(DenoiseOptions{}, toy::toyMethod()).position);
    // A value no row has is an InputError, not undefined behaviour.
    DenoiseOptions o;
    o.method = static_cast<DenoiseMethod>(999);
    const Rendered r;
    EXPECT_THROW(denoise(r.inputs(), o), InputError);
}

TEST(ToyMethod, IsItsCascadeOnThePreparedPlanesThenRemodulate) {
    const Rendered r;
    for (bool albedo : {true, false}) {
        DenoiseInputs in = r.inputs();
        if (!albedo) in.albedo = nullptr;
        DenoiseOptions o;
        o.method = toy::toyMethod();
        DenoiseReport rep;
        const Image out = test::denoiseReporting(in, o, rep);
        EXPECT_EQ(rep.methodUsed, toy::toyMethod());
        bool staged = false;
        for (const StageTime& s : rep.stages) staged = staged || s.name == "toy";
        EXPECT_TRUE(staged) << "no stage 'toy'";
        const PreparedPlanes p = learnedPlanes(in, o);
        StillPlanes P;
        P.color = p.d.view(), P.variance = p.var.view();
        if (!p.albedo.empty()) P.albedo = p.albedo.view();
        Image f(32, 24, 3);
        toy::toyCascade(P, o, f.view());
        long differ = -1, changed = -1;
        for (int y = 0; y < 24 && differ < 0; ++y)
            for (int x = 0; x < 32; ++x)
                for (int c = 0; c < 3; ++c) {
                    if (!(out(x, y, c) == f(x, y, c) * p.mod(x, y, c) + p.emission(x, y, c))) differ = long(c) * 1000 + y * 32 + x;
                    if (out(x, y, c) != r.b.color(x, y, c)) changed = 1;
                }
        EXPECT_EQ(differ, -1) << "albedo " << albedo;
        EXPECT_EQ(changed, 1) << "it filtered";
    }
    // No CUDA cascade: on CUDA an InputError naming the method (whether or not a GPU is present).
    DenoiseOptions o;
    o.method = toy::toyMethod();
    o.device = Device::Cuda;
    try {
        denoise(r.inputs(), o);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("'toy' has no cascade for CUDA"), std::string::npos) << e.what();
    }
}

// A cascade's exception reaches the caller naming the method, whatever it threw.
TEST(ToyMethod, ACascadesErrorsNameTheMethod) {
    registerDenoiseMethod({DenoiseMethod::Eaw, "throws-int", "", false,
                           [](const StillPlanes&, const DenoiseOptions&, const ImageView&) { throw 42; }});
    registerDenoiseMethod({DenoiseMethod::Eaw, "throws-input", "", false,
                           [](const StillPlanes&, const DenoiseOptions&, const ImageView&) { throw InputError("bad"); }});
    const Rendered r;
    DenoiseOptions o;
    o.method = parseDenoiseMethod("throws-int");
    try {
        denoise(r.inputs(), o);
        ADD_FAILURE() << "no error";
    } catch (const RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find("method 'throws-int': "), std::string::npos) << e.what();
    }
    o.method = parseDenoiseMethod("throws-input");
    EXPECT_NE(test::inputErrorOf(r.inputs(), o).find("method 'throws-input': bad"), std::string::npos);
}

TEST(ToyMethod, TheViewerListsAndRunsIt) {
    using namespace view;
    const auto& names = methodNames();
    EXPECT_NE(std::find(names.begin(), names.end(), "toy"), names.end());
    const Method m = parseMethod("toy");
    EXPECT_EQ(m, Method::of(toy::toyMethod()));
    EXPECT_STREQ(methodName(m), "toy");
    ViewPipeline pl(Scene::builtin("cornell"), 32, 24, Device::Cpu, 1);
    PipelineSettings s;
    s.methodA = m;
    s.maxDepth = 3;
    for (int i = 0; i < 2; ++i) pl.step(s);
    const SlotResult& r = pl.slot(0);
    EXPECT_TRUE(r.error.empty()) << r.error;
    ASSERT_EQ(r.image.width(), 32);
    EXPECT_EQ(r.method, m);
}

#ifdef ATROUS_TOY_CLI
TEST(ToyMethod, TheCliWithItListsAndRunsItAndTheOneWithoutRefusesIt) {
    const std::string toyCli = ATROUS_TOY_CLI;
    if (!std::filesystem::exists(toyCli)) GTEST_SKIP() << toyCli << " is not there (a test pack moved elsewhere)";
    test::CliResult h = test::runShell(toyCli + " denoise --help");
    EXPECT_EQ(h.exitCode, 0) << h.output;
    EXPECT_NE(h.output.find("toy: a toy"), std::string::npos) << h.output;
    test::TempDir dir;
    const std::string in = renderFolder(dir);
    const std::string out = dir / "o.exr";
    test::CliResult run = test::runShell(toyCli + " denoise --in " + in + " --out " + out + " --method toy");
    EXPECT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("method toy"), std::string::npos) << run.output;
    EXPECT_TRUE(std::filesystem::exists(out));
    // The project's own CLI has no such method: one line, exit 2, nothing written.
    const std::string out2 = dir / "o2.exr";
    test::CliResult plain = test::runCli("denoise --in " + in + " --out " + out2 + " --method toy");
    EXPECT_EQ(plain.exitCode, 2) << plain.output;
    EXPECT_NE(plain.output.find("toy"), std::string::npos) << plain.output;
    EXPECT_FALSE(std::filesystem::exists(out2));
    test::CliResult plainHelp = test::runCli("denoise --help");
    EXPECT_EQ(plainHelp.output.find("toy: a toy"), std::string::npos);
}
#endif

#ifdef ATROUS_TOY_PLUGIN_FILE
// The same file built as a plugin: `atrous --plugin` lists it in denoise's help and the viewer's
// method list and runs it with the same output as atrous_toy; a plugin that is not there, or a
// library that is no plugin, is one line and exit 2.
TEST(ToyMethod, AsAPluginTheCliListsAndRunsIt) {
    if (!std::filesystem::exists(ATROUS_TOY_PLUGIN_FILE)) GTEST_SKIP() << ATROUS_TOY_PLUGIN_FILE << " is not there";
    const std::string plugin = std::string(" --plugin ") + ATROUS_TOY_PLUGIN_FILE + " ";
    test::expectCli(plugin + "denoise --help", 0, {"toy: a toy"});
    test::expectCli(plugin + "view --help", 0, {"| toy |"});
    test::TempDir dir;
    const std::string in = renderFolder(dir);
    test::expectCli(plugin + "denoise --in " + in + " --method toy --out " + (dir / "plugin.exr"), 0, {"method toy"});
#ifdef ATROUS_TOY_CLI
    if (std::filesystem::exists(ATROUS_TOY_CLI)) {
        test::runShell(std::string(ATROUS_TOY_CLI) + " denoise --in " + in + " --method toy --out " + (dir / "linked.exr"));
        EXPECT_TRUE(test::sameImages(atrous::readImage(dir / "plugin.exr"), atrous::readImage(dir / "linked.exr")));
    }
#endif
    const test::CliResult missing = test::expectCli(" --plugin " + (dir / "nope.so") + " denoise --help", 2, {"nope.so"});
    EXPECT_EQ(std::count(missing.output.begin(), missing.output.end(), '\n'), 1) << missing.output;
    std::ofstream(dir / "junk.so") << "not a library";
    test::expectCli(" --plugin " + (dir / "junk.so") + " denoise --help", 2, {"junk.so: cannot load the plugin"});
}
#endif

}  // namespace
}  // namespace atrous

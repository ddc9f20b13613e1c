// A new still method is one registry row plus its policy (issue 31): tests/toy_method.cpp registers
// "toy" (the toy edge-stop policy of tests/toy_policy.h as a three-level cascade) and nothing else
// is edited. Linked into this test, the viewer's pipeline lists and runs it; linked with the CLI's
// objects (atrous_toy), `denoise --help` lists it and `denoise --method toy` runs it, while the
// CLI without it refuses the name. denoise() with it is the cascade on the prepared planes, then
// the remodulation, bit for bit. Python's registry (atrous.register_method) and the farm's
// --plugin are tests/python/test_methods.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/sequence_methods.h"
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

// A registry row of a registered method.
DenoiseMethodInfo row(const char* name, StillCascade cascade, MethodReads reads = {}) {
    DenoiseMethodInfo m;
    m.name = name, m.cpu = std::move(cascade), m.reads = std::move(reads);
    return m;
}

TEST(ToyMethod, IsARowOfTheRegistry) {
    const DenoiseMethodInfo* m = findDenoiseMethod("toy");
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->method, toy::toyMethod());
    EXPECT_TRUE(m->registered());
    EXPECT_FALSE(readsWeights(*m));
    EXPECT_EQ(parseDenoiseMethod("toy"), toy::toyMethod());
    EXPECT_STREQ(denoiseMethodName(toy::toyMethod()), "toy");
    EXPECT_NE(denoiseMethodNames().find("toy"), std::string::npos);
    // The built-in rows keep their order and come first.
    EXPECT_STREQ(denoiseMethods().front().name, "eaw");
    EXPECT_EQ(&denoiseMethodInfo(toy::toyMethod()), m);
    // A taken or malformed name, no cascade, or the weights: an InputError, nothing added.
    const size_t n = denoiseMethods().size();
    EXPECT_THROW(registerDenoiseMethod(row("toy", toy::toyCascade)), InputError);
    EXPECT_THROW(registerDenoiseMethod(row("sure", toy::toyCascade)), InputError);
    EXPECT_THROW(registerDenoiseMethod(row("a b", toy::toyCascade)), InputError);
    EXPECT_THROW(registerDenoiseMethod(row("", toy::toyCascade)), InputError);
    EXPECT_THROW(registerDenoiseMethod(row("bare", {})), InputError);
    EXPECT_THROW(registerDenoiseMethod(row("weighted", toy::toyCascade, {{}, {}, true, {}})), InputError);
    EXPECT_THROW(registerDenoiseMethod(row("nogroup", toy::toyCascade, {{}, {"no-such-group"}, false, {}})), InputError);
    EXPECT_THROW(registerDenoiseMethod(row("combines", toy::toyCascade, {{}, {}, false, {DenoiseMethod::Sure}})), InputError);
    EXPECT_THROW(registerDenoiseMethod(row("motion", toy::toyCascade, {{Buffer::Motion}, {}, false, {}})), InputError);
    for (const char* reserved : {"temporal", "svgf", "none", "noisy", "oidn"})
        EXPECT_THROW(registerDenoiseMethod(row(reserved, toy::toyCascade)), InputError) << reserved;
    EXPECT_EQ(denoiseMethods().size(), n);
    // What a row reads tells a reader what to decode (the preparation's buffers always), and the
    // report what was unused.
    const DenoiseMethod normalOnly = registerDenoiseMethod(row("toy-normal-only", toy::toyCascade, {{Buffer::Normal}, {}, false, {}}));
    const BufferMask use = denoiseReads(DenoiseOptions{}, normalOnly);
    for (Buffer b : {Buffer::Color, Buffer::Normal, Buffer::Variance, Buffer::Emission, Buffer::Albedo, Buffer::Depth})
        EXPECT_TRUE(use.has(b)) << bufferName(b);
    EXPECT_FALSE(use.has(Buffer::Position) || use.has(Buffer::ObjectId) || use.has(Buffer::Motion));
    EXPECT_EQ(unusedReason(Buffer::Position, DenoiseOptions{}, normalOnly, false), "by toy-normal-only");
    EXPECT_EQ(unusedReason(Buffer::Normal, DenoiseOptions{}, normalOnly, false), "");
    EXPECT_EQ(unusedReason(Buffer::Depth, DenoiseOptions{}, normalOnly, true), "");  // the noise estimate's
    EXPECT_TRUE(denoiseReads(DenoiseOptions{}, toy::toyMethod()).has(Buffer::Albedo));
    // A value no row has is an InputError, not undefined behaviour.
    DenoiseOptions o;
    o.method = static_cast<DenoiseMethod>(999);
    const Rendered r;
    EXPECT_THROW(denoise(r.inputs(), o), InputError);
}

TEST(ToyMethod, IsItsCascadeOnThePreparedPlanesThenRemodulate) {
    const Rendered r;
    for (bool albedo : {true, false}) {
        Frame in = r.inputs();
        if (!albedo) in.albedo = nullptr;
        DenoiseOptions o;
        o.method = toy::toyMethod();
        DenoiseReport rep;
        const Image out = test::denoiseReporting(in, o, rep);
        EXPECT_EQ(rep.methodUsed, toy::toyMethod());
        bool staged = false;
        for (const StageTime& s : rep.stages) staged = staged || s.name == "toy";
        EXPECT_TRUE(staged) << "no stage 'toy'";
        const PreparedPlanes p = preparePlanes(in, o);
        PreparedView P = p.view();
        P.modulation = P.emission = ImageView{};  // what a cascade is given
        Image f(32, 24, 3);
        toy::toyCascade(P, o, f.view());
        long differ = -1, changed = -1;
        for (int y = 0; y < 24 && differ < 0; ++y)
            for (int x = 0; x < 32; ++x)
                for (int c = 0; c < 3; ++c) {
                    if (!(out(x, y, c) == f(x, y, c) * p.modulation(x, y, c) + p.emission(x, y, c))) differ = long(c) * 1000 + y * 32 + x;
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
    registerDenoiseMethod(row("throws-int", [](const PreparedView&, const DenoiseOptions&, const ImageView&) { throw 42; }));
    registerDenoiseMethod(
        row("throws-input", [](const PreparedView&, const DenoiseOptions&, const ImageView&) { throw InputError("bad"); }));
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

// The toy sequence method (tests/toy_sequence_method.cpp): a row of the sequence methods' registry
// with its own parameter table; the name rules are the still methods', both ways.
TEST(ToySequenceMethod, IsARowOfTheRegistry) {
    const SequenceMethodInfo* m = findSequenceMethod("toyseq");
    ASSERT_NE(m, nullptr);
    EXPECT_TRUE(m->registered);
    EXPECT_TRUE(m->causal && m->history);
    EXPECT_STREQ(m->params.set(), "toyseq");
    ASSERT_EQ(m->params.rows().size(), 1u);
    EXPECT_EQ(m->params.rows()[0].flag, "--toyseq-alpha");
    EXPECT_TRUE(m->reads.has(Buffer::Motion));
    EXPECT_NE(sequenceMethodNames().find("toyseq"), std::string::npos);
    EXPECT_STREQ(sequenceMethods().front().name, "temporal");  // the built-in rows first
    const size_t n = sequenceMethods().size(), still = denoiseMethods().size();
    SequenceMethodInfo again = *m;
    for (const char* taken : {"toyseq", "svgf", "temporal", "toy", "eaw", "auto", "none", "noisy", "oidn", "", "a b"}) {
        again.name = taken;
        EXPECT_THROW(registerSequenceMethod(again), InputError) << taken;
    }
    again.name = "toyseq-bare";
    again.make = nullptr;
    EXPECT_THROW(registerSequenceMethod(again), InputError);
    again.make = m->make;
    again.weightsParam = "no_such_switch";
    EXPECT_THROW(registerSequenceMethod(again), InputError);
    EXPECT_THROW(registerDenoiseMethod(row("toyseq", toy::toyCascade)), InputError);
    EXPECT_EQ(sequenceMethods().size(), n);
    EXPECT_EQ(denoiseMethods().size(), still);
}

// Through the one interface: the first frame is its own colour, then where nothing moved the
// running average alpha * c + (1 - alpha) * previous, elsewhere the frame's colour; reset() starts
// over; a bad parameter is a ParamError naming the field.
TEST(ToySequenceMethod, IsTheRunningAverageThroughTheInterface) {
    const Rendered a;
    Image still(32, 24, 2), moved(32, 24, 2);
    moved.fill(1.0f);
    SequenceSetup setup;
    ParamSet p = findSequenceMethod("toyseq")->params;
    *std::get<float*>(p.at(0)) = 0.25f;
    setup.params = p;
    std::unique_ptr<SequenceDenoiser> d = makeSequenceDenoiser("toyseq", setup);
    EXPECT_EQ(d->lookahead(), 0);
    Frame f0 = a.inputs(), f1 = a.inputs();
    f0.motion = &still, f1.motion = &still;
    d->push({f0, nullptr});
    ASSERT_TRUE(d->ready());
    const SequenceOutput o0 = d->next();
    EXPECT_EQ(o0.methodUsed, "toyseq");
    EXPECT_TRUE(test::sameImages(o0.image, a.b.color));
    d->push({f1, nullptr});
    const Image o1 = d->next().image;
    EXPECT_EQ(o1(3, 4, 1), 0.25f * a.b.color(3, 4, 1) + 0.75f * o0.image(3, 4, 1));
    f1.motion = &moved;
    d->push({f1, nullptr});
    EXPECT_TRUE(test::sameImages(d->next().image, a.b.color));
    d->reset();
    d->push({f0, nullptr});
    EXPECT_TRUE(test::sameImages(d->next().image, a.b.color));
    *std::get<float*>(setup.params.at(0)) = 2.0f;
    EXPECT_THROW(makeSequenceDenoiser("toyseq", setup), ParamError);
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
    // The toy sequence method too: listed, and run on each frame's own samples.
    EXPECT_NE(std::find(names.begin(), names.end(), "toyseq"), names.end());
    const Method seq = parseMethod("toyseq");
    EXPECT_TRUE(seq.ownSamples());
    s.methodA = seq;
    for (int i = 0; i < 2; ++i) pl.step(s);
    EXPECT_TRUE(pl.slot(0).error.empty()) << pl.slot(0).error;
    EXPECT_EQ(pl.slot(0).image.width(), 32);
    EXPECT_STREQ(methodName(pl.slot(0).method), "toyseq");
    *std::get<float*>(sequenceParams(s, *findSequenceMethod("toyseq")).at(0)) = 5.0f;
    pl.step(s);
    EXPECT_NE(pl.slot(0).error.find("alpha"), std::string::npos) << pl.slot(0).error;
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
    // What the row reads is what the CLI says: the toy reads no EAW or SURE parameter (a flag of a
    // stage every method has, --firefly-k, is no note).
    const std::string out3 = dir / "o3.exr";
    test::CliResult noted = test::runShell(toyCli + " denoise --in " + in + " --out " + out3 +
                                           " --method toy --levels 3 --sure-window 2 --firefly-k 5");
    EXPECT_EQ(noted.exitCode, 0) << noted.output;
    EXPECT_NE(noted.output.find("ignored with --method toy: --levels, --sure-window"), std::string::npos) << noted.output;
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
    // The toy sequence method of the same plugin: listed (its flags in their group), run on a
    // sequence, each frame the running average of the frames before where nothing moved; its
    // flags are ignored (noted) with another method and range-checked with it.
    test::expectCli(plugin + "denoise --help", 0, {"toyseq (with --sequence): a toy", "Toy sequence (--method toyseq)",
                                                   "--toyseq-alpha"});
    test::expectCli(plugin + "view --help", 0, {"| toyseq"});
    const std::string seq = test::renderSequence(dir, 3);
    test::expectCli(plugin + "denoise --sequence " + seq + " --method toyseq --toyseq-alpha 0.5 --out " + (dir / "toyseq"), 0,
                    {"frame_0002: toyseq"});
    Image avg = atrous::readImage(seq + "/frame_0000/color.exr");
    for (int f = 0; f < 3; ++f) {
        const std::string frame = seq + "/frame_000" + std::to_string(f);
        const Image c = atrous::readImage(frame + "/color.exr"), motion = atrous::readImage(frame + "/motion.exr");
        for (int y = 0; y < c.height(); ++y)
            for (int x = 0; x < c.width(); ++x) {
                const bool still = f > 0 && std::fabs(motion(x, y, 0)) < 0.05f && std::fabs(motion(x, y, 1)) < 0.05f;
                for (int ch = 0; ch < 3; ++ch) avg(x, y, ch) = still ? 0.5f * c(x, y, ch) + 0.5f * avg(x, y, ch) : c(x, y, ch);
            }
        EXPECT_TRUE(test::sameImages(atrous::readImage(dir / ("toyseq/frame_000" + std::to_string(f) + ".exr")), avg)) << f;
    }
    test::expectCli(plugin + "denoise --sequence " + seq + " --method toyseq --toyseq-alpha 2 --out " + (dir / "bad"), 2,
                    {"--toyseq-alpha: must be in (0, 1] (got 2)"});
    test::expectCli(plugin + "denoise --sequence " + seq + " --method svgf --toyseq-alpha 0.5 --out " + (dir / "svgf"), 0,
                    {"ignored with --method svgf: --toyseq-alpha"});
    const test::CliResult missing = test::expectCli(" --plugin " + (dir / "nope.so") + " denoise --help", 2, {"nope.so"});
    EXPECT_EQ(std::count(missing.output.begin(), missing.output.end(), '\n'), 1) << missing.output;
    std::ofstream(dir / "junk.so") << "not a library";
    test::expectCli(" --plugin " + (dir / "junk.so") + " denoise --help", 2, {"junk.so: cannot load the plugin"});
}
#endif

}  // namespace
}  // namespace atrous

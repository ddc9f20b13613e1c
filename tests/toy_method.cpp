// The toy still method: the whole of what a new method is, one registry row plus its policy
// (tests/toy_policy.h). Linked into a program it is registered when the program starts; built as
// a plugin (ATROUS_TOY_PLUGIN) when the plugin is loaded.
#include "toy_method.h"

#include "core/parallel.h"
#include "cpu/atrous_rows.h"
#include "toy_policy.h"

namespace atrous::toy {

void toyCascade(const StillPlanes& p, const DenoiseOptions&, const ImageView& out) {
    const int w = p.color.width, h = p.color.height;
    Image tmp = Image::uninitialized(w, h, 3);
    const bool guided = p.albedo.valid();
    const ImageView guide{guided ? p.albedo.channel(1) : p.color.channel(1), w, h, 1};
    // Levels 1, 2, 4: colour -> out -> tmp -> out.
    const ImageView from[3] = {p.color, out, tmp.view()}, to[3] = {out, tmp.view(), out};
    for (int i = 0; i < 3; ++i) {
        ToyStop s;
        s.step_ = 1 << i;
        s.invSigma2 = guided ? 100.0f : 0.0f;
        s.in = from[i], s.guide = guide, s.out = to[i];
        cpu::runAtrousRows(s, cpuHasAvx512());
    }
}

void registerToy() {
    registerDenoiseMethod({DenoiseMethod::Eaw, "toy", "a toy: three levels of a cross-bilateral a-trous on the albedo (tests/toy_method.cpp)",
                           false, toyCascade});
}

DenoiseMethod toyMethod() { return parseDenoiseMethod("toy"); }

#if !defined(ATROUS_TOY_PLUGIN)
namespace {
// Linked into a program (atrous_toy, toy_method_test): registered when it starts.
const bool kRegistered = (registerToy(), true);
}  // namespace
#endif

}  // namespace atrous::toy

#if defined(ATROUS_TOY_PLUGIN)
// Built as a plugin (libatrous_toy_plugin.so): registered when loaded (atrous::loadPlugin).
extern "C" void atrous_plugin_register() {
    atrous::toy::registerToy();
    atrous::toy::registerToySequence();  // tests/toy_sequence_method.cpp
}
#endif

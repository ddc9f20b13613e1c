// The toy still method: the whole of what a new method is, one registry row plus its policy
// (tests/toy_policy.h). Registered when the program starts, before main.
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

namespace {
const DenoiseMethod kToy =
    registerDenoiseMethod({DenoiseMethod::Eaw, "toy", "a toy: three levels of a cross-bilateral a-trous on the albedo (tests/toy_method.cpp)",
                           false, toyCascade});
}  // namespace

DenoiseMethod toyMethod() { return kToy; }

}  // namespace atrous::toy

// RenderSettings' parameter table and validation, shared by the CPU and CUDA renderers, the CLI and
// Python: the table (renderParams(), atrous/render.h; the machinery: atrous/param_table.h) checks
// every field.
#include <iterator>

#include "atrous/param_table.h"
#include "atrous/render.h"

namespace atrous {

namespace {

using params_detail::at;
using R = RenderSettings;
// clang-format off
// threads: a ceiling, since tbb::task_arena aborts in its destructor from 65537 threads on
// (docs/reliability.md).
const ParamField<R> kRender[] = {
    {"width", &at<&R::width>, paramIn(1, kMaxImageDim), "image width in pixels"},
    {"height", &at<&R::height>, paramIn(1, kMaxImageDim), "image height in pixels"},
    {"spp", &at<&R::spp>, paramAtLeast(1), "samples per pixel"},
    {"seed", &at<&R::seed>, paramIn(0, 4294967295.0), "random seed (same seed, same image, whatever the thread count)"},
    {"first_sample", &at<&R::firstSample>, paramIn(0, 4294967295.0),
     "global index of the first sample (progressive accumulation: frame * spp)", "", ""},
    {"max_depth", &at<&R::maxDepth>, paramIn(0, 1024), "maximum bounces (0 = emitted light only, 1 = direct light)"},
    {"threads", &at<&R::threads>, paramIn(0, 4096), "worker threads (0 = all cores)"},
    {"light_sampling", &at<&R::lightSampling>, {},
     "next-event estimation with multiple importance sampling (else BSDF sampling only)", "", nullptr, true},
};
// clang-format on

}  // namespace

const ParamTable<RenderSettings>& renderParams() {
    static const ParamTable<RenderSettings> t{"render", "", kRender, std::size(kRender)};
    return t;
}

void validateRenderSettings(const RenderSettings& s) { validateParams(s, renderParams()); }

}  // namespace atrous

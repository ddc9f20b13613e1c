// RenderSettings' validation, shared by the CPU and CUDA renderers, the CLI and Python: the
// render parameter table (atrous/params.h, renderParams()) checks every field.
#include "atrous/params.h"
#include "atrous/render.h"

namespace atrous {

void validateRenderSettings(const RenderSettings& s) { validateParams(s, renderParams()); }

}  // namespace atrous

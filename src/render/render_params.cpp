// RenderSettings' validation, shared by the CPU and CUDA renderers, the CLI and Python.
#include <string>

#include "atrous/error.h"
#include "atrous/image.h"
#include "atrous/render.h"

namespace atrous {

void validateRenderSettings(const RenderSettings& s) {
    if (s.width <= 0 || s.width > kMaxImageDim)
        throw InputError("--width: " + std::to_string(s.width) + " is out of range (1.." + std::to_string(kMaxImageDim) + ")");
    if (s.height <= 0 || s.height > kMaxImageDim)
        throw InputError("--height: " + std::to_string(s.height) + " is out of range (1.." + std::to_string(kMaxImageDim) + ")");
    if (s.spp <= 0) throw InputError("--spp: must be at least 1 (got " + std::to_string(s.spp) + ")");
    if (s.maxDepth < 0 || s.maxDepth > 1024)
        throw InputError("--max-depth: " + std::to_string(s.maxDepth) + " is out of range (0..1024)");
    // A ceiling: tbb::task_arena aborts in its destructor from 65537 threads on (docs/reliability.md).
    constexpr int kMaxThreads = 4096;
    if (s.threads < 0 || s.threads > kMaxThreads)
        throw InputError("--threads: must be in 0..4096 (0 = all cores; got " + std::to_string(s.threads) + ")");
}

}  // namespace atrous

// No CUDA backend in this build: no CUDA-OpenGL interop (see cuda_display.h).
#include "view/cuda_display.h"

#if !defined(ATROUS_HAVE_CUDA)
namespace atrous::view {

std::unique_ptr<CudaGlDisplay> createCudaGlDisplay(unsigned, int, int, std::string& why) {
    why = "this build has no CUDA backend";
    return nullptr;
}

}  // namespace atrous::view
#endif

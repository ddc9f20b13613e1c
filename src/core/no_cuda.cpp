// Stand-ins for the CUDA backend in a build without nvcc: every entry point that would touch a GPU
// says so clearly instead of crashing.
#include "atrous/device.h"
#include "atrous/error.h"
#include "core/memory.h"
#include "core/strided.h"

namespace atrous {

bool cudaCompiled() { return false; }

namespace detail {

[[noreturn]] static void noCuda() { throw InputError("this build of atrous has no CUDA backend (nvcc was not found at build time)"); }

void* cudaAllocate(size_t) { noCuda(); }
void cudaRelease(void*) {}
void cudaCopy(void*, Device, const void*, Device, size_t) { noCuda(); }
void cudaFillFloats(float*, float, size_t) { noCuda(); }
bool cudaDevicePresent() { return false; }
std::string cudaDeviceName() { return "none (no CUDA backend)"; }
double cudaPeakBandwidthGBs() { return 0.0; }
void cudaImportStrided(const StridedImage&, const ImageView&) { noCuda(); }
void cudaExportStrided(const ImageView&, const StridedImage&) { noCuda(); }

}  // namespace detail
}  // namespace atrous

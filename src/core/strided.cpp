#include "core/strided.h"

#include <string>

#include "atrous/error.h"
#include "atrous/interop.h"
#include "core/parallel.h"

namespace atrous {

Image imageFromStrided(const StridedArray& a, int outChannels, const char* what) {
    if (!a.data) throw InputError(std::string(what) + ": no data");
    if (a.channels != 1 && a.channels != outChannels)
        throw InputError(std::string(what) + ": expected " + std::to_string(outChannels) + " channels (or 1), got " +
                         std::to_string(a.channels));
    // Every value is written below: no zero fill first.
    Image out = Image::uninitialized(a.width, a.height, outChannels, a.device);
    detail::GatherStrided f{a.data, a.strideY, a.strideX, a.strideC, a.channels, out.view()};
    if (a.device == Device::Cuda)
        detail::cudaGatherStrided(f, a.width, a.height);
    else if (a.channels == 3 && outChannels == 3 && a.strideX == 3 && a.strideC == 1)
        parallelForRowsCpu(a.height, detail::GatherInterleaved3{a.data, a.strideY, out.view()});
    else
        parallelFor2dCpu(a.width, a.height, f);
    return out;
}

void imageToInterleaved(const Image& img, float* dst) {
    detail::ScatterInterleaved f{img.view(), dst};
    if (img.device() == Device::Cuda)
        detail::cudaScatterInterleaved(f, img.width(), img.height());
    else if (img.channels() == 3)
        parallelForRowsCpu(img.height(), detail::ScatterInterleaved3{img.view(), dst});
    else
        parallelFor2dCpu(img.width(), img.height(), f);
}

}  // namespace atrous

// The CUDA halves of importImage / exportImage (src/core/strided.cpp): the functors of
// src/core/strided.h as kernels, with cuda_fp16's conversions.
#include "core/strided.h"
#include "cuda/cuda_exec.cuh"

namespace atrous::detail {

namespace {

// The functor of the image's element type, over width x height, finished before returning.
template <template <DataType> class F, class Src, class Dst>
void launch(DataType type, const Src& src, const Dst& dst, int width, int height) {
    CudaExec exec;
    if (type == DataType::Float16)
        exec.forEachPixel(width, height, F<DataType::Float16>{src, dst});
    else
        exec.forEachPixel(width, height, F<DataType::Float32>{src, dst});
    exec.synchronize();
}

}  // namespace

void cudaImportStrided(const StridedImage& src, const ImageView& dst) {
    launch<ImportStrided>(src.type, src, dst, dst.width, dst.height);
}

void cudaExportStrided(const ImageView& src, const StridedImage& dst) {
    launch<ExportStrided>(dst.type, src, dst, src.width, src.height);
}

}  // namespace atrous::detail

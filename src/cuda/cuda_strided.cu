// The CUDA halves of importImage / exportImage (src/core/strided.cpp): the functors of
// src/core/strided.h as kernels, with cuda_fp16's conversions.
#include "core/strided.h"
#include "cuda/cuda_exec.cuh"

namespace atrous::detail {

void cudaImportStrided(const StridedImage& src, const ImageView& dst) {
    CudaExec exec;
    if (src.type == DataType::Float16)
        exec.forEachPixel(dst.width, dst.height, ImportStrided<DataType::Float16>{src, dst});
    else
        exec.forEachPixel(dst.width, dst.height, ImportStrided<DataType::Float32>{src, dst});
    exec.synchronize();
}

void cudaExportStrided(const ImageView& src, const StridedImage& dst) {
    CudaExec exec;
    if (dst.type == DataType::Float16)
        exec.forEachPixel(src.width, src.height, ExportStrided<DataType::Float16>{src, dst});
    else
        exec.forEachPixel(src.width, src.height, ExportStrided<DataType::Float32>{src, dst});
    exec.synchronize();
}

}  // namespace atrous::detail

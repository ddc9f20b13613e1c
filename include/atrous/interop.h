// Moving pixels between atrous's planar images and images in other layouts (StridedImage,
// atrous/image.h: the C API's buffers, numpy / PyTorch / CuPy arrays: float32 or float16, 1 to 4
// channels, interleaved or planar, byte strides of any sign), on the host or on the GPU, without a
// round trip through host memory for GPU images.
#pragma once

#include "atrous/image.h"

namespace atrous {

// Copies `src` into a new planar float32 image on src.device with `outChannels` (1..4) channels: a
// 1-channel source is repeated into every output channel; otherwise src.channels must equal
// outChannels. Float16 elements are converted exactly (every half is a float). Throws InputError
// naming `what` for no data, a size or channel count out of range, a channel mismatch, or data or
// strides that are not multiples of the element's size.
Image importImage(const StridedImage& src, int outChannels, const char* what);

// Writes the planar image `src`, which lives on dst.device, into `dst`, the caller's output memory
// (StridedImage::data is written through): dst.channels of src's channels (src.channels >=
// dst.channels), same size. float16 outputs are rounded to nearest even, values beyond half's range
// clamped to +-65504. Throws InputError naming `what` when the sizes or devices differ, when dst is
// malformed (as importImage's) or when two of its elements would share memory (overlapping
// strides); nothing is written then.
void exportImage(const ImageView& src, const StridedImage& dst, const char* what);

// The layout of interleaved pixels of `channels` packed elements in rows of `rowBytes` bytes (0 =
// packed: width pixels), as a StridedImage over `data`.
StridedImage interleavedImage(const void* data, DataType type, int width, int height, int channels,
                              Device device = Device::Cpu, int64_t rowBytes = 0);

}  // namespace atrous

// Moving pixels between atrous's planar images and other libraries' interleaved arrays (numpy,
// PyTorch, CuPy: H x W x C with arbitrary strides), on the host or on the GPU, without a round
// trip through host memory for GPU arrays.
#pragma once
#include <cstdint>

#include "atrous/image.h"

namespace atrous {

// A borrowed H x W x C float32 array. Strides are in elements (not bytes) and may be anything,
// negative included. `device` says where `data` lives.
struct StridedArray {
    const float* data = nullptr;
    int height = 0, width = 0, channels = 0;
    int64_t strideY = 0, strideX = 0, strideC = 0;
    Device device = Device::Cpu;
};

// Copies `a` into a new planar image on a.device() with `outChannels` channels: a 1-channel
// array is repeated into every output channel; otherwise a.channels must equal outChannels.
// Throws InputError (naming `what`) on a shape mismatch.
Image imageFromStrided(const StridedArray& a, int outChannels, const char* what);

// Writes `img` as a C-contiguous H x W x C array into `dst`, which lives on img.device() and has
// room for img.size() floats.
void imageToInterleaved(const Image& img, float* dst);

}  // namespace atrous

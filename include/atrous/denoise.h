// Denoising API: EAW (Dammertz et al. 2010) and SURE-based À-Trous (Kim, Moon, Yoon 2016).
// OWNER: the denoiser work (issue 3) extends this header; the names below are used by the render
// command (`atrous render --denoise eaw,sure`) and must keep working.
#pragma once
#include <string>

#include "atrous/device.h"
#include "atrous/image.h"

namespace atrous {

enum class DenoiseMethod { Eaw, Sure };

// Per-pixel buffers, each a 3-channel planar Image of the colour's size (see ALGORITHMS.md 1).
// Only `color` is required; a missing feature simply removes its edge stop.
struct DenoiseInputs {
    const Image* color = nullptr;     // mean radiance, linear HDR
    const Image* variance = nullptr;  // variance of the mean, per channel
    const Image* albedo = nullptr;
    const Image* normal = nullptr;    // world-space unit normals (0 for background)
    const Image* position = nullptr;  // world-space hit points
    const Image* depth = nullptr;     // view depth repeated in R,G,B
    const Image* ids = nullptr;       // R = mesh id, G = material id, -1 for background
};

struct DenoiseOptions {
    DenoiseMethod method = DenoiseMethod::Sure;
    Device device = Device::Cpu;
    // Filter parameters are added by the denoiser work (EawParams, SureParams, firefly, ...).
};

// Denoises inputs.color and returns a 3-channel host image of the same size. Throws InputError
// for mismatched sizes, missing colour, negative variance or parameters out of range.
Image denoise(const DenoiseInputs& inputs, const DenoiseOptions& options);

DenoiseMethod parseDenoiseMethod(const std::string& name);  // "eaw" | "sure"; InputError otherwise
const char* denoiseMethodName(DenoiseMethod m);

}  // namespace atrous

// Where data lives and code runs.
#pragma once
#include <string>

namespace atrous {

enum class Device { Cpu, Cuda };

// True when this build has the CUDA backend and a usable GPU is present.
bool cudaAvailable();
// True when this build was compiled with the CUDA backend (a GPU may still be missing).
bool cudaCompiled();
// "cpu" / "cuda".
const char* deviceToString(Device d);
// Parses "cpu", "cuda" or "auto" (auto: cuda when available, else cpu). Throws ParamError
// (atrous/params.h, field "device") on any other word, or when "cuda" is asked for and
// cudaAvailable() is false.
Device parseDevice(const std::string& name);
// Human-readable name of the hardware behind `d`: the CPU model with its thread count, or the
// GPU's name. Used in benchmark JSON.
std::string deviceName(Device d);

}  // namespace atrous

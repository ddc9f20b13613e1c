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
// (atrous/error.h, field "device") on any other word, or when "cuda" is asked for and
// cudaAvailable() is false.
Device parseDevice(const std::string& name);
// Throws parseDevice("cuda")'s ParamError (field "device") unless cudaAvailable(): what every
// CUDA entry point calls first. noCudaBackend: the same error for a build without the backend
// (the stubs of CUDA-only entry points).
void requireCuda();
[[noreturn]] void noCudaBackend();
// Human-readable name of the hardware behind `d`: the CPU model with its thread count and the
// instruction set its row loops run (ATROUS_CPU_ISA, docs/development.md), or the GPU's name.
// Used in benchmark JSON.
std::string deviceName(Device d);
// The GPU's theoretical peak DRAM bandwidth in GB/s (memory clock x bus width x 2, from its device
// attributes), for benchmarks that compare achieved traffic with it; 0 without a GPU.
double cudaPeakBandwidthGBs();

}  // namespace atrous

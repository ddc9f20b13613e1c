#include "atrous/device.h"

#include <fstream>
#include <string>
#include <thread>

#include <tbb/info.h>

#include "atrous/error.h"
#include "core/memory.h"
#include "core/cpu_isa.h"

namespace atrous {

bool cudaAvailable() { return cudaCompiled() && detail::cudaDevicePresent(); }

const char* deviceToString(Device d) { return d == Device::Cuda ? "cuda" : "cpu"; }

void noCudaBackend() {
    throw ParamError("device", "device", "cannot be cuda: this build of atrous has no CUDA backend (nvcc was not found at build time)");
}

void requireCuda() {
    if (!cudaCompiled()) noCudaBackend();
    if (!detail::cudaDevicePresent()) throw ParamError("device", "device", "cannot be cuda: no CUDA-capable GPU is available");
}

Device parseDevice(const std::string& name) {
    if (name == "cpu") return Device::Cpu;
    if (name == "auto") return cudaAvailable() ? Device::Cuda : Device::Cpu;
    if (name == "cuda") {
        // ParamError naming the field `device`: the CLI shows its flag, Python its keyword.
        requireCuda();
        return Device::Cuda;
    }
    throw ParamError("device", "device", "must be cpu, cuda or auto", "'" + name + "'");
}

static std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("model name", 0) == 0) {
            auto pos = line.find(':');
            if (pos != std::string::npos) return line.substr(pos + 2);
        }
    }
    return "unknown CPU";
}

double cudaPeakBandwidthGBs() { return detail::cudaPeakBandwidthGBs(); }

std::string deviceName(Device d) {
    if (d == Device::Cuda) return detail::cudaDeviceName();
    return cpuModel() + " (" + std::to_string(tbb::info::default_concurrency()) + " threads, " + cpu::isaDescription() + ")";
}

}  // namespace atrous

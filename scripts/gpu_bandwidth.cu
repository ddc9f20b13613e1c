// Device-to-device copy bandwidth probe for scripts/gpu-check.sh (built by scripts/gpu-pack.sh with
// nvcc alone: static cudart, no other library). Prints one JSON object: the median of --runs timed
// cudaMemcpyAsync D2D copies of --mb MiB (CUDA events), as GB/s counting read + write (2 bytes of
// traffic per byte copied, as `achieved_gb_s` in `atrous bench` counts reads and writes), and the
// peak from the device attributes (memory clock x bus width x 2). Exit 3 without a CUDA device.
//   gpu_bandwidth [--mb 1024] [--runs 20]
#include <cuda_runtime.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

static int fail(const char* what, cudaError_t e) {
    std::printf("{\"error\": \"%s: %s\"}\n", what, cudaGetErrorString(e));
    return 3;
}

int main(int argc, char** argv) {
    size_t mb = 1024;
    int runs = 20;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--mb")) mb = size_t(std::atol(argv[i + 1]));
        else if (!std::strcmp(argv[i], "--runs")) runs = std::max(1, std::atoi(argv[i + 1]));
    }
    int n = 0;
    cudaError_t e = cudaGetDeviceCount(&n);
    if (e != cudaSuccess) return fail("cudaGetDeviceCount", e);
    if (n == 0) return fail("cudaGetDeviceCount", cudaErrorNoDevice);
    cudaDeviceProp p{};
    cudaGetDeviceProperties(&p, 0);
    int memClockKHz = 0, busBits = 0;
    cudaDeviceGetAttribute(&memClockKHz, cudaDevAttrMemoryClockRate, 0);
    cudaDeviceGetAttribute(&busBits, cudaDevAttrGlobalMemoryBusWidth, 0);
    const double peak = 2.0 * memClockKHz * 1e3 * (busBits / 8.0) / 1e9;
    const size_t bytes = mb << 20;
    void *a = nullptr, *b = nullptr;
    if ((e = cudaMalloc(&a, bytes)) != cudaSuccess || (e = cudaMalloc(&b, bytes)) != cudaSuccess)
        return fail("cudaMalloc", e);
    cudaMemset(a, 1, bytes);
    cudaMemset(b, 0, bytes);
    cudaEvent_t t0, t1;
    cudaEventCreate(&t0);
    cudaEventCreate(&t1);
    std::vector<double> gbs;
    for (int i = -3; i < runs; ++i) {  // three untimed warm-up copies
        cudaEventRecord(t0);
        cudaMemcpyAsync(b, a, bytes, cudaMemcpyDeviceToDevice);
        cudaEventRecord(t1);
        if ((e = cudaEventSynchronize(t1)) != cudaSuccess) return fail("cudaMemcpyAsync", e);
        float ms = 0;
        cudaEventElapsedTime(&ms, t0, t1);
        if (i >= 0) gbs.push_back(2.0 * double(bytes) / (ms * 1e-3) / 1e9);
    }
    std::sort(gbs.begin(), gbs.end());
    const double med = gbs[gbs.size() / 2];
    std::printf("{\"device_name\": \"%s\", \"cc\": \"%d.%d\", \"copy_mib\": %zu, \"runs\": %d, "
                "\"d2d_copy_gb_s_median\": %.1f, \"d2d_copy_gb_s_min\": %.1f, \"d2d_copy_gb_s_max\": %.1f, "
                "\"peak_gb_s\": %.1f, \"fraction_of_peak\": %.3f, "
                "\"note\": \"GB/s = 2 x bytes copied / time (read + write), median of timed D2D cudaMemcpyAsync\"}\n",
                p.name, p.major, p.minor, mb, runs, med, gbs.front(), gbs.back(), peak, peak > 0 ? med / peak : 0.0);
    cudaFree(a);
    cudaFree(b);
    return 0;
}

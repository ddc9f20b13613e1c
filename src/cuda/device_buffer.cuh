// Owner of a typed array in GPU memory (docs/architecture.md, principle 3).
// Allocation goes through detail::cudaAllocate / cudaRelease (src/cuda/cuda_memory.cu), the only
// place that calls cudaMalloc; copies through detail::cudaCopy, which checks every call.
#pragma once
#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "atrous/error.h"
#include "core/memory.h"

namespace atrous::cuda {

template <class T>
class DeviceBuffer {
    static_assert(std::is_trivially_copyable<T>::value, "DeviceBuffer holds plain data only");

public:
    DeviceBuffer() = default;
    explicit DeviceBuffer(size_t count) : mCount(count) {
        if (count) mData = static_cast<T*>(detail::cudaAllocate(count * sizeof(T)));
    }
    explicit DeviceBuffer(const std::vector<T>& host) : DeviceBuffer(host.size()) { upload(host.data(), host.size()); }
    ~DeviceBuffer() { detail::cudaRelease(mData); }
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;
    DeviceBuffer(DeviceBuffer&& o) noexcept : mData(std::exchange(o.mData, nullptr)), mCount(std::exchange(o.mCount, 0)) {}
    DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
        if (this != &o) {
            detail::cudaRelease(mData);
            mData = std::exchange(o.mData, nullptr);
            mCount = std::exchange(o.mCount, 0);
        }
        return *this;
    }

    // Copies `count` elements from host memory to the start of the buffer.
    void upload(const T* host, size_t count) {
        if (count > mCount)
            throw RuntimeError("DeviceBuffer: upload of " + std::to_string(count) + " elements into " +
                               std::to_string(mCount));
        if (count) detail::cudaCopy(mData, Device::Cuda, host, Device::Cpu, count * sizeof(T));
    }
    std::vector<T> download() const {
        std::vector<T> host(mCount);
        if (mCount) detail::cudaCopy(host.data(), Device::Cpu, mData, Device::Cuda, mCount * sizeof(T));
        return host;
    }

    T* data() { return mData; }
    const T* data() const { return mData; }
    size_t size() const { return mCount; }
    bool empty() const { return mCount == 0; }

private:
    T* mData = nullptr;
    size_t mCount = 0;
};

}  // namespace atrous::cuda

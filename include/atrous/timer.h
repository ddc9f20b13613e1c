// A steady-clock stopwatch and the median of a sample: what the library, the CLI and the benchmarks
// time with.
#pragma once
#include <algorithm>
#include <chrono>
#include <vector>

namespace atrous {

class Timer {
public:
    Timer() : mStart(std::chrono::steady_clock::now()) {}
    void reset() { mStart = std::chrono::steady_clock::now(); }
    double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - mStart).count(); }
    double ms() const { return seconds() * 1e3; }

private:
    std::chrono::steady_clock::time_point mStart;
};

// Median of a sample (by value: sorts a copy).
inline double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace atrous

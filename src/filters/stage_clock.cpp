// The CPU stage clock and the clock factory (see stage_clock.h).
#include "filters/stage_clock.h"

#include <chrono>
#include <string>

#include "atrous/error.h"

namespace atrous::filters {

namespace {

class CpuStageClock final : public StageClock {
public:
    void start() override {
        mCount = 0;
        mStart = Clock::now();
    }
    void mark(const char* name, int index) override {
        if (mCount >= kMaxMarks) return;
        mMarks[mCount++] = Mark{name, index, Clock::now()};
    }
    double collect(std::vector<StageTime>& out) override {
        out.clear();
        Clock::time_point prev = mStart;
        for (int i = 0; i < mCount; ++i) {
            const Mark& m = mMarks[i];
            StageTime t;
            t.name = m.index >= 0 ? std::string(m.name) + " " + std::to_string(m.index) : std::string(m.name);
            t.milliseconds = std::chrono::duration<double, std::milli>(m.time - prev).count();
            out.push_back(std::move(t));
            prev = m.time;
        }
        return std::chrono::duration<double, std::milli>(prev - mStart).count();
    }

private:
    using Clock = std::chrono::steady_clock;
    struct Mark {
        const char* name;
        int index;
        Clock::time_point time;
    };
    Clock::time_point mStart;
    Mark mMarks[kMaxMarks];
    int mCount = 0;
};

}  // namespace

std::unique_ptr<StageClock> makeStageClock(Device device) {
    if (device == Device::Cuda) return makeCudaStageClock();
    return std::make_unique<CpuStageClock>();
}

#if !defined(ATROUS_HAVE_CUDA)
std::unique_ptr<StageClock> makeCudaStageClock() {
    throw InputError("stage timing on cuda: this build of atrous has no CUDA backend");
}
#endif

}  // namespace atrous::filters

// The CUDA stage clock (see src/filters/stage_clock.h): one cudaEvent recorded on the default
// stream (CudaExec's) per mark, read after the run has synchronised. Events are created once and
// reused run after run (the SVGF pipeline keeps its clock), so a timed frame costs one
// cudaEventRecord per stage and no synchronisation until the driver's own final one.
#include <cuda_runtime.h>

#include <string>

#include "atrous/cuda_check.cuh"
#include "filters/stage_clock.h"

namespace atrous::filters {

namespace {

class CudaStageClock final : public StageClock {
public:
    ~CudaStageClock() override {
        // No check here: a destructor must not throw, and at exit the context may be gone.
        for (int i = 0; i < mCreated; ++i) cudaEventDestroy(mEvents[i]);
    }
    void start() override {
        mCount = 0;
        record(0);
    }
    void mark(const char* name, int index) override {
        if (mCount >= kMaxMarks) return;
        mNames[mCount] = name;
        mIndices[mCount] = index;
        ++mCount;
        record(mCount);
    }
    double collect(std::vector<StageTime>& out) override {
        out.clear();
        if (mCreated == 0) return 0.0;
        ATROUS_CUDA_CHECK(cudaEventSynchronize(mEvents[mCount]));
        double total = 0;
        for (int i = 0; i < mCount; ++i) {
            float ms = 0;
            ATROUS_CUDA_CHECK(cudaEventElapsedTime(&ms, mEvents[i], mEvents[i + 1]));
            StageTime t;
            t.name = mIndices[i] >= 0 ? std::string(mNames[i]) + " " + std::to_string(mIndices[i]) : std::string(mNames[i]);
            t.milliseconds = ms;
            total += ms;
            out.push_back(std::move(t));
        }
        return total;
    }

private:
    void record(int slot) {
        while (mCreated <= slot) ATROUS_CUDA_CHECK(cudaEventCreate(&mEvents[mCreated++]));
        ATROUS_CUDA_CHECK(cudaEventRecord(mEvents[slot], nullptr));
    }
    cudaEvent_t mEvents[kMaxMarks + 1] = {};
    const char* mNames[kMaxMarks] = {};
    int mIndices[kMaxMarks] = {};
    int mCreated = 0, mCount = 0;
};

}  // namespace

std::unique_ptr<StageClock> makeCudaStageClock() { return std::make_unique<CudaStageClock>(); }

}  // namespace atrous::filters

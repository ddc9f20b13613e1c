// Timestamps at the end of each stage of a filter driver (still_pipeline.h, svgf_pipeline.h),
// turned into per-stage milliseconds once the run has finished. The CPU clock reads the steady
// clock (the CPU executor's loops return when their work is done); the CUDA clock records a
// cudaEvent on the stream at each mark and reads the elapsed times after the driver's final
// synchronize, so timing adds no synchronisation inside the run. Virtual on purpose: the drivers
// stay templates on the executor only, and a null clock (timing off) costs one branch per stage.
#pragma once
#include <memory>
#include <vector>

#include "atrous/device.h"
#include "atrous/stage_time.h"

namespace atrous::filters {

class StageClock {
public:
    static constexpr int kMaxMarks = 64;  // more marks than this in one run are ignored

    virtual ~StageClock() = default;
    // Starts a run: forgets earlier marks and takes the reference time.
    virtual void start() = 0;
    // Ends the stage `name` (with `index` >= 0 appended, e.g. "level 2"). `name` must outlive the
    // run (a string literal); nothing is allocated here.
    virtual void mark(const char* name, int index = -1) = 0;
    // After the run's device work has finished: one entry per mark, in order. Returns the total
    // (start to last mark) in milliseconds.
    virtual double collect(std::vector<StageTime>& out) = 0;
};

inline void markStage(StageClock* clock, const char* name, int index = -1) {
    if (clock) clock->mark(name, index);
}

// A clock for work issued on `device` (CUDA: the default stream, where CudaExec launches).
std::unique_ptr<StageClock> makeStageClock(Device device);

// Defined in src/cuda/cuda_stage_clock.cu on CUDA builds (stage_clock.cpp otherwise: throws).
std::unique_ptr<StageClock> makeCudaStageClock();

}  // namespace atrous::filters

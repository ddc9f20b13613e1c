// Per-stage frame timings of the viewer averaged over the last frames: the timing table of the
// control panel (mean of the last ~30 frames, so the numbers hold still enough to read) and the
// medians of the --benchmark JSON line. Header-only, no GL.
#pragma once
#include <algorithm>
#include <deque>
#include <string>
#include <vector>

#include "atrous/stage_time.h"

namespace atrous::view {

class StageHistory {
public:
    explicit StageHistory(size_t window = 30) : mWindow(std::max<size_t>(1, window)) {}

    // One frame's stages, in display order. A different list of names (another method, level
    // count or split) starts the history afresh: means over mixed configurations mean nothing.
    void add(const std::vector<StageTime>& frame) {
        bool same = frame.size() == mNames.size();
        for (size_t i = 0; same && i < frame.size(); ++i) same = frame[i].name == mNames[i];
        if (!same) {
            mNames.clear();
            mSamples.assign(frame.size(), {});
            for (const StageTime& t : frame) mNames.push_back(t.name);
        }
        for (size_t i = 0; i < frame.size(); ++i) {
            std::deque<double>& d = mSamples[i];
            d.push_back(frame[i].milliseconds);
            if (d.size() > mWindow) d.pop_front();
        }
    }

    size_t size() const { return mNames.size(); }
    const std::string& name(size_t i) const { return mNames[i]; }
    size_t frames() const { return mSamples.empty() ? 0 : mSamples[0].size(); }
    double mean(size_t i) const {
        const std::deque<double>& d = mSamples[i];
        double s = 0;
        for (double v : d) s += v;
        return d.empty() ? 0.0 : s / double(d.size());
    }
    double median(size_t i) const {
        std::vector<double> v(mSamples[i].begin(), mSamples[i].end());
        if (v.empty()) return 0.0;
        std::sort(v.begin(), v.end());
        const size_t n = v.size();
        return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    }

private:
    size_t mWindow;
    std::vector<std::string> mNames;
    std::vector<std::deque<double>> mSamples;
};

}  // namespace atrous::view

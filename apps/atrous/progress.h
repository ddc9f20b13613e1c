// What the CLI prints, and where (docs/cli.md, "Output"): results, the lines a script parses, on
// stdout (resultLine()); everything else, notes and what was done, on stderr (logLine()); the stage times
// only with -v (verbose()); nothing but an error with --quiet. And a progress line on stderr
// for long CLI runs (`atrous render`): "render: frame 3/32, 41% (1 min 02 s, ETA 1 min 30 s)",
// redrawn in place once a second by a helper thread, only when stderr is a terminal (logs and
// tests see nothing) and --quiet was not given; sequences count frames (FrameCounter).
#pragma once
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>

#include "atrous/timer.h"

namespace atrous::cli {

inline bool stderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

// Erases the terminal's current line (a progress line drawn in place).
inline void eraseLine() {
    std::fputs("\r\033[K", stderr);
    std::fflush(stderr);
}

enum class Verbosity { Quiet, Normal, Verbose };
// The command's --quiet / -v (addVerbosityFlags); Normal unless given.
inline Verbosity& verbosity() {
    static Verbosity v = Verbosity::Normal;
    return v;
}
inline bool quiet() { return verbosity() == Verbosity::Quiet; }

// --quiet and -v,--verbose on a command (denoise, render, compare). No -q: on denoise it is
// oidnDenoise's --quality.
inline void addVerbosityFlags(CLI::App& cmd) {
    cmd.add_flag_callback("--quiet", [] { verbosity() = Verbosity::Quiet; },
                          "Print nothing on success (an error is still one line on stderr, exit status 2)");
    cmd.add_flag_callback("-v,--verbose", [] { verbosity() = Verbosity::Verbose; },
                          "Also print the stage times (on stderr)");
}

// A result line on stdout (what a script parses); nothing with --quiet. Flushed.
inline void resultLine(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
inline void resultLine(const char* fmt, ...) {
    if (quiet()) return;
    va_list ap;
    va_start(ap, fmt);
    std::vprintf(fmt, ap);
    va_end(ap);
    std::fflush(stdout);
}

// A log line on stderr (notes, what was done); nothing with --quiet.
inline void logLine(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
inline void logLine(const char* fmt, ...) {
    if (quiet()) return;
    va_list ap;
    va_start(ap, fmt);
    std::vfprintf(stderr, fmt, ap);
    va_end(ap);
}

// A line on stderr with -v only (stage times).
inline void verbose(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
inline void verbose(const char* fmt, ...) {
    if (verbosity() != Verbosity::Verbose) return;
    va_list ap;
    va_start(ap, fmt);
    std::vfprintf(stderr, fmt, ap);
    va_end(ap);
}

// "42 s", "3 min 05 s", "1 h 02 min".
inline std::string durationText(double seconds) {
    char buf[48];
    const long s = long(seconds + 0.5);
    if (s < 60)
        std::snprintf(buf, sizeof(buf), "%ld s", s);
    else if (s < 3600)
        std::snprintf(buf, sizeof(buf), "%ld min %02ld s", s / 60, s % 60);
    else
        std::snprintf(buf, sizeof(buf), "%ld h %02ld min", s / 3600, (s / 60) % 60);
    return buf;
}

// "denoise: frame 3/24 (2 s, ETA 14 s)" on stderr as each frame of a sequence is done: redrawn in
// place on a terminal, one line per frame otherwise (logs); nothing when disabled (--quiet). Called
// from one thread (the sequence session's events).
class FrameCounter {
public:
    FrameCounter(std::string label, bool enabled) : mLabel(std::move(label)), mEnabled(enabled), mTty(stderrIsTerminal()) {}
    ~FrameCounter() { finish(); }
    FrameCounter(const FrameCounter&) = delete;
    FrameCounter& operator=(const FrameCounter&) = delete;

    // Runs print() with the counter cleared, then draws it again (a terminal).
    template <class F>
    void above(F&& print) {
        clear();
        print();
        std::fflush(stdout);
        if (mTty && !mLine.empty()) draw();
    }

    // The k-th of n frames is done (1-based).
    void frameDone(int k, int n) {
        if (!mEnabled || k < 1 || n < 1) return;
        const double elapsed = mTimer.seconds();
        mLine = mLabel + ": frame " + std::to_string(k) + "/" + std::to_string(n) + " (" + durationText(elapsed) +
                (k < n ? ", ETA " + durationText(elapsed / k * (n - k)) : std::string()) + ")";
        draw();
    }

    // Clears the line on a terminal (idempotent).
    void finish() {
        clear();
        mLine.clear();
    }

private:
    void draw() {
        if (!mEnabled) return;
        std::fputs(((mTty ? "\r\033[K" : "") + mLine + (mTty ? "" : "\n")).c_str(), stderr);
        std::fflush(stderr);
        mShown = mTty;
    }
    void clear() {
        if (mShown) eraseLine();
        mShown = false;
    }

    const std::string mLabel;
    const bool mEnabled, mTty;
    std::string mLine;
    bool mShown = false;
    Timer mTimer;
};

class ProgressLine {
public:
    // `total`: work units of the whole run (samples: pixels x spp summed over every render);
    // `frames` > 0: a sequence, shown as "frame f/frames". The first line is drawn at once (a
    // short run still shows one), then the helper thread redraws it every second.
    ProgressLine(bool enabled, std::string label, uint64_t total, int frames = 0)
        : mEnabled(enabled && total > 0), mLabel(std::move(label)), mTotal(total), mFrames(frames) {
        if (!mEnabled) return;
        {
            std::lock_guard<std::mutex> lock(mMutex);
            drawLocked();
        }
        mThread = std::thread([this] { loop(); });
    }
    ~ProgressLine() { finish(); }
    ProgressLine(const ProgressLine&) = delete;
    ProgressLine& operator=(const ProgressLine&) = delete;

    // The counter to hand to RenderSettings::samplesDone; nullptr when the line is off, so the
    // renderer does no atomic adds at all then.
    std::atomic<uint64_t>* counter() { return mEnabled ? &mDone : nullptr; }

    // Sequences: the frame being rendered now (0-based).
    void setFrame(int frame) { mFrame.store(frame, std::memory_order_relaxed); }

    // Runs print() (stdout lines) with the progress line cleared; the next tick redraws it.
    template <class F>
    void above(F&& print) {
        std::lock_guard<std::mutex> lock(mMutex);
        clearLocked();
        print();
        std::fflush(stdout);
    }

    // Stops the helper thread and clears the line (idempotent).
    void finish() {
        {
            std::lock_guard<std::mutex> lock(mMutex);
            if (mStop) return;
            mStop = true;
            clearLocked();
        }
        mWake.notify_all();
        if (mThread.joinable()) mThread.join();
    }

private:
    void loop() {
        std::unique_lock<std::mutex> lock(mMutex);
        while (!mStop) {
            mWake.wait_for(lock, std::chrono::seconds(1), [this] { return mStop; });
            if (!mStop) drawLocked();
        }
    }

    void drawLocked() {
        const double frac = std::min(1.0, double(mDone.load(std::memory_order_relaxed)) / double(mTotal));
        const double elapsed = mTimer.seconds();
        std::string line = "\r\033[K" + mLabel + ": ";
        if (mFrames > 0)
            line += "frame " + std::to_string(mFrame.load(std::memory_order_relaxed) + 1) + "/" + std::to_string(mFrames) + ", ";
        char pct[16];
        std::snprintf(pct, sizeof(pct), "%.0f%%", frac * 100.0);
        line += std::string(pct) + " (" + durationText(elapsed);
        // The ETA extrapolates the mean rate so far; below 1% it would be noise.
        line += frac >= 0.01 ? ", ETA " + durationText(elapsed * (1.0 - frac) / frac) + ")" : ", ETA --)";
        std::fputs(line.c_str(), stderr);
        std::fflush(stderr);
        mShown = true;
    }

    void clearLocked() {
        if (mShown) eraseLine();
        mShown = false;
    }

    const bool mEnabled;
    const std::string mLabel;
    const uint64_t mTotal;
    std::atomic<uint64_t> mDone{0};
    const int mFrames;
    std::atomic<int> mFrame{0};
    Timer mTimer;
    std::mutex mMutex;
    std::condition_variable mWake;
    bool mStop = false, mShown = false;
    std::thread mThread;  // last: started once every other member exists
};

}  // namespace atrous::cli

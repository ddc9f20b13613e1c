// The methods that denoise a sequence as a sequence (temporal, svgf, a plugin's), beside the still
// methods of atrous/denoise.h: one registry row each, with its parameter table, what it reads and
// a factory of stateful denoisers, one per stream of frames. Every front-end drives them through
// the one interface below (SequenceDenoiser: frames pushed in order, denoised frames handed back
// in order), and none names a method: the CLI's --method, its flags and notes, `atrous bench`,
// the viewer's list, the sequence session (atrous/sequence.h), Python and the farm read the rows.
// docs/architecture.md, "Where a new piece goes", says how to add one (tests/toy_sequence_method.cpp
// is one, built from the installed headers).
#pragma once
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "atrous/buffers.h"
#include "atrous/denoise.h"
#include "atrous/device.h"
#include "atrous/image.h"
#include "atrous/param_set.h"
#include "atrous/stage_time.h"

namespace atrous {

// One frame handed to a sequence method: its buffers (a Frame, atrous/buffers.h) and what keeps
// them alive. A method that reads a frame after push() returned (a window of frames) holds
// `owner` until it is done with it; the caller changes none of the buffers meanwhile. A null
// owner is the caller's word that the buffers outlive the denoiser (or its next reset()).
struct SequenceInput {
    Frame buffers;
    std::shared_ptr<const void> owner;
};

// One denoised frame and what the method did.
struct SequenceOutput {
    size_t index = 0;         // its place in the stream: 0 = the first frame pushed since reset()
    Image image;              // 3 channels, linear HDR; on the host unless SequenceSetup::keepOnDevice
    std::string methodUsed;   // the still method that ran (auto resolved: "blend"), else the method's name
    // What the report line says after the method's name: " (+-3 frames, 3.8 averaged per pixel in
    // 6 ms; then auto -> blend)", " -> sure", " (learned spatial)", "".
    std::string detail;
    std::vector<StageTime> stages;  // the filter's stages (with SequenceSetup::timing)
};

// What a sequence method is made with (SequenceMethodInfo::make, makeSequenceDenoiser).
struct SequenceSetup {
    Device device = Device::Cpu;
    // The method's parameters: a set of its row's table (SequenceMethodInfo::params) holding the
    // caller's values; empty = the row's defaults.
    ParamSet params;
    // A still method's options: the one a row with `stillMethod` ends with (method: the CLI's
    // --spatial, Python's spatial=), or those of a still method run on each frame alone. Their
    // weights are also the learned weights of a row whose parameters read them (weightsParam).
    DenoiseOptions still;
    bool causal = false;        // a row with causalMode runs in it: each frame from those before it only
    // The frames' motion vectors are the renderer's own; false when they are fitted to positions or
    // estimated from colours, which see a moving object as still (temporal's static window is off).
    bool motionGiven = true;
    bool timing = false;        // SequenceOutput::stages
    bool keepOnDevice = false;  // with Device::Cuda, results stay on the GPU (the viewer's display)
};

// A stateful denoiser of one stream of frames. Frames are pushed in order; frame t comes out of
// next(), in order, once lookahead() frames after it are in (or finish() says there are no
// more). Frame t is denoised from the window of frames t - lookbehind() .. t + lookahead() (clipped
// to the stream) and, for a method with history, from what it carried over. Not thread-safe.
//
// A method implements denoise() (and check(), restart() where it needs them); the window,
// the order, skipping and the buffers left out are this class's.
class SequenceDenoiser {
public:
    // lookbehind, lookahead: the frames before and after t that frame t's window holds; reads:
    // the buffers this denoiser reads (its row's, less what its parameters leave unread).
    SequenceDenoiser(int lookbehind, int lookahead, BufferMask reads);
    virtual ~SequenceDenoiser();
    SequenceDenoiser(const SequenceDenoiser&) = delete;
    SequenceDenoiser& operator=(const SequenceDenoiser&) = delete;

    int lookbehind() const { return mLookbehind; }
    int lookahead() const { return mLookahead; }
    BufferMask reads() const { return mReads; }

    // The next frame. It is checked now (InputError naming the buffer, nothing kept then) and
    // denoised by a later next(). InputError after finish() (reset() starts a new stream).
    void push(SequenceInput frame);
    // Whether next() (or skip()) has a frame: lookahead() frames after it are in, or finish() was called.
    bool ready() const;
    // The next frame in order, denoised. InputError when none is ready; a method's InputError
    // (a bad buffer) leaves the frame to come out again.
    SequenceOutput next();
    // Passes the next ready frame over without denoising it (a caller that wants some frames
    // only); it stays in its neighbours' windows. A method with history misses it.
    void skip();
    // No more frames: those left come out without the later neighbours they would have had.
    void finish();
    // Forgets every frame, the method's history and ignore(): the next push starts a new stream.
    void reset();
    // From now on buffer b is left out of every frame, the frames already pushed included (a stream
    // that finds a buffer unreliable: ids that change from frame to frame).
    void ignore(Buffer b);
    size_t pushed() const { return mPushed; }  // frames pushed since reset()

protected:
    // Each frame as it is pushed (sizes, channels, values): InputError naming the buffer.
    virtual void check(const Frame& frame);
    // Denoises window[center]: the frames center - lookbehind .. center + lookahead of the stream
    // (fewer at its ends), `ids` their places in it (the same frame keeps its id while it is held).
    virtual SequenceOutput denoise(const std::vector<Frame>& window, size_t center, const std::vector<long long>& ids) = 0;
    // reset()'s part in the method: its history.
    virtual void restart();

private:
    struct Held {
        long long index;
        SequenceInput input;
    };
    int mLookbehind, mLookahead;
    BufferMask mReads, mIgnored;
    std::deque<Held> mHeld;  // the frames a window still needs, oldest first
    size_t mPushed = 0, mNext = 0;
    bool mFinished = false;
    Frame visible(const Frame& f) const;  // f without the ignored buffers
    void release();                       // drops the frames no later window reads
};

using SequenceFactory = std::function<std::unique_ptr<SequenceDenoiser>(const SequenceSetup& setup)>;

// One row of the sequence methods' registry.
struct SequenceMethodInfo {
    const char* name = nullptr;     // "temporal": the CLI's --method, Python's method=
    const char* label = nullptr;    // in prose and headings ("SVGF"): help groups, the viewer's sections
    const char* summary = nullptr;  // one line: the CLI's help
    bool causal = false;            // each frame from the frames before it only (real time, the viewer)
    // Not causal itself, but has a causal mode (SequenceSetup::causal), which a viewer runs.
    bool causalMode = false;
    // Carries state from frame to frame (SVGF's history): a stream must see every frame, in order.
    // Without it (temporal) a frame depends on its window only, so frames can be denoised apart
    // (the farm's items, skip()).
    bool history = false;
    // Ends with a still method of the caller's choice (SequenceSetup::still: the CLI's --spatial);
    // the still methods' parameters then apply.
    bool stillMethod = false;
    // Its parameter table with the defaults; empty: none. The CLI's flags are the table's
    // (--<prefix><name>), Python's keywords its rows' names.
    ParamSet params;
    // A Bool row of `params` that makes it read the learned filter's weights (svgf's
    // learned_spatial); null: it never reads them (but through its still method).
    const char* weightsParam = nullptr;
    BufferMask reads;  // the frame's buffers it reads; colour always
    // For messages: how it uses other frames ("SVGF carries its history from one frame to the
    // next"), and what it does with frames that have no motion vectors.
    const char* acrossFrames = nullptr;
    const char* withoutMotion = nullptr;
    SequenceFactory make;
    bool registered = false;  // added by registerSequenceMethod (the built-in rows: false)
};

// The rows in order: temporal (the --sequence default), svgf, then the registered methods. The
// references stay valid while the program runs.
const std::deque<SequenceMethodInfo>& sequenceMethods();
const SequenceMethodInfo* findSequenceMethod(const std::string& name);  // null when unknown
std::string sequenceMethodNames();  // "temporal, svgf"
// Adds a sequence method (a plugin's, a program's): a new name (letters, digits, '_' or '-'; no
// still method's either, nor none, noisy or oidn), a factory, and weightsParam a Bool row of its
// params when given; the strings are copied. Call it before the method is used (it is not
// synchronised with running denoisers). InputError for a taken or malformed name or no factory.
const SequenceMethodInfo& registerSequenceMethod(SequenceMethodInfo info);

// A denoiser of the method `name`: a row of sequenceMethods() (setup.params a set of its table, or
// empty for its defaults), or a still method (denoiseMethods()) run on each frame alone with
// setup.still (its method set by the name; its report line " -> blend" when auto). Validates the
// parameters: InputError (ParamError naming the field) for a bad one, or for an unknown name.
std::unique_ptr<SequenceDenoiser> makeSequenceDenoiser(const std::string& name, const SequenceSetup& setup);

// Whether a row's parameters make it read the learned weights (its weightsParam row is true).
bool sequenceMethodReadsWeights(const SequenceMethodInfo& method, const ParamSet& params);

}  // namespace atrous

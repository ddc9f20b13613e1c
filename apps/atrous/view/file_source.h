// What `atrous view --in` and `atrous view --sequence` open (docs/viewer.md, "Your render"): one
// still read as `atrous denoise --in` reads it, or the frames of a sequence as `atrous denoise
// --sequence` lists them (io/sequence.h), each loaded when it is shown. No GL.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "atrous/io/buffer_set.h"
#include "atrous/io/sequence.h"
#include "input_flags.h"
#include "still_output.h"

namespace atrous::view {

class FileSource {
  public:
    // A still (input.any(), no sequence) or a sequence (a folder or a pattern; input only its
    // --pass and --layer). The frames are listed and checked now; InputError naming the file or
    // flag and the problem otherwise (a JSON scene given as a render included).
    FileSource(const cli::InputFlags& input, const std::string& sequence, const io::FrameRange& range);

    bool isSequence() const { return !mSequence.empty(); }
    int frameCount() const { return int(mFrames.size()); }
    int current() const { return mCurrent; }
    // What the window's title and the panel name: the file or folder, and the frame's number.
    std::string title() const;
    std::string frameName(int k) const;

    // Reads frame k (0-based) and makes it the current one. InputError naming the file and the
    // problem (a still's colour with no finite pixel too, as `atrous denoise` refuses it).
    io::BufferSet load(int k);

    // The flags with which `atrous denoise` reads the current frame alone (" --in FRAME ...",
    // quoted): the still's own flags; a sequence's frame folder or layered file (with --pass and
    // --layer), or its per-buffer files.
    std::string denoiseInput() const;
    // The still's extras (alpha, LDR) as `atrous denoise` applies them to its output; null for a
    // sequence's frame.
    const cli::StillExtras* extras() const { return isSequence() ? nullptr : &mExtras; }

  private:
    cli::InputFlags mInput;
    std::string mSequence;
    std::vector<std::string> mFrames;    // a sequence's frames (folders or files); one "" for a still
    std::vector<std::string> mExpected;  // the buffers every frame has (validateSequence)
    io::SequenceOptions mOptions;
    int mCurrent = -1;
    std::string mFiles[10];              // the current sequence frame's file per kSequenceBuffers entry
    cli::StillExtras mExtras;
};

}  // namespace atrous::view

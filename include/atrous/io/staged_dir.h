// An output folder written as a whole (docs/reliability.md): its files are built in a hidden
// sibling folder and moved into place only when every one is done, so bad input that only
// decoding finds (a truncated EXR in frame 40) leaves the folder as it was.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace atrous::io {

class StagedDir {
public:
    // Makes the staging folder beside `outDir` (in its parent, so that the final rename stays on
    // one file system). InputError (naming `flag`) when outDir is a file, not writable, or cannot
    // be made.
    StagedDir(const std::string& flag, const std::string& outDir);
    // Removes the staging folder, and any parent folders it made, unless committed.
    ~StagedDir();
    StagedDir(const StagedDir&) = delete;
    StagedDir& operator=(const StagedDir&) = delete;

    std::string stage() const { return mStage.string(); }

    // Moves the staged files into outDir. An absent or empty outDir is replaced by the staging
    // folder in one rename. A non-empty one keeps its other files; this run's files replace those
    // of the same name, and the frame_NNNN.exr/.png (and preview.mp4) of an earlier run that this
    // run did not write are removed. Returns a line naming them ("" when none). RuntimeError when a
    // file cannot be moved.
    std::string commit();

private:
    std::filesystem::path mOut, mStage, mCreatedParent;
    bool mCommitted = false;
};

// Full path of an executable named `name` on PATH, or "" when there is none.
std::string findOnPath(const std::string& name);
// `s` single-quoted for std::system's shell (ffmpeg's command lines).
std::string shellQuote(const std::string& s);

}  // namespace atrous::io

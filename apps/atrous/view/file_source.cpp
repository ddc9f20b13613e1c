// The renders `atrous view` opens (file_source.h).
#include "view/file_source.h"

#include <filesystem>
#include <utility>

#include "atrous/error.h"
#include "atrous/io/image_io.h"
#include "atrous/io/pass_map.h"
#include "cli_flags.h"

namespace atrous::view {

namespace {

// A path that names a JSON scene: refused as a render with a word on what to do instead.
void refuseScene(const std::string& flag, const std::string& path) {
    if (io::extensionOf(path) == ".json")
        throw InputError(path + ": a JSON scene, not a render (" + flag + " opens renders): open it with --scene " + path);
}

// A buffer's name among a sequence frame's files (kSequenceBuffers, SequenceFrame::fileOf): the
// library's name, "ids" for the object ids.
std::string frameBufferName(int b) {
    return b == int(io::Buffer::ObjectId) ? "ids" : io::bufferName(io::Buffer(b));
}

}  // namespace

FileSource::FileSource(const cli::InputFlags& input, const std::string& sequence, const io::FrameRange& range)
    : mInput(input), mSequence(sequence) {
    if (!isSequence()) {
        if (mInput.in.empty() == mInput.file[int(io::Buffer::Color)].empty())
            throw InputError("give exactly one of --in RENDER_DIR, --in LAYERED.exr or --color FILE (--hdr)");
        refuseScene("--in", mInput.in);
        refuseScene("--color", mInput.file[int(io::Buffer::Color)]);
        mFrames.push_back("");
        return;
    }
    refuseScene("--sequence", sequence);
    std::string given;
    for (int b = 0; b < io::kBufferCount; ++b)
        if (!mInput.file[b].empty()) given += (given.empty() ? "" : ", ") + std::string(cli::bufferFlag(io::Buffer(b)));
    if (!mInput.in.empty()) given = "--in" + (given.empty() ? "" : ", " + given);
    if (!given.empty())
        throw InputError(given + ": a sequence's frames bring their own buffers (--sequence DIR); drop " +
                         (given.find(',') == std::string::npos ? "it" : "them"));
    mOptions.passes = cli::withFlag("--pass", [&] { return io::parsePassRequests(mInput.passes); });
    mOptions.viewLayer = mInput.layer;
    mFrames = io::listSequenceFrames(sequence, range);
    int w = 0, h = 0;
    mExpected = io::validateSequence(mFrames, w, h, mOptions);
}

std::string FileSource::frameName(int k) const {
    if (!isSequence()) return mInput.in.empty() ? mInput.file[int(io::Buffer::Color)] : mInput.in;
    return std::filesystem::path(mFrames[size_t(k)]).filename().string();
}

std::string FileSource::title() const {
    if (!isSequence()) return frameName(0);
    return mSequence + ": " + frameName(mCurrent) + " (" + std::to_string(mCurrent + 1) + " of " +
           std::to_string(frameCount()) + ")";
}

io::BufferSet FileSource::load(int k) {
    if (k < 0 || k >= frameCount()) throw InputError("view: no frame " + std::to_string(k + 1));
    io::BufferSet set;
    if (!isSequence()) {
        const io::BufferFiles files = cli::bufferFiles(mInput);
        set = io::loadBuffers(files);
        mExtras = cli::readStillExtras(files, set, false);
    } else {
        io::SequenceFrame f = io::loadSequenceFrame(mFrames[size_t(k)], mExpected, mOptions);
        const std::pair<io::Buffer, Image*> slots[] = {
            {io::Buffer::Color, &f.color},       {io::Buffer::Albedo, &f.albedo}, {io::Buffer::Normal, &f.normal},
            {io::Buffer::Position, &f.position}, {io::Buffer::Depth, &f.depth},   {io::Buffer::ObjectId, &f.ids},
            {io::Buffer::Motion, &f.motion},     {io::Buffer::Emission, &f.emission}, {io::Buffer::Variance, &f.variance}};
        for (auto& [b, img] : slots) set.image[int(b)] = std::move(*img);
        for (int i = 0; i < 10; ++i) mFiles[i] = f.files[i];
        for (int b = 0; b < io::kBufferCount; ++b)
            if (!set.image[b].empty()) set.from[b] = f.fileOf(frameBufferName(b));
        set.layered = f.layered;
    }
    mCurrent = k;
    return set;
}

std::string FileSource::denoiseInput() const {
    if (!isSequence()) return cli::inputCommandLine(mInput);
    const std::string& frame = mFrames[size_t(mCurrent)];
    cli::InputFlags f;
    if (std::filesystem::is_directory(frame) || io::isLayeredSequenceFrame(frame)) {
        f.in = frame;
        f.passes = mInput.passes;
        f.layer = mInput.layer;
    } else {
        // Numbered files per buffer in one folder: each buffer's file by its own flag.
        for (int i = 0; i < 10; ++i)
            for (int b = 0; b < io::kBufferCount && !mFiles[i].empty(); ++b) {
                if (frameBufferName(b) == io::kSequenceBuffers[i] && *cli::bufferFlag(io::Buffer(b))) f.file[b] = mFiles[i];
            }
    }
    return cli::inputCommandLine(f);
}

}  // namespace atrous::view

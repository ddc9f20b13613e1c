// The viewer's "write image + command" (the O key, the panel's button, headless --write-image):
// the displayed result of method A as OUT/view_NNNN.exr and .png, and the `atrous denoise`
// command that makes the same image from the same files (the method, every still parameter that
// differs from its default, the device), printed and written beside them as view_NNNN.txt. No GL.
#pragma once
#include <string>

#include "atrous/denoise.h"
#include "atrous/view_pipeline.h"
#include "view/file_source.h"

namespace atrous::view {

// The `atrous denoise` command for still method `method` with options `o` on the input flags
// `input` (FileSource::denoiseInput()), on `device`, writing `out`. Parameters that no flag can set
// to their value are named in *unset (empty when there are none).
std::string denoiseCommand(const std::string& method, const DenoiseOptions& o, const std::string& input,
                           const std::string& device, const std::string& out, std::string* unset);

struct WrittenResult {
    std::string exr, png, txt;  // the files written
    std::string command;        // the equivalent command, or "" (then `note` says why)
    std::string note;
};

// Writes slot A's result of the last step (the noisy colour for "none") into outDir (created when
// missing) under the first free view_NNNN name. `files`: the render shown (null: a built-in or
// JSON scene, which has no such command); `device`: the viewer's --device. Throws InputError or
// RuntimeError naming the file when it cannot be written.
WrittenResult writeResult(const ViewPipeline& pl, const PipelineSettings& ps, const FileSource* files,
                          const std::string& device, const std::string& outDir);

}  // namespace atrous::view

// Alpha passed through (include/atrous/io/alpha.h, docs/inputs.md "Alpha").
#include "atrous/io/alpha.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <utility>

#include "atrous/error.h"
#include "atrous/io/buffer_set.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"
#include "atrous/io/sequence.h"

namespace fs = std::filesystem;

namespace atrous::io {

namespace {

std::string sizeText(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// The layer the colour of an EXR is read from: a plain image's root (readImage's rule: R,G,B, or Y,
// or its only channel), else the colour pass as loadBuffers picks it: mapPasses for `--in FILE`,
// passForFile for a file given as the colour alone (`--color FILE`). -1 when there is none.
int colourLayer(const ExrInfo& info, const std::vector<PassRequest>& passes, const std::string& viewLayer, bool alone) {
    const bool plain = info.layers.size() == 1 && info.layers[0].name.empty();
    if (plain && passes.empty()) return 0;
    return alone ? passForFile(info, Buffer::Color, passes, viewLayer).layer : mapPasses(info, passes, viewLayer)[Buffer::Color].layer;
}

Image exrAlpha(const std::string& path, const std::vector<PassRequest>& passes, const std::string& viewLayer,
               int width, int height, bool alone) {
    const ExrInfo info = inspectExr(path);
    const int layer = colourLayer(info, passes, viewLayer, alone);
    if (layer < 0) return {};
    const ExrLayer& l = info.layers[size_t(layer)];
    int channel = -1;
    for (size_t k = 0; k < l.components.size(); ++k)
        if (l.components[k] == "A" || l.components[k] == "a") channel = l.channels[k];
    if (channel < 0) return {};
    const ExrChannelInfo& ch = info.channels[size_t(channel)];
    if (ch.xSampling != 1 || ch.ySampling != 1) {
        // Stored at 1/xSampling x 1/ySampling of the image: not a value per pixel of the colour.
        const int w = (info.width + ch.xSampling - 1) / std::max(ch.xSampling, 1);
        const int h = (info.height + ch.ySampling - 1) / std::max(ch.ySampling, 1);
        throw InputError(path + ": alpha channel '" + ch.fullName + "' is " + sizeText(w, h) + " (subsampled " +
                         std::to_string(ch.xSampling) + "x" + std::to_string(ch.ySampling) + ") but the colour is " +
                         sizeText(width >= 0 ? width : info.width, height >= 0 ? height : info.height) +
                         ": atrous passes an alpha of the colour's size through, one value per pixel");
    }
    return std::move(readExrChannelSets(info, {{channel}}, {"alpha channel '" + ch.fullName + "'"}, {1})[0]);
}

Image alphaOf(const std::string& path, const std::vector<PassRequest>& passes, const std::string& viewLayer, int width,
              int height, bool alone) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return {};  // readImage has said what is wrong with it
    Image a = isExrFile(path)     ? exrAlpha(path, passes, viewLayer, width, height, alone)
              : isLdrFormat(path) ? readStbAlpha(path)
                                  : Image();
    if (!a.empty() && width >= 0 && (a.width() != width || a.height() != height))
        throw InputError(path + ": alpha channel is " + sizeText(a.width(), a.height()) + " but the colour is " +
                         sizeText(width, height));
    return a;
}

}  // namespace

Image readAlpha(const std::string& path, const std::vector<PassRequest>& passes, const std::string& viewLayer, int width,
                int height) {
    return alphaOf(path, passes, viewLayer, width, height, false);
}

Image readAlpha(const BufferFiles& files, int width, int height, std::string* from) {
    std::string path = files.file[int(Buffer::Color)];
    const bool alone = !path.empty();  // a colour file given for itself: passForFile's pass when it is layered
    bool layered = alone;
    std::error_code ec;
    if (path.empty() && !files.in.empty()) {
        layered = !fs::is_directory(files.in, ec);
        path = layered ? files.in : dirBufferFile(files.in, "color");
    }
    if (from) *from = path;
    if (path.empty()) return {};
    return alphaOf(path, layered ? files.passes : std::vector<PassRequest>{}, layered ? files.viewLayer : std::string(),
                   width, height, alone);
}

Image readFrameAlpha(const SequenceFrame& frame, const SequenceOptions& options) {
    const std::string path = frame.files[0].empty() ? frame.dir : frame.files[0];
    const bool layered = isLayeredSequenceFrame(frame.dir);
    return alphaOf(path, layered ? options.passes : std::vector<PassRequest>{}, layered ? options.viewLayer : std::string(),
                   frame.color.width(), frame.color.height(), false);
}

Image withAlpha(Image rgb, const Image& alpha) {
    if (alpha.empty()) return rgb;
    if (alpha.width() != rgb.width() || alpha.height() != rgb.height())
        throw InputError("alpha channel is " + sizeText(alpha.width(), alpha.height()) + " but the colour is " +
                         sizeText(rgb.width(), rgb.height()));
    if (rgb.device() != Device::Cpu) rgb = rgb.to(Device::Cpu);
    Image out = Image::uninitialized(rgb.width(), rgb.height(), 4);
    const size_t n = rgb.plane();
    for (int k = 0; k < 3; ++k) {
        const float* src = rgb.data() + size_t(std::min(k, rgb.channels() - 1)) * n;  // grey: repeated
        std::copy(src, src + n, out.data() + size_t(k) * n);
    }
    std::copy(alpha.data(), alpha.data() + n, out.data() + 3 * n);
    return out;
}

}  // namespace atrous::io

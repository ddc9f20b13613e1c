// The learned filter's weight file, version 4 (python/atrous/learn/weights.py, docs/learned.md):
// little-endian "ATRL" | u32 version | u32 n_in, n_hidden, n_feat, n_levels, n_ctx_in, n_ctx, n_floats
// | the floats (w1, b1, w2, b2, w3, b3, then the context branch's k1, kb1, ..., kz, kbz) | u32 FNV-1a
// 32 of every byte before it. Version 3 (no n_ctx_in, n_ctx; the MLP's floats only) is read as
// version 4 without a context. And the plane checks of the two runLearned entry points
// (filters/learned.h).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "atrous/error.h"
#include "atrous/learned.h"
#include "filters/learned.h"
#include "filters/weight_file.h"

namespace atrous::filters {
extern const std::uint8_t kLearnedDefaultWeights[];
extern const std::size_t kLearnedDefaultWeightsSize;
}  // namespace atrous::filters

namespace atrous {

namespace {

constexpr size_t kHeaderBytesV3 = 28, kHeaderBytesV4 = 36;

using filters::weightFnv1a;
using filters::weightU32;

std::string shapeText(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d, bool ctx, std::uint32_t e,
                      std::uint32_t f, std::uint32_t n) {
    return std::to_string(a) + "/" + std::to_string(b) + "/" + std::to_string(c) + "/" + std::to_string(d) +
           (ctx ? "/" + std::to_string(e) + "/" + std::to_string(f) : std::string()) + " (" + std::to_string(n) +
           " floats)";
}

}  // namespace

LearnedWeights LearnedWeights::parse(const void* data, size_t size, const std::string& name) {
    using namespace filters;
    const auto* p = static_cast<const std::uint8_t*>(data);
    if (size < 8 || std::memcmp(p, "ATRL", 4) != 0)
        throw InputError(name + ": not an atrous learned-filter weight file (no ATRL header)");
    const std::uint32_t version = weightU32(p + 4);
    // The retired versions, named as python/atrous/learn/weights.py names them.
    if (version == 1) throw InputError(name + ": version 1 (the first network, retired); retrain with make train");
    if (version == 2)
        throw InputError(name + ": version 2 (the network without the noise-relative colour term, retired); " +
                         "retrain with make train");
    if (version != 3 && version != 4)
        throw InputError(name + ": weight file version " + std::to_string(version) +
                         ", this build reads versions 3 and 4");
    const bool v4 = version == 4;
    const size_t head = v4 ? kHeaderBytesV4 : kHeaderBytesV3;
    if (size < head + 4) throw InputError(name + ": truncated weight file (" + std::to_string(size) + " bytes)");
    const std::uint32_t nIn = weightU32(p + 8), nHid = weightU32(p + 12), nFeat = weightU32(p + 16), nLev = weightU32(p + 20);
    const std::uint32_t nCtxIn = v4 ? weightU32(p + 24) : 0, nCtx = v4 ? weightU32(p + 28) : 0, n = weightU32(p + head - 4);
    const std::uint32_t want = v4 ? std::uint32_t(kLearnedParams) : std::uint32_t(kLearnedMlpParams);
    if (nIn != kLearnedIn || nHid != kLearnedHidden || nFeat != kLearnedFeat || nLev != kLearnedLevels || n != want ||
        (v4 && (nCtxIn != kLearnedCtxIn || nCtx != kLearnedCtx)))
        throw InputError(name + ": network shape n_in/n_hidden/n_feat/n_levels" + (v4 ? "/n_ctx_in/n_ctx " : " ") +
                         shapeText(nIn, nHid, nFeat, nLev, v4, nCtxIn, nCtx, n) + " is not this build's " +
                         shapeText(kLearnedIn, kLearnedHidden, kLearnedFeat, kLearnedLevels, v4, kLearnedCtxIn,
                                   kLearnedCtx, want));
    const size_t expect = head + 4 * size_t(n) + 4;
    if (size < expect)
        throw InputError(name + ": truncated weight file (" + std::to_string(size) + " bytes, " +
                         std::to_string(expect) + " expected)");
    if (size > expect)
        throw InputError(name + ": over-long weight file (" + std::to_string(size) + " bytes, " +
                         std::to_string(expect) + " expected)");
    if (weightFnv1a(p, size - 4) != weightU32(p + size - 4)) throw InputError(name + ": weight file checksum mismatch (corrupt)");
    auto impl = std::make_shared<Impl>();
    std::memset(&impl->net, 0, sizeof(impl->net));
    // The floats in the file's order: the MLP's, then (version 4) the context's, as LearnedNet lays them out.
    float* w = reinterpret_cast<float*>(&impl->net);
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t b = weightU32(p + head + 4 * size_t(i));
        std::memcpy(&w[i], &b, 4);
        if (!std::isfinite(w[i])) throw InputError(name + ": weight " + std::to_string(i) + " is not finite");
    }
    // A context whose last layer is all zero changes nothing: not computed (every version-3 file).
    bool context = false;
    for (float v : impl->net.ctx.kz) context = context || v != 0.0f;
    for (float v : impl->net.ctx.kbz) context = context || v != 0.0f;
    impl->net.context = context;
    LearnedWeights out;
    out.impl = impl;
    return out;
}

LearnedWeights LearnedWeights::load(const std::string& path) {
    const std::vector<std::uint8_t> bytes = filters::readWeightFile(path, "learned-filter weight file");
    return parse(bytes.data(), bytes.size(), path);
}

LearnedWeights LearnedWeights::builtin() {
    static const LearnedWeights w =
        parse(filters::kLearnedDefaultWeights, filters::kLearnedDefaultWeightsSize, "built-in learned weights");
    return w;
}

namespace filters {

void checkLearnedPlanes(const LearnedWeights& w, const PreparedView& in, const ImageView& out) {
    if (!w.impl) throw InputError("learned filter: no weights loaded");
    auto need = [&](const ImageView& v, const char* field, int channels, bool optional) {
        if (!v.valid()) {
            if (optional) return;
            throw InputError(std::string("learned filter: ") + field + ": missing");
        }
        if (!v.sameSize(in.color))
            throw InputError(std::string("learned filter: ") + field + ": size " + std::to_string(v.width) + "x" +
                             std::to_string(v.height) + " differs from the colour's " + std::to_string(in.color.width) + "x" +
                             std::to_string(in.color.height));
        if (v.channels < channels)
            throw InputError(std::string("learned filter: ") + field + ": " + std::to_string(v.channels) +
                             " channels, " + std::to_string(channels) + " needed");
    };
    if (!in.color.valid() || in.color.width <= 0 || in.color.height <= 0) throw InputError("learned filter: color: missing or empty");
    need(in.color, "color", 3, false), need(in.variance, "variance", 3, false), need(in.albedo, "albedo", 3, true);
    need(in.normal, "normal", 3, true), need(in.depth, "depth", 1, true), need(out, "out", 3, false);
}

}  // namespace filters

}  // namespace atrous

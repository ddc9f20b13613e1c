// The learned filter's weights (file format: python/atrous/learn/weights.py, docs/learned.md) and
// its CPU entry point, atrous::learnedDenoise (include/atrous/learned.h).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "atrous/error.h"
#include "atrous/learned.h"
#include "core/parallel.h"
#include "filters/learned.h"

namespace atrous::filters {
extern const std::uint8_t kLearnedDefaultWeights[];
extern const std::size_t kLearnedDefaultWeightsSize;
}  // namespace atrous::filters

namespace atrous {

struct LearnedWeights::Impl {
    filters::LearnedNet net;
};

namespace {

std::uint32_t fnv1a(const std::uint8_t* p, size_t n) {
    std::uint32_t h = 0x811C9DC5u;
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x01000193u;
    return h;
}

std::uint32_t u32(const std::uint8_t* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

}  // namespace

LearnedWeights LearnedWeights::parse(const void* data, size_t size, const std::string& name) {
    using namespace filters;
    const auto* p = static_cast<const std::uint8_t*>(data);
    if (size < 32 || std::memcmp(p, "ATRL", 4) != 0)
        throw InputError(name + ": not an atrous learned-filter weight file (no ATRL header)");
    const std::uint32_t version = u32(p + 4), nIn = u32(p + 8), nHid = u32(p + 12), nFeat = u32(p + 16),
                        nLev = u32(p + 20), n = u32(p + 24);
    if (version != 1)
        throw InputError(name + ": weight file version " + std::to_string(version) + ", this build reads version 1");
    if (nIn != kLearnedIn || nHid != kLearnedHidden || nFeat != kLearnedFeat || nLev != kLearnedLevels ||
        n != std::uint32_t(kLearnedParams))
        throw InputError(name + ": network shape " + std::to_string(nIn) + "/" + std::to_string(nHid) + "/" +
                         std::to_string(nFeat) + "/" + std::to_string(nLev) + " is not this build's " +
                         std::to_string(kLearnedIn) + "/" + std::to_string(kLearnedHidden) + "/" +
                         std::to_string(kLearnedFeat) + "/" + std::to_string(kLearnedLevels));
    if (size != 28 + 4 * size_t(n) + 4) throw InputError(name + ": truncated or over-long weight file");
    if (fnv1a(p, size - 4) != u32(p + size - 4)) throw InputError(name + ": weight file checksum mismatch (corrupt)");
    auto impl = std::make_shared<Impl>();
    float* w = reinterpret_cast<float*>(&impl->net);
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t b = u32(p + 28 + 4 * size_t(i));
        std::memcpy(&w[i], &b, 4);
        if (!std::isfinite(w[i])) throw InputError(name + ": weight " + std::to_string(i) + " is not finite");
    }
    LearnedWeights out;
    out.impl = impl;
    return out;
}

LearnedWeights LearnedWeights::load(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw InputError(path + ": cannot open the learned-filter weight file");
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    return parse(bytes.data(), bytes.size(), path);
}

LearnedWeights LearnedWeights::builtin() {
    static const LearnedWeights w =
        parse(filters::kLearnedDefaultWeights, filters::kLearnedDefaultWeightsSize, "built-in learned weights");
    return w;
}

Image learnedDenoise(const LearnedInputs& in, const LearnedWeights& weights) {
    using namespace filters;
    if (!weights.impl) throw InputError("learned filter: no weights loaded");
    if (!in.color.valid() || in.color.channels < 3) throw InputError("learned filter: color: missing or not RGB");
    const int w = in.color.width, h = in.color.height;
    auto check = [&](const ImageView& v, const char* name, int ch) {
        if (!v.valid()) return;
        if (v.width != w || v.height != h)
            throw InputError(std::string("learned filter: ") + name + ": size differs from the colour's");
        if (v.channels < ch) throw InputError(std::string("learned filter: ") + name + ": too few channels");
    };
    check(in.variance, "variance", 3), check(in.albedo, "albedo", 3), check(in.normal, "normal", 3);
    check(in.depth, "depth", 1), check(in.emission, "emission", 3);
    Image d(w, h, 3), tmp(w, h, 3), alb(w, h, 3), feat(w, h, kLearnedFeat), band(w, h, kLearnedLevels),
        centre(w, h, kLearnedLevels), out(w, h, 3);
    LearnedPrepare prep{&weights.impl->net, in.color, in.variance, in.albedo, in.normal, in.depth, in.emission,
                        d.view(), alb.view(), feat.view(), band.view(), centre.view()};
    runLearnedCascade(CpuExec{}, prep, tmp.view(), out.view());
    return out;
}

}  // namespace atrous

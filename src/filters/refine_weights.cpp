// The refine stage's weight file, version 1 (python/atrous/learn/refine.py writes it; docs/learned.md,
// "Refine"): little-endian "ATRF" | u32 version | u32 n_in, c1, c2, c3, n_floats | u32 steps |
// 48 bytes: the training run's name, NUL-padded | the floats (RefineNet's order) | u32 FNV-1a 32 of
// every byte before it.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "atrous/error.h"
#include "atrous/refine.h"
#include "filters/refine.h"
#include "filters/weight_file.h"

namespace atrous::filters {
extern const std::uint8_t kRefineDefaultWeights[];
extern const std::size_t kRefineDefaultWeightsSize;
}  // namespace atrous::filters

namespace atrous {

struct RefineWeights::Impl {
    filters::RefineNet net;
    std::string run;
    std::uint32_t steps = 0;
};

namespace {

constexpr size_t kHeader = 32, kRunBytes = 48;

}  // namespace

RefineWeights RefineWeights::parse(const void* data, size_t size, const std::string& name) {
    using namespace filters;
    const auto* p = static_cast<const std::uint8_t*>(data);
    if (size < 8 || std::memcmp(p, "ATRF", 4) != 0)
        throw InputError(name + ": not an atrous refine weight file (no ATRF header)");
    const std::uint32_t version = weightU32(p + 4);
    if (version != 1)
        throw InputError(name + ": refine weight file version " + std::to_string(version) + ", this build reads version 1");
    const size_t head = kHeader + kRunBytes;
    if (size < head + 4) throw InputError(name + ": truncated refine weight file (" + std::to_string(size) + " bytes)");
    const std::uint32_t nIn = weightU32(p + 8), c1 = weightU32(p + 12), c2 = weightU32(p + 16), c3 = weightU32(p + 20), n = weightU32(p + 24);
    if (nIn != kRefineIn || c1 != kRefineC1 || c2 != kRefineC2 || c3 != kRefineC3 || n != std::uint32_t(kRefineParams))
        throw InputError(name + ": network shape n_in/c1/c2/c3 " + std::to_string(nIn) + "/" + std::to_string(c1) + "/" +
                         std::to_string(c2) + "/" + std::to_string(c3) + " (" + std::to_string(n) +
                         " floats) is not this build's " + std::to_string(kRefineIn) + "/" + std::to_string(kRefineC1) +
                         "/" + std::to_string(kRefineC2) + "/" + std::to_string(kRefineC3) + " (" +
                         std::to_string(kRefineParams) + " floats)");
    const size_t expect = head + 4 * size_t(n) + 4;
    if (size != expect)
        throw InputError(name + (size < expect ? ": truncated" : ": over-long") + " refine weight file (" +
                         std::to_string(size) + " bytes, " + std::to_string(expect) + " expected)");
    if (weightFnv1a(p, size - 4) != weightU32(p + size - 4)) throw InputError(name + ": refine weight file checksum mismatch (corrupt)");
    auto impl = std::make_shared<Impl>();
    float* w = reinterpret_cast<float*>(&impl->net);
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t b = weightU32(p + head + 4 * size_t(i));
        std::memcpy(&w[i], &b, 4);
        if (!std::isfinite(w[i])) throw InputError(name + ": refine weight " + std::to_string(i) + " is not finite");
    }
    impl->steps = weightU32(p + 28);
    const char* run = reinterpret_cast<const char*>(p + kHeader);
    impl->run.assign(run, strnlen(run, kRunBytes));
    RefineWeights out;
    out.impl = impl;
    return out;
}

RefineWeights RefineWeights::load(const std::string& path) {
    const std::vector<std::uint8_t> bytes = filters::readWeightFile(path, "refine weight file");
    return parse(bytes.data(), bytes.size(), path);
}

RefineWeights RefineWeights::builtin() {
    static const RefineWeights w =
        parse(filters::kRefineDefaultWeights, filters::kRefineDefaultWeightsSize, "built-in refine weights");
    return w;
}

std::string RefineWeights::run() const { return impl ? impl->run : builtin().run(); }
std::uint32_t RefineWeights::steps() const { return impl ? impl->steps : builtin().steps(); }

namespace filters {
const RefineNet& refineNet(const RefineWeights& w) { return w.impl ? w.impl->net : RefineWeights::builtin().impl->net; }
}  // namespace filters

}  // namespace atrous

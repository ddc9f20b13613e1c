// The refine stage's weight file, version 1 (python/atrous/learn/refine.py writes it; docs/learned.md,
// "Refine"): little-endian "ATRF" | u32 version | u32 n_in, c1, c2, c3, n_floats | u32 steps |
// 48 bytes: the training run's name, NUL-padded | the floats (RefineNet's order) | u32 FNV-1a 32 of
// every byte before it.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "atrous/error.h"
#include "atrous/refine.h"
#include "filters/refine.h"

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

std::uint32_t fnv1a(const std::uint8_t* p, size_t n) {
    std::uint32_t h = 0x811C9DC5u;
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x01000193u;
    return h;
}

std::uint32_t u32(const std::uint8_t* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

}  // namespace

RefineWeights RefineWeights::parse(const void* data, size_t size, const std::string& name) {
    using namespace filters;
    const auto* p = static_cast<const std::uint8_t*>(data);
    if (size < 8 || std::memcmp(p, "ATRF", 4) != 0)
        throw InputError(name + ": not an atrous refine weight file (no ATRF header)");
    const std::uint32_t version = u32(p + 4);
    if (version != 1)
        throw InputError(name + ": refine weight file version " + std::to_string(version) + ", this build reads version 1");
    const size_t head = kHeader + kRunBytes;
    if (size < head + 4) throw InputError(name + ": truncated refine weight file (" + std::to_string(size) + " bytes)");
    const std::uint32_t nIn = u32(p + 8), c1 = u32(p + 12), c2 = u32(p + 16), c3 = u32(p + 20), n = u32(p + 24);
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
    if (fnv1a(p, size - 4) != u32(p + size - 4)) throw InputError(name + ": refine weight file checksum mismatch (corrupt)");
    auto impl = std::make_shared<Impl>();
    float* w = reinterpret_cast<float*>(&impl->net);
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t b = u32(p + head + 4 * size_t(i));
        std::memcpy(&w[i], &b, 4);
        if (!std::isfinite(w[i])) throw InputError(name + ": refine weight " + std::to_string(i) + " is not finite");
    }
    impl->steps = u32(p + 28);
    const char* run = reinterpret_cast<const char*>(p + kHeader);
    impl->run.assign(run, strnlen(run, kRunBytes));
    RefineWeights out;
    out.impl = impl;
    return out;
}

RefineWeights RefineWeights::load(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::exists(path, ec)) throw InputError(path + ": cannot open the refine weight file (not found)");
    if (fs::is_directory(path, ec)) throw InputError(path + ": is a directory, not a refine weight file");
    // Only regular files (a FIFO or /dev/zero would be read for ever), and only as many bytes as
    // this build's network has (parse() checks the exact size).
    if (!fs::is_regular_file(path, ec)) throw InputError(path + ": not a regular file (a refine weight file)");
    const uintmax_t size = fs::file_size(path, ec);
    constexpr uintmax_t kMaxBytes = 1u << 20;
    if (ec || size > kMaxBytes)
        throw InputError(path + ": over-long refine weight file (" + std::to_string(size) + " bytes)");
    std::ifstream f(path, std::ios::binary);
    if (!f) throw InputError(path + ": cannot open the refine weight file");
    std::vector<std::uint8_t> bytes(static_cast<size_t>(size));
    f.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size));
    if (size_t(f.gcount()) != bytes.size()) throw InputError(path + ": cannot read the refine weight file");
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

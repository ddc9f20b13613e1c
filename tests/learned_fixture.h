// tests/learned_fixture.bin (scripts/train/make_fixture.py, the learned filter v4's parity
// fixture): "ATRF" | u32 4 | u32 width | u32 height | u32 n | the weight file (n bytes) | planes
// d(3), var(3), albedo(3), normal(3), depth(1), out_d(3), f32 planar. Shared by learned_test and
// tests/cuda/learned_cuda_test.cu.
#pragma once
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "atrous/image.h"
#include "filters/learned.h"

namespace atrous::test {

struct Fixture {
    int w = 0, h = 0;
    std::vector<std::uint8_t> weights;
    Image d, var, albedo, normal, depth, expect;
    PreparedView planes() const { return filters::preparedView(d.view(), var.view(), albedo.view(), normal.view(), depth.view()); }
};

inline std::uint32_t rd32(const std::uint8_t* p) {
    std::uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

inline const Fixture& fixture() {
    static const Fixture fx = [] {
        const std::string path = std::string(ATROUS_SOURCE_DIR) + "/tests/learned_fixture.bin";
        std::ifstream f(path, std::ios::binary);
        if (!f) throw std::runtime_error(path + ": missing");
        const std::vector<std::uint8_t> b((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
        if (b.size() < 20 || std::memcmp(b.data(), "ATRF", 4) != 0 || rd32(&b[4]) != 4)
            throw std::runtime_error(path + ": not a version-4 ATRF fixture");
        Fixture fx;
        fx.w = int(rd32(&b[8])), fx.h = int(rd32(&b[12]));
        const size_t nw = rd32(&b[16]);
        fx.weights.assign(b.begin() + 20, b.begin() + 20 + std::ptrdiff_t(nw));
        size_t o = 20 + nw;
        const size_t plane = size_t(fx.w) * size_t(fx.h);
        if (b.size() != o + 16 * plane * 4) throw std::runtime_error(path + ": wrong size");
        Image* dst[6] = {&fx.d, &fx.var, &fx.albedo, &fx.normal, &fx.depth, &fx.expect};
        const int ch[6] = {3, 3, 3, 3, 1, 3};
        for (int k = 0; k < 6; ++k) {
            *dst[k] = Image(fx.w, fx.h, ch[k]);
            std::memcpy(dst[k]->data(), &b[o], plane * ch[k] * 4);
            o += plane * ch[k] * 4;
        }
        return fx;
    }();
    return fx;
}

// Weight files a reader must refuse, written into `dir`: the path of one that is not there, one that
// is not a weight file ("junk.atrl"), and the fixture relabelled version 2 with its checksum fixed
// ("v2.atrl": only the version is wrong), in that order.
inline std::vector<std::string> badWeightFiles(const std::string& dir) {
    const std::string junk = dir + "/junk.atrl", v2 = dir + "/v2.atrl";
    std::ofstream(junk) << "ATRL but not really";
    std::vector<std::uint8_t> w = fixture().weights;
    w[4] = 2;
    std::uint32_t h = 0x811C9DC5u;
    for (size_t i = 0; i + 4 < w.size(); ++i) h = (h ^ w[i]) * 0x01000193u;
    std::memcpy(&w[w.size() - 4], &h, 4);
    std::ofstream(v2, std::ios::binary).write(reinterpret_cast<const char*>(w.data()), std::streamsize(w.size()));
    return {dir + "/missing.atrl", junk, v2};
}

}  // namespace atrous::test

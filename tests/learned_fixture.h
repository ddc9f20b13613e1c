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
    filters::LearnedPlanes planes() const { return {d.view(), var.view(), albedo.view(), normal.view(), depth.view()}; }
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

}  // namespace atrous::test

// libFuzzer target: learned-filter weight files through atrous::LearnedWeights::parse (what
// --learned-weights FILE and LearnedWeights::load read). The input is the file's bytes. Each input
// is parsed as it is and, when it has a header, once more with its last 4 bytes replaced by the
// right FNV-1a checksum, so that mutations reach the checks behind the checksum.
//
// Contract (fuzz_common.h): parse returns weights or throws InputError; weights it returns are all
// finite (learned.h: "a non-finite weight" is refused).
#include <cstring>

#include "atrous/learned.h"
#include "filters/learned.h"
#include "fuzz_common.h"

using namespace atrous_fuzz;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    targetName() = "weights";
    return 0;
}

static void parseAndCheck(const uint8_t* p, size_t n, const char* what) {
    atrous::LearnedWeights w;
    if (!returnsOrInputError(what, [&] { w = atrous::LearnedWeights::parse(p, n, "fuzz.bin"); })) return;
    if (!w.impl) finding(std::string(what) + ": returned no weights");
    const float* f = reinterpret_cast<const float*>(&w.impl->net);
    for (int i = 0; i < atrous::filters::kLearnedParams; ++i)
        if (!std::isfinite(f[i])) finding(std::string(what) + ": weight " + std::to_string(i) + " is not finite");
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    parseAndCheck(data, size, "LearnedWeights::parse");
    if (size < 32) return 0;
    std::vector<uint8_t> fixed(data, data + size);
    uint32_t h = 0x811C9DC5u;
    for (size_t i = 0; i + 4 < size; ++i) h = (h ^ fixed[i]) * 0x01000193u;
    for (int k = 0; k < 4; ++k) fixed[size - 4 + size_t(k)] = uint8_t(h >> (8 * k));
    if (std::memcmp(fixed.data(), data, size) != 0) parseAndCheck(fixed.data(), size, "LearnedWeights::parse (checksum fixed)");
    return 0;
}

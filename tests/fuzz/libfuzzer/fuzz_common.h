// Shared by the libFuzzer targets (tests/fuzz/libfuzzer/*.cpp, docs/reliability.md): the contract
// every target checks, a per-process scratch directory for readers that need a path, and the
// checks of what a reader promises about what it returns.
//
// The contract: a reader returns or throws atrous::InputError. Any other exception, a crash, a
// sanitizer report, a leak, or a returned value that breaks the reader's promise (a NaN where the
// conventions say none, an image larger than its file can hold, a scene value outside its rule) is
// a finding: the target prints one line "==atrous-fuzz== FINDING in <target>: ..." and aborts, and
// libFuzzer keeps the input as crash-<sha1>.
//
// Known problems: a target can name one with knownIssue() ("==atrous-fuzz== KNOWN <id>", once)
// and skip the input, so that a long run goes on while it is being fixed; with ATROUS_FUZZ_STRICT=1
// nothing is skipped. None is open: every problem found so far is fixed (tests/fuzz/libfuzzer/README.md),
// its input a seed (corpus/*/finding_*).
#pragma once
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <set>
#include <string>
#include <typeinfo>
#include <vector>

#include "atrous/error.h"
#include "atrous/image.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/pass_map.h"
#include "render/scene_data.h"
#include "render/scene_limits.h"

namespace atrous_fuzz {

using atrous::Image;

// The target's name, for messages (set once in LLVMFuzzerInitialize or at first use).
inline const char*& targetName() {
    static const char* name = "atrous";
    return name;
}

// `s` with control and non-ASCII bytes as '?' (file names and attribute names from the input
// stay on one printable line of the log).
inline std::string printable(std::string s) {
    for (char& c : s)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
    return s;
}

[[noreturn]] inline void finding(const std::string& what) {
    std::fprintf(stderr, "\n==atrous-fuzz== FINDING in %s: %s\n", targetName(), printable(what).c_str());
    std::fflush(stderr);
    std::abort();
}

inline bool strict() {
    static const bool s = [] {
        const char* e = std::getenv("ATROUS_FUZZ_STRICT");
        return e && *e && std::string(e) != "0";
    }();
    return s;
}

// True (skip the input) for a known problem, unless ATROUS_FUZZ_STRICT is set. Named once per id.
inline bool knownIssue(const char* id, const std::string& detail) {
    if (strict()) return false;
    static std::set<std::string>* seen = new std::set<std::string>();
    if (seen->insert(id).second) {
        std::fprintf(stderr, "==atrous-fuzz== KNOWN %s (skipped; ATROUS_FUZZ_STRICT=1 makes it a finding): %s\n", id,
                     printable(detail).c_str());
        std::fflush(stderr);
    }
    return true;
}

// ------------------------------------------------------------------------------- scratch files

// A directory of this process's own: $ATROUS_FUZZ_TMP (scripts/libfuzz.sh gives each target one
// under /dev/shm), else /dev/shm or $TMPDIR; removed at a normal exit.
inline const std::string& scratchDir() {
    static const std::string* dir = [] {
        std::string base;
        if (const char* t = std::getenv("ATROUS_FUZZ_TMP"); t && *t)
            base = t;
        else if (access("/dev/shm", W_OK) == 0)
            base = "/dev/shm";
        else if (const char* t2 = std::getenv("TMPDIR"); t2 && *t2)
            base = t2;
        else
            base = "/tmp";
        auto* d = new std::string(base + "/atrous-fuzz-" + std::to_string(getpid()));
        std::error_code ec;
        std::filesystem::create_directories(*d, ec);
        if (ec) {
            std::fprintf(stderr, "cannot create %s: %s\n", d->c_str(), ec.message().c_str());
            std::exit(2);
        }
        std::atexit([] {
            std::error_code e2;
            std::filesystem::remove_all(scratchDir(), e2);
        });
        return d;
    }();
    return *dir;
}

// Writes `size` bytes to scratchDir()/name (replacing it) and returns the path.
inline std::string writeScratch(const std::string& name, const void* data, size_t size) {
    const std::string path = scratchDir() + "/" + name;
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f || (size && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
        std::fprintf(stderr, "cannot write %s\n", path.c_str());
        std::exit(2);
    }
    return path;
}
inline std::string writeScratch(const std::string& name, const std::string& text) {
    return writeScratch(name, text.data(), text.size());
}

// The libFuzzer entry points of a target that reads its input as a file: the target's name for
// findings, and the input's bytes written to scratchDir()/file; the body that follows is the
// check, with `path` (that file), `data` and `size`, returning 0:
//   ATROUS_FUZZ_FILE_TARGET("pfm", "in.pfm") { ...; return 0; }
#define ATROUS_FUZZ_FILE_TARGET(name, file)                                                       \
    static int fuzzFileTarget(const std::string& path, const uint8_t* data, size_t size);         \
    extern "C" int LLVMFuzzerInitialize(int*, char***) {                                          \
        ::atrous_fuzz::targetName() = name;                                                       \
        return 0;                                                                                 \
    }                                                                                             \
    extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {                     \
        return fuzzFileTarget(::atrous_fuzz::writeScratch(file, data, size), data, size);         \
    }                                                                                             \
    static int fuzzFileTarget(const std::string& path, [[maybe_unused]] const uint8_t* data,     \
                              [[maybe_unused]] size_t size)

// The input cut at each `sep` into at most `maxParts` parts (the last keeps the rest): how the
// targets with several files (a scene JSON and an image; an OBJ, its MTL and a texture) take them
// from one input.
inline std::vector<std::string> splitSections(const uint8_t* data, size_t size, const std::string& sep, size_t maxParts) {
    std::vector<std::string> parts;
    const std::string all(reinterpret_cast<const char*>(data), size);
    size_t at = 0;
    while (parts.size() + 1 < maxParts) {
        const size_t next = all.find(sep, at);
        if (next == std::string::npos) break;
        parts.push_back(all.substr(at, next - at));
        at = next + sep.size();
    }
    parts.push_back(all.substr(at));
    while (parts.size() < maxParts) parts.emplace_back();
    return parts;
}

// --------------------------------------------------------------------------------- the contract

// Runs f(). True when it returned, false when it threw InputError (with a message); anything else
// is a finding.
template <class F>
bool returnsOrInputError(const std::string& what, F&& f) {
    try {
        f();
        return true;
    } catch (const atrous::InputError& e) {
        if (std::string(e.what()).empty()) finding(what + ": InputError with an empty message");
        return false;
    } catch (const std::exception& e) {
        finding(what + ": threw " + typeid(e).name() + " instead of atrous::InputError: " + e.what());
    } catch (...) {
        finding(what + ": threw something that is not a std::exception");
    }
}

// A returned image: a host image of `minPlanes` to 3 channels and of a size the readers accept.
inline void checkShape(const std::string& what, const Image& img, int minPlanes = 3) {
    if (img.empty()) finding(what + ": returned an empty image");
    if (img.channels() < minPlanes || img.channels() > 3 || img.width() <= 0 || img.height() <= 0 || img.width() > atrous::kMaxImageDim ||
        img.height() > atrous::kMaxImageDim)
        finding(what + ": returned a " + std::to_string(img.width()) + "x" + std::to_string(img.height()) + "x" +
                std::to_string(img.channels()) + " image");
}

inline std::string at(const Image& img, size_t i) {
    const size_t plane = img.plane(), c = i / plane, p = i % plane;
    return " at (" + std::to_string(p % size_t(img.width())) + ", " + std::to_string(p / size_t(img.width())) +
           ") channel " + std::to_string(c);
}

// What conformBuffer (io/pass_map.h) promises for buffer b: normals finite and at most unit
// length, depth in (0, 1e9) or the background 1e30, albedo in [0, 1], positions, ids and motion
// finite. Colour, variance and emission are left as they are (the filters repair them).
inline void checkConformed(atrous::io::Buffer b, const Image& img, const std::string& what) {
    using atrous::io::Buffer;
    const float* p = img.data();
    const size_t n = img.plane(), all = img.size();
    switch (b) {
        case Buffer::Normal:
            for (size_t i = 0; i < n; ++i) {
                const float x = p[i], y = p[i + n], z = p[i + 2 * n];
                if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || double(x) * x + double(y) * y + double(z) * z > 1.001)
                    finding(what + ": normal (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) +
                            ") is not finite or longer than 1" + at(img, i));
            }
            break;
        case Buffer::Depth:
            for (size_t i = 0; i < all; ++i)
                if (!((p[i] > 0.0f && p[i] < 1e9f) || p[i] == 1e30f))
                    finding(what + ": depth " + std::to_string(p[i]) + " is neither in (0, 1e9) nor 1e30" + at(img, i));
            break;
        case Buffer::Albedo:
            for (size_t i = 0; i < all; ++i)
                if (!(p[i] >= 0.0f && p[i] <= 1.0f)) finding(what + ": albedo " + std::to_string(p[i]) + " outside [0, 1]" + at(img, i));
            break;
        case Buffer::Position:
        case Buffer::ObjectId:
        case Buffer::MaterialId:
        case Buffer::Motion:
            for (size_t i = 0; i < all; ++i)
                if (!std::isfinite(p[i])) finding(what + ": a non-finite value" + at(img, i));
            break;
        default: break;
    }
}

// ------------------------------------------------------------------------------ layered EXR

// What inspectExr promises about the ExrInfo it returns (io/exr_layers.h): parts of accepted sizes,
// an image window of an accepted size inside the first part's data window, every channel in one
// part and in exactly one layer, each layer's components the last name components of its channels.
inline void checkExrInfo(const atrous::io::ExrInfo& info, const std::string& what) {
    auto bad = [&](const std::string& m) { finding(what + ": " + m); };
    if (info.parts.empty()) bad("no parts");
    for (const auto& p : info.parts)
        if (p.width <= 0 || p.height <= 0 || p.width > atrous::kMaxImageDim || p.height > atrous::kMaxImageDim)
            bad("a part of size " + std::to_string(p.width) + "x" + std::to_string(p.height));
    if (info.width <= 0 || info.height <= 0 || info.width > info.parts[0].width || info.height > info.parts[0].height)
        bad("an image of " + std::to_string(info.width) + "x" + std::to_string(info.height) + " for a first part of " +
            std::to_string(info.parts[0].width) + "x" + std::to_string(info.parts[0].height));
    std::vector<int> seen(info.channels.size(), 0);
    for (const auto& ch : info.channels)
        if (ch.part < 0 || size_t(ch.part) >= info.parts.size()) bad("a channel in a missing part");
    for (const auto& l : info.layers) {
        if (l.channels.size() != l.components.size() || l.channels.empty()) bad("a layer with mismatched components");
        for (size_t i = 0; i < l.channels.size(); ++i) {
            const int c = l.channels[i];
            if (c < 0 || size_t(c) >= info.channels.size()) bad("a layer with a missing channel");
            ++seen[size_t(c)];
            const std::string& full = info.channels[size_t(c)].fullName;
            const size_t dot = full.rfind('.');
            if ((dot == std::string::npos ? full : full.substr(dot + 1)) != l.components[i] ||
                (dot == std::string::npos ? std::string() : full.substr(0, dot)) != l.name)
                bad("channel '" + full + "' in layer '" + l.name + "' as component '" + l.components[i] + "'");
        }
    }
    for (int n : seen)
        if (n != 1) bad("a channel in " + std::to_string(n) + " layers");
}

inline bool isAlphaName(const std::string& c) { return c == "A" || c == "a" || c == "alpha" || c == "Alpha"; }

// What mapPasses / passForFile promise about a choice (io/pass_map.h): 1 or the buffer's count of
// distinct, existing channels, inside the chosen layer; never an alpha channel unless named by
// --pass as a full channel name (the only way to get a choice without a layer).
inline void checkPassChoice(const atrous::io::ExrInfo& info, atrous::io::Buffer b, const atrous::io::PassChoice& c,
                            const std::string& what) {
    using namespace atrous::io;
    auto bad = [&](const std::string& m) { finding(what + " (" + bufferName(b) + "): " + m); };
    if (c.layer < -1 || c.layer >= int(info.layers.size())) bad("layer index " + std::to_string(c.layer));
    if (!c.found()) return;
    if (c.rule.empty()) bad("a choice without a rule");
    const size_t n = c.channels.size();
    if (n != 1 && int(n) != bufferChannels(b)) bad(std::to_string(n) + " channels");
    for (size_t i = 0; i < n; ++i) {
        const int ch = c.channels[i];
        if (ch < 0 || size_t(ch) >= info.channels.size()) bad("channel index " + std::to_string(ch));
        for (size_t j = 0; j < i; ++j)
            if (c.channels[j] == ch) bad("a channel taken twice");
        if (c.layer < 0) continue;
        const ExrLayer& l = info.layers[size_t(c.layer)];
        size_t k = 0;
        while (k < l.channels.size() && l.channels[k] != ch) ++k;
        if (k == l.channels.size()) bad("a channel outside its layer '" + l.name + "'");
        if (isAlphaName(l.components[k])) bad("the alpha channel of '" + l.name + "'");
    }
    if (c.layer < 0 && n != 1) bad("several channels without a layer");
}

// ------------------------------------------------------------------------------- scene values

inline bool inRule(const atrous::pt::ValueRule& r, float v) { return atrous::pt::allowed(r, v); }
inline bool inRule(const atrous::pt::ValueRule& r, atrous::Vec3 v) {
    return inRule(r, v.x) && inRule(r, v.y) && inRule(r, v.z);
}
inline bool finite3(atrous::Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Every value of a parsed scene within its rule (src/render/scene_limits.h, docs/reliability.md),
// every index in range, every derived table (light CDF, environment distribution) finite.
inline void checkScene(const atrous::pt::SceneData& d, const std::string& what) {
    using namespace atrous::pt;
    auto bad = [&](const std::string& m) { finding(what + ": parsed scene has " + m); };
    const size_t nTri = d.triMaterial.size();
    if (d.indices.size() != 3 * nTri || d.triMesh.size() != nTri || d.triLight.size() != nTri) bad("inconsistent triangle arrays");
    if (d.normals.size() != d.positions.size() || d.uvs.size() != d.positions.size()) bad("inconsistent vertex arrays");
    for (size_t i = 0; i < d.positions.size(); ++i) {
        if (!inRule(kCoordinateRule, d.positions[i])) bad("vertex " + std::to_string(i) + " outside +-1e9 or not finite");
        if (!finite3(d.normals[i])) bad("a non-finite vertex normal");
        if (!inRule(kTexcoordRule, d.uvs[i].x) || !inRule(kTexcoordRule, d.uvs[i].y)) bad("a texcoord outside +-1e6");
    }
    for (uint32_t ix : d.indices)
        if (ix >= d.positions.size()) bad("a triangle index past the last vertex");
    const size_t nMat = d.materials.size(), nMesh = d.meshNames.size(), nLight = d.lights.size();
    for (size_t t = 0; t < nTri; ++t) {
        if (d.triMaterial[t] < 0 || size_t(d.triMaterial[t]) >= nMat) bad("a triangle with a bad material id");
        if (d.triMesh[t] < 0 || size_t(d.triMesh[t]) >= nMesh) bad("a triangle with a bad mesh id");
        if (d.triLight[t] < -1 || d.triLight[t] >= int(nLight)) bad("a triangle with a bad light id");
    }
    for (const Sphere& s : d.spheres) {
        if (!inRule(kCoordinateRule, s.center) || !(s.radius > 0.0f) || !inRule(kCoordinateRule, s.radius)) bad("a sphere out of range");
        if (s.material < 0 || size_t(s.material) >= nMat || s.mesh < 0 || size_t(s.mesh) >= nMesh) bad("a sphere with a bad id");
    }
    for (const Material& m : d.materials) {
        if (!inRule(kReflectanceRule, m.albedo) || !inRule(kReflectanceRule, m.albedo2)) bad("an albedo outside [0, 1]");
        if (!inRule(kRadianceRule, m.emission)) bad("an emission outside [0, 1e8]");
        if (!inRule(kRoughnessRule, m.roughness) || !inRule(kIorRule, m.ior)) bad("a roughness or ior out of range");
        if (!(m.checkerScale > 0.0f) || !inRule(kCheckerScaleRule, m.checkerScale)) bad("a checker scale out of range");
        if (m.texture < -1 || m.texture >= int(d.textures.size())) bad("a material with a bad texture id");
    }
    for (const Texture& t : d.textures)
        if (t.width <= 0 || t.height <= 0 || t.offset < 0 ||
            size_t(t.offset) + 3 * size_t(t.width) * size_t(t.height) > d.texels.size())
            bad("a texture outside the texel array");
    for (float v : d.texels)
        if (!(v >= 0.0f) || !std::isfinite(v)) bad("a texel that is negative or not finite");
    for (const Light& l : d.lights) {
        if (l.type == LightType::Point && (!inRule(kCoordinateRule, l.position) || !inRule(kRadianceRule, l.intensity)))
            bad("a point light out of range");
        if (l.type == LightType::Triangle && (l.triangle < 0 || size_t(l.triangle) >= nTri)) bad("a light on a missing triangle");
    }
    if (d.lightCdf.size() != nLight + 1) bad("a light CDF of the wrong size");
    for (size_t i = 0; i < d.lightCdf.size(); ++i)
        if (!(d.lightCdf[i] >= 0.0f && d.lightCdf[i] <= 1.0f) || (i && d.lightCdf[i] < d.lightCdf[i - 1]))
            bad("a light CDF that is not finite and non-decreasing in [0, 1]");
    for (float v : d.envDist)
        if (!std::isfinite(v)) bad("a non-finite environment sampling distribution");
    if (!finite3(d.env.color) || !inRule(kRadianceRule, d.env.color)) bad("an environment colour/scale outside [0, 1e8]");
    if (d.env.type == EnvType::Map) {
        if (d.env.texture < 0 || size_t(d.env.texture) >= d.textures.size()) bad("an environment map with a bad texture id");
        const Texture& t = d.textures[size_t(d.env.texture)];
        for (size_t i = 0; i < 3 * size_t(t.width) * size_t(t.height); ++i)
            if (double(d.texels[size_t(t.offset) + i]) * d.env.color.x > 1.0001e8) bad("an environment texel times its scale above 1e8");
        if (!std::isfinite(d.env.margInt)) bad("a non-finite environment integral");
    }
    const Camera& c = d.camera;
    if (!inRule(kCoordinateRule, c.position) || !finite3(c.forward) || !finite3(c.right) || !finite3(c.up) ||
        !(c.tanHalfFov > 0.0f) || !std::isfinite(c.tanHalfFov))
        bad("a camera out of range");
    if (!(d.sceneRadius > 0.0f) || !std::isfinite(d.sceneRadius)) bad("a scene radius that is not finite");
    for (size_t k = 0; k < d.cameraKeys.size(); ++k) {
        const CameraKey& key = d.cameraKeys[k];
        if (!inRule(kCoordinateRule, key.position) || !inRule(kCoordinateRule, key.target) || !inRule(kCoordinateRule, key.up) ||
            !(key.fovDeg > 0.5f && key.fovDeg < 179.0f) || !inRule(kCoordinateRule, key.t) ||
            (k && !(key.t > d.cameraKeys[k - 1].t)))
            bad("a camera keyframe out of range or out of order");
    }
    if (d.meshMotion.size() > nMesh) bad("motion for a missing mesh");
    for (const MeshMotion& m : d.meshMotion)
        if (!inRule(kCoordinateRule, m.translate) || !inRule(kAngleRule, m.rotateYDeg) || !finite3(m.pivot))
            bad("a motion out of range");
}

}  // namespace atrous_fuzz

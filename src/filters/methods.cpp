// The registry of still methods (include/atrous/denoise.h): the built-in rows, the rows
// registerDenoiseMethod adds, the lookups by name and value, and auto's rule.
#include <cctype>
#include <deque>
#include <string>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/sequence_methods.h"

namespace atrous {

namespace {

// The registry: the built-in rows, then the registered ones (a deque: rows never move, so the
// references and names handed out stay valid), with the registered names' storage beside them.
struct MethodRegistry {
    std::deque<DenoiseMethodInfo> rows = {
        {DenoiseMethod::Eaw, "eaw", "the edge-avoiding a-trous wavelet filter (Dammertz et al. 2010)", false},
        {DenoiseMethod::Sure, "sure", "EAW's cascade keeping part of each detail, chosen by SURE (Kim, Moon, Yoon 2016)", false},
        {DenoiseMethod::Learned, "learned", "a small network steering the a-trous cascade (docs/learned.md)", true},
        {DenoiseMethod::Blend, "blend", "the mean of learned and sure, from one preparation", true},
        {DenoiseMethod::Auto, "auto", "blend with an albedo and a normal, else sure: the method measured best for the buffers given",
         true},
    };
    std::deque<std::string> strings;
};

MethodRegistry& registry() {
    static MethodRegistry r;
    return r;
}

}  // namespace

const std::deque<DenoiseMethodInfo>& denoiseMethods() { return registry().rows; }

DenoiseMethod registerDenoiseMethod(DenoiseMethodInfo info) {
    const std::string name = info.name ? info.name : "";
    bool ok = !name.empty() && name.size() <= 64;
    for (char ch : name) ok = ok && (std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-');
    if (!ok) throw InputError("registerDenoiseMethod: '" + name + "' is not a method name (letters, digits, '_', '-')");
    if (findDenoiseMethod(name)) throw InputError("registerDenoiseMethod: there is already a method '" + name + "'");
    // The sequence methods' names, and the front-ends' own words for no filter and for OIDN.
    bool taken = name == "none" || name == "noisy" || name == "oidn";
    for (const SequenceMethodInfo& m : sequenceMethods()) taken = taken || name == m.name;
    if (taken) throw InputError("registerDenoiseMethod: '" + name + "' is a name the front-ends use (a sequence method, none, noisy or oidn)");
    if (!info.registered()) throw InputError("registerDenoiseMethod: method '" + name + "' has no cascade (cpu or cuda)");
    if (info.usesWeights)
        throw InputError("registerDenoiseMethod: method '" + name + "': a registered cascade cannot read the learned weights");
    MethodRegistry& r = registry();
    info.method = static_cast<DenoiseMethod>(r.rows.size());  // the built-ins are 0..4
    r.strings.push_back(name);
    info.name = r.strings.back().c_str();
    r.strings.push_back(info.summary ? info.summary : "");
    info.summary = r.strings.back().c_str();
    r.rows.push_back(std::move(info));
    return r.rows.back().method;
}

const DenoiseMethodInfo* findDenoiseMethod(const std::string& name) {
    for (const DenoiseMethodInfo& m : denoiseMethods())
        if (name == m.name) return &m;
    return nullptr;
}

const DenoiseMethodInfo& denoiseMethodInfo(DenoiseMethod m) {
    for (const DenoiseMethodInfo& i : denoiseMethods())
        if (i.method == m) return i;
    throw InputError("unknown denoise method (value " + std::to_string(static_cast<int>(m)) + ", not in denoiseMethods())");
}

std::string denoiseMethodNames() {
    const auto& ms = denoiseMethods();
    std::string s;
    for (size_t i = 0; i < ms.size(); ++i) s += (i == 0 ? "" : i + 1 == ms.size() ? " or " : ", ") + std::string(ms[i].name);
    return s;
}

DenoiseMethod parseDenoiseMethod(const std::string& name) {
    if (const DenoiseMethodInfo* m = findDenoiseMethod(name)) return m->method;
    throw InputError("unknown denoise method '" + name + "' (expected " + denoiseMethodNames() + ")");
}

const char* denoiseMethodName(DenoiseMethod m) { return denoiseMethodInfo(m).name; }

// The network was trained with an albedo and a normal (docs/learned.md); without them SURE. With
// them, the mean of the two (Blend): measured best on other renderers' stills (docs/quality.md).
DenoiseMethod resolveDenoiseMethod(DenoiseMethod m, bool albedo, bool normal) {
    if (m != DenoiseMethod::Auto) return m;
    return albedo && normal ? DenoiseMethod::Blend : DenoiseMethod::Sure;
}

DenoiseMethod resolveDenoiseMethod(DenoiseMethod m, const DenoiseInputs& in) {
    return resolveDenoiseMethod(m, in.albedo && !in.albedo->empty(), in.normal && !in.normal->empty());
}

}  // namespace atrous

// The registry of still methods (include/atrous/denoise.h): the built-in rows, the rows
// registerDenoiseMethod adds, the lookups by name and value, auto's rule, and what a call reads:
// every rule below derives from the rows' `reads` (docs/denoising.md, "What a method reads").
#include <algorithm>
#include <cctype>
#include <deque>
#include <string>

#include "atrous/denoise.h"
#include "atrous/error.h"
#include "atrous/params.h"
#include "atrous/sequence_methods.h"

namespace atrous {

namespace {

// The features the EAW family's cascade reads (its edge stops; the albedo for the give-back), and the
// learned network's.
constexpr BufferMask kEawReads{Buffer::Albedo, Buffer::Normal, Buffer::Position, Buffer::Depth, Buffer::ObjectId};
constexpr BufferMask kLearnedReads{Buffer::Albedo, Buffer::Normal, Buffer::Depth};

DenoiseMethodInfo builtin(DenoiseMethod m, const char* name, const char* summary, MethodReads reads, CascadeKind kind) {
    DenoiseMethodInfo i;
    i.method = m, i.name = name, i.summary = summary, i.reads = std::move(reads), i.kind = kind;
    return i;
}

// The registry: the built-in rows, then the registered ones (a deque: rows never move, so the
// references and names handed out stay valid), with the registered names' storage beside them.
struct MethodRegistry {
    std::deque<DenoiseMethodInfo> rows = {
        builtin(DenoiseMethod::Eaw, "eaw", "the edge-avoiding a-trous wavelet filter (Dammertz et al. 2010)",
                {kEawReads, {"eaw"}, false, {}}, CascadeKind::Eaw),
        builtin(DenoiseMethod::Sure, "sure", "EAW's cascade keeping part of each detail, chosen by SURE (Kim, Moon, Yoon 2016)",
                {kEawReads, {"eaw", "sure"}, false, {}}, CascadeKind::Sure),
        builtin(DenoiseMethod::Learned, "learned", "a small network steering the a-trous cascade (docs/learned.md)",
                {kLearnedReads, {}, true, {}}, CascadeKind::Learned),
        builtin(DenoiseMethod::Blend, "blend", "the mean of learned and sure, from one preparation",
                {{}, {}, false, {DenoiseMethod::Learned, DenoiseMethod::Sure}}, CascadeKind::Blend),
        builtin(DenoiseMethod::Auto, "auto",
                "blend with an albedo and a normal, else sure: the method measured best for the buffers given",
                {{}, {}, false, {DenoiseMethod::Blend, DenoiseMethod::Sure}}, CascadeKind::Auto),
        builtin(DenoiseMethod::Refine, "refine",
                "SURE, then a small U-Net that predicts a correction of the image, keeping its light per 64-pixel "
                "block (docs/refine.md; needs an albedo and a normal)",
                {kEawReads, {"eaw", "sure"}, false, {}}, CascadeKind::Sure),
    };
    std::deque<std::string> strings;
};

MethodRegistry& registry() {
    static MethodRegistry r;
    return r;
}

bool hasParamGroup(const std::string& group) {
    for (const ParamField<DenoiseOptions>& f : denoiseParams())
        if (group == f.group) return true;
    return false;
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
    if (!info.cpu && !info.cuda) throw InputError("registerDenoiseMethod: method '" + name + "' has no cascade (cpu or cuda)");
    if (!info.reads.combines.empty())
        throw InputError("registerDenoiseMethod: method '" + name + "': a registered method combines no other rows");
    if (info.reads.weights)
        throw InputError("registerDenoiseMethod: method '" + name + "': a registered cascade cannot read the learned weights");
    if (info.reads.buffers.has(Buffer::Color) || info.reads.buffers.has(Buffer::Motion) ||
        info.reads.buffers.has(Buffer::MaterialId))
        throw InputError("registerDenoiseMethod: method '" + name +
                         "': reads names the features it reads (variance, albedo, normal, position, depth, object_id, "
                         "emission); the colour is always read");
    for (const std::string& g : info.reads.params)
        if (!hasParamGroup(g))
            throw InputError("registerDenoiseMethod: method '" + name + "': reads the parameter group '" + g +
                             "', which denoiseParams() does not have");
    MethodRegistry& r = registry();
    info.method = static_cast<DenoiseMethod>(r.rows.size());  // the built-ins are 0..5
    info.kind = CascadeKind::Registered;
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

DenoiseMethod resolveDenoiseMethod(DenoiseMethod m, const Frame& in) {
    return resolveDenoiseMethod(m, in.albedo && !in.albedo->empty(), in.normal && !in.normal->empty());
}

// ---- What a call reads ------------------------------------------------------------------------

const std::vector<std::string>& stillStageGroups() {
    static const std::vector<std::string> g = {"", "firefly", "emission", "safety"};
    return g;
}

bool readsParamGroup(const DenoiseMethodInfo& method, const std::string& group) {
    const std::vector<std::string>& stages = stillStageGroups();
    const std::vector<std::string>& own = method.reads.params;
    if (std::find(stages.begin(), stages.end(), group) != stages.end() || std::find(own.begin(), own.end(), group) != own.end())
        return true;
    for (DenoiseMethod m : method.reads.combines)
        if (readsParamGroup(denoiseMethodInfo(m), group)) return true;
    return false;
}

bool readsWeights(const DenoiseMethodInfo& method) {
    bool w = method.reads.weights;
    for (DenoiseMethod m : method.reads.combines) w = w || readsWeights(denoiseMethodInfo(m));
    return w;
}

namespace {

// The parameters that switch a buffer off (the buffer is not read where the parameter is 0 or
// false), each applying to the methods that read its group.
struct BufferSwitch {
    Buffer buffer;
    const char* param;  // a row of denoiseParams()
};
constexpr BufferSwitch kSwitches[] = {
    {Buffer::Albedo, "demodulate"},
    {Buffer::Depth, "sigma_depth"},
    {Buffer::ObjectId, "use_ids"},
};

// The row of denoiseParams() named `name` and whether its value in `o` is 0 or false.
bool switchedOff(const DenoiseOptions& o, const char* name, const ParamField<DenoiseOptions>** row) {
    const ParamField<DenoiseOptions>* f = denoiseParams().find(name);
    *row = f;
    DenoiseOptions copy = o;
    const ParamRef r = f->at(copy);
    if (const bool* const* b = std::get_if<bool*>(&r)) return !**b;
    if (const float* const* x = std::get_if<float*>(&r)) return **x == 0.0f;
    if (const int* const* i = std::get_if<int*>(&r)) return **i == 0;
    return false;
}

// The switch that turns `b` off for a row's own reads (the stages' groups and its own), or null.
const ParamField<DenoiseOptions>* offSwitch(Buffer b, const DenoiseMethodInfo& m, const DenoiseOptions& o) {
    const std::vector<std::string>& stages = stillStageGroups();
    for (const BufferSwitch& s : kSwitches) {
        if (s.buffer != b) continue;
        const ParamField<DenoiseOptions>* row = nullptr;
        const std::string g = denoiseParams().find(s.param)->group;
        const bool applies = std::find(stages.begin(), stages.end(), g) != stages.end() ||
                             std::find(m.reads.params.begin(), m.reads.params.end(), g) != m.reads.params.end();
        if (applies && switchedOff(o, s.param, &row)) return row;
    }
    return nullptr;
}

}  // namespace

BufferMask methodReads(const DenoiseMethodInfo& m, const DenoiseOptions& o) {
    BufferMask r;
    for (int i = 0; i < kBufferCount; ++i) {
        const Buffer b = Buffer(i);
        if (m.reads.buffers.has(b) && !offSwitch(b, m, o)) r = r.with(b);
    }
    for (DenoiseMethod c : m.reads.combines) r = r | methodReads(denoiseMethodInfo(c), o);
    return r;
}

BufferMask denoiseReads(const DenoiseOptions& o, DenoiseMethod resolved) {
    BufferMask r{Buffer::Color, Buffer::Variance, Buffer::Emission, Buffer::Normal, Buffer::Depth};
    if (o.demodulate) r = r.with(Buffer::Albedo);
    if (resolved == DenoiseMethod::Refine) r = r.with(Buffer::Albedo);  // the network's input, demodulating or not
    r = r | methodReads(denoiseMethodInfo(resolved), o);
    // The ids are one image: the material id comes with the object id.
    if (r.has(Buffer::ObjectId)) r = r.with(Buffer::MaterialId);
    return r;
}

std::string unusedReason(Buffer b, const DenoiseOptions& o, DenoiseMethod resolved, bool noiseEstimated) {
    const DenoiseMethodInfo& m = denoiseMethodInfo(resolved);
    const bool preparation = b == Buffer::Color || b == Buffer::Variance || b == Buffer::Emission ||
                             (b == Buffer::Albedo && (o.demodulate || resolved == DenoiseMethod::Refine)) ||
                             ((b == Buffer::Normal || b == Buffer::Depth) && noiseEstimated);
    if (preparation || methodReads(m, o).has(b)) return "";
    // A switch of the row or of a row it combines that reads b.
    const ParamField<DenoiseOptions>* off = nullptr;
    std::vector<const DenoiseMethodInfo*> rows = {&m};
    for (size_t i = 0; i < rows.size() && !off; ++i) {
        if (rows[i]->reads.buffers.has(b)) off = offSwitch(b, *rows[i], o);
        for (DenoiseMethod c : rows[i]->reads.combines) rows.push_back(&denoiseMethodInfo(c));
    }
    if (off) {
        const std::string flag = denoiseParams().flag(*off);
        return off->kind() == ParamKind::Bool ? flag : flag + " 0";
    }
    return std::string("by ") + m.name;
}

}  // namespace atrous

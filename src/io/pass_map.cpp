#include "atrous/io/pass_map.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "atrous/error.h"

namespace atrous::io {

namespace {

// Pass names of each buffer by tier ('|' separates tiers), compared after lower-casing and mapping
// '_' and '-' to ' '. "" is the root layer (R, G, B without a prefix). Sources: Blender's pass
// names (Combined, Denoising Albedo, IndexOB...), Mitsuba's AOV types and common user names.
const char* const kRules[kBufferCount] = {
    "noisy image|combined,,color,colour,rgb,rgba,beauty,image,radiance,main",
    "variance,color variance,denoising variance",
    "denoising albedo,albedo,alb|diffcol,diffuse color,diffuse albedo,base color",
    "normal,normals,nn,sh normal,shading normal,n,nrm|denoising normal,geo normal,ng",
    "position,positions,p,pos,world position",
    "depth,z,dd,distance|denoising depth",
    "object index,indexob,shape index,object id,objectid,ids",
    "material index,indexma,material id,materialid",
    "emission,emit,emitted",
    "vector,motion,motion vector,motion vectors,mv,velocity",
};

std::string norm(std::string s) {
    for (char& c : s) {
        c = char(std::tolower(static_cast<unsigned char>(c)));
        if (c == '_' || c == '-') c = ' ';
    }
    return s;
}

std::vector<std::vector<std::string>> tiersOf(Buffer b) {
    std::vector<std::vector<std::string>> tiers(1);
    std::string cur;
    const std::string rule = kRules[int(b)];
    for (size_t i = 0; i <= rule.size(); ++i) {
        const char c = i < rule.size() ? rule[i] : '\0';
        if (c == ',' || c == '|' || c == '\0') {
            tiers.back().push_back(cur);
            cur.clear();
            if (c == '|') tiers.emplace_back();
        } else {
            cur += c;
        }
    }
    return tiers;
}

std::string where(const ExrInfo& info, const ExrLayer& layer) {
    const ExrChannelInfo& ch = info.channels[size_t(layer.channels[0])];
    const std::string& part = info.parts[size_t(ch.part)].name;
    return info.parts.size() > 1 ? " (part '" + part + "')" : "";
}

std::string layerLabel(const ExrLayer& l) { return l.name.empty() ? "(root)" : "'" + l.name + "'"; }


bool inViewLayer(const ExrLayer& l, const std::string& viewLayer) {
    return viewLayer.empty() || l.prefix().empty() || l.prefix() == viewLayer;
}

}  // namespace

bool isSecondMomentLayer(const ExrLayer& l) { return l.name.rfind("m2_", 0) == 0; }

namespace {

// The channels of `layer` for buffer b, or an InputError naming the file and the layer.
std::vector<int> channelsFor(const ExrInfo& info, const ExrLayer& layer, Buffer b) {
    // Motion: X, Y of Blender's Vector (to the previous frame; Z, W point to the next one).
    std::vector<int> ch = pickComponents(info, layer, bufferChannels(b));
    if (ch.empty())
        throw InputError(info.path + where(info, layer) + ": layer " + layerLabel(layer) + " has no usable channels for " +
                         bufferName(b) + " (it has " + std::to_string(layer.components.size()) + ")");
    requireComponents(b, int(ch.size()), info.path + where(info, layer) + ": layer " + layerLabel(layer));
    return ch;
}

// The layer of the first tier that matches, or -1. Throws on two matches of one name.
int matchRules(const ExrInfo& info, Buffer b, const std::string& viewLayer, std::string& rule) {
    for (const auto& tier : tiersOf(b)) {
        for (const std::string& name : tier) {
            int found = -1;
            for (size_t i = 0; i < info.layers.size(); ++i) {
                const ExrLayer& l = info.layers[i];
                // Mitsuba's moment integrator writes each output twice, as itself and as "m2_<name>",
                // its samples' second moment: never a buffer by name (a --pass may still name it).
                if (!inViewLayer(l, viewLayer) || isSecondMomentLayer(l)) continue;
                const bool root = l.name.empty();
                const bool match = name.empty() ? root : !root && norm(l.passName()) == name;
                if (!match) continue;
                if (pickComponents(info, l, bufferChannels(b)).empty()) continue;  // e.g. alpha only
                if (found >= 0)
                    throw InputError(info.path + ": ambiguous " + std::string(bufferName(b)) + " pass: both " +
                                     layerLabel(info.layers[size_t(found)]) + where(info, info.layers[size_t(found)]) +
                                     " and " + layerLabel(l) + where(info, l) +
                                     " match; choose a view layer with --layer or a pass with --pass " + bufferName(b) + "=NAME");
                found = int(i);
            }
            if (found >= 0) {
                rule = name.empty() ? "root channels" : "pass name '" + info.layers[size_t(found)].passName() + "'";
                return found;
            }
        }
    }
    return -1;
}

// A --pass by a layer's full name, else by a pass name under `viewLayer` (--layer; all view layers
// when empty), else by a full channel name.
PassChoice requested(const ExrInfo& info, const PassRequest& r, const std::string& viewLayer) {
    PassChoice c;
    c.rule = "--pass " + std::string(bufferName(r.buffer)) + "=" + r.name;
    for (size_t i = 0; i < info.layers.size(); ++i)
        if (info.layers[i].name == r.name) {
            c.layer = int(i);
            c.channels = channelsFor(info, info.layers[i], r.buffer);
            return c;
        }
    int byPass = -1;
    for (size_t i = 0; i < info.layers.size(); ++i)
        if (!info.layers[i].name.empty() && info.layers[i].passName() == r.name && inViewLayer(info.layers[i], viewLayer)) {
            if (byPass >= 0)
                throw InputError(info.path + ": " + c.rule + " is ambiguous: layers '" + info.layers[size_t(byPass)].name +
                                 "' and '" + info.layers[i].name + "' (give the full layer name, or a view layer with --layer)");
            byPass = int(i);
        }
    if (byPass >= 0) {
        c.layer = byPass;
        c.channels = channelsFor(info, info.layers[size_t(byPass)], r.buffer);
        return c;
    }
    for (size_t i = 0; i < info.channels.size(); ++i)
        if (info.channels[i].fullName == r.name) {
            requireComponents(r.buffer, 1, info.path + ": " + c.rule + " (one channel)");
            c.channels = {int(i)};
            return c;
        }
    throw InputError(info.path + ": " + c.rule + " names no layer or channel of the file (layers: " + layerList(info) + ")");
}

}  // namespace


std::string layerList(const ExrInfo& info) {
    std::string s;
    for (const ExrLayer& l : info.layers) s += (s.empty() ? "" : ", ") + (l.name.empty() ? std::string("(root)") : l.name);
    return s;
}

Buffer parseBufferName(const std::string& name) {
    if (name == "ids") return Buffer::ObjectId;
    for (int i = 0; i < kBufferCount; ++i)
        if (name == bufferName(Buffer(i))) return Buffer(i);
    std::string all;
    for (int i = 0; i < kBufferCount; ++i) all += (all.empty() ? "" : ", ") + std::string(bufferName(Buffer(i)));
    throw InputError("unknown buffer '" + name + "' (expected one of " + all + ")");
}

void requireComponents(Buffer b, int have, const std::string& source) {
    if (have >= bufferChannels(b) || bufferTakesGrey(b)) return;
    const char* what = b == Buffer::Motion ? "motion needs 2 (an x and a y offset)" : b == Buffer::Normal ? "normal needs 3 (x, y, z)"
                                                                                               : "position needs 3 (x, y, z)";
    throw InputError(source + " has " + std::to_string(have) + " channel" + (have == 1 ? "" : "s") + "; " + what +
                     ", and one channel cannot stand for a direction or a point");
}

std::vector<PassRequest> parsePassRequests(const std::vector<std::string>& specs) {
    std::vector<PassRequest> out;
    for (const std::string& spec : specs) out.push_back(parsePassRequest(spec));
    requireDistinctPasses(out);
    return out;
}

void requireDistinctPasses(const std::vector<PassRequest>& requests) {
    for (size_t i = 0; i < requests.size(); ++i)
        for (size_t j = 0; j < i; ++j)
            if (requests[i].buffer == requests[j].buffer)
                throw InputError(std::string("--pass ") + bufferName(requests[i].buffer) + " given twice ('" + requests[j].name +
                                 "' and '" + requests[i].name + "'): name each buffer once");
}

PassRequest parsePassRequest(const std::string& spec) {
    const size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
        throw InputError("'" + spec + "': expected BUFFER=NAME (e.g. albedo=ViewLayer.Denoising Albedo)");
    return {parseBufferName(spec.substr(0, eq)), spec.substr(eq + 1)};
}


PassMap mapPasses(const ExrInfo& info, const std::vector<PassRequest>& requests, const std::string& viewLayer) {
    if (!viewLayer.empty()) {
        const bool any = std::any_of(info.layers.begin(), info.layers.end(),
                                     [&](const ExrLayer& l) { return l.prefix() == viewLayer; });
        if (!any) throw InputError(info.path + ": --layer '" + viewLayer + "': no pass under that view layer (layers: " +
                                   layerList(info) + ")");
    }
    PassMap m;
    for (const PassRequest& r : requests) m.pass[size_t(r.buffer)] = requested(info, r, viewLayer);
    for (int b = 0; b < kBufferCount; ++b) {
        PassChoice& c = m.pass[size_t(b)];
        if (c.found()) continue;
        c.layer = matchRules(info, Buffer(b), viewLayer, c.rule);
        if (c.layer >= 0) c.channels = channelsFor(info, info.layers[size_t(c.layer)], Buffer(b));
    }
    return m;
}

PassChoice passForFile(const ExrInfo& info, Buffer b, const std::vector<PassRequest>& requests,
                       const std::string& viewLayer) {
    for (const PassRequest& r : requests)
        if (r.buffer == b) return requested(info, r, viewLayer);
    std::vector<int> usable;
    for (size_t i = 0; i < info.layers.size(); ++i)
        if (!isSecondMomentLayer(info.layers[i]) && !pickComponents(info, info.layers[i], bufferChannels(b)).empty())
            usable.push_back(int(i));
    PassChoice c;
    if (usable.size() == 1) {
        c.layer = usable[0];
        c.rule = "the file's only layer";
        c.channels = channelsFor(info, info.layers[size_t(c.layer)], b);
        return c;
    }
    c.layer = matchRules(info, b, viewLayer, c.rule);
    if (c.layer < 0)
        throw InputError(info.path + ": has several layers (" + layerList(info) + ") and none is a " + bufferName(b) +
                         " pass; name one with --pass " + bufferName(b) + "=LAYER");
    c.channels = channelsFor(info, info.layers[size_t(c.layer)], b);
    return c;
}

std::vector<Image> readPasses(const ExrInfo& info, const std::vector<std::pair<Buffer, const PassChoice*>>& passes) {
    std::vector<std::vector<int>> sets;
    std::vector<std::string> whats;
    std::vector<int> outs;  // planes as the buffer takes them: depth and ids 1, motion 2, the rest 3
    for (const auto& [b, pass] : passes) {
        sets.push_back(pass->channels);
        outs.push_back(bufferChannels(b));
        whats.push_back(std::string(bufferName(b)) + " pass" +
                        (pass->layer >= 0 ? " " + layerLabel(info.layers[size_t(pass->layer)]) : std::string()));
    }
    std::vector<Image> images = readExrChannelSets(info, sets, whats, outs);
    for (size_t k = 0; k < images.size(); ++k) conformBuffer(passes[k].first, images[k]);
    return images;
}

Image readPass(const ExrInfo& info, const PassChoice& pass, Buffer b) { return std::move(readPasses(info, {{b, &pass}})[0]); }

void conformBuffer(Buffer b, Image& img) {
    const size_t n = img.plane();
    float* r = img.data();
    float* g = img.channels() > 1 ? r + n : r;
    float* bl = img.channels() > 2 ? r + 2 * n : r;
    switch (b) {
        case Buffer::Normal:
            for (size_t i = 0; i < n; ++i) {
                const float x = r[i], y = g[i], z = bl[i];
                const float l2 = x * x + y * y + z * z;
                // Longer than unit: unnormalised (scaled) normals are brought to length 1. Shorter
                // ones are kept: a pixel's mean over samples across an edge is shorter, which the
                // normal stop reads as the edge it is; zero stays zero (background).
                const bool finite = std::isfinite(l2);
                const float s = !finite ? 0.0f : l2 > 1.0001f ? 1.0f / std::sqrt(l2) : 1.0f;
                r[i] = x * s, g[i] = y * s, bl[i] = z * s;
                if (!finite) r[i] = g[i] = bl[i] = 0.0f;
            }
            break;
        case Buffer::Depth:
            for (size_t i = 0; i < 3 * n && i < img.channels() * n; ++i) {
                const float z = r[i];
                if (!(z > 0.0f) || !(z < 1e9f)) r[i] = 1e30f;  // NaN, Inf, 0 or the 1e10 of Cycles: background
            }
            break;
        case Buffer::Albedo:
            // Cycles' Denoising Albedo carries a visible emitter's radiance (30 on a panel light) and
            // its background's colour: a reflectance is at most 1 (non-finite: 1, no demodulation).
            for (size_t i = 0; i < img.channels() * n; ++i) r[i] = std::isfinite(r[i]) ? std::min(std::max(r[i], 0.0f), 1.0f) : 1.0f;
            break;
        case Buffer::Position:
        case Buffer::ObjectId:
        case Buffer::MaterialId:
        case Buffer::Motion:
            for (size_t i = 0; i < img.channels() * n; ++i)
                if (!std::isfinite(r[i])) r[i] = 0.0f;
            break;
        default: break;
    }
}

std::string describeLayer(const ExrInfo& info, const ExrLayer& layer) {
    std::string comps, types;
    for (size_t i = 0; i < layer.components.size(); ++i) {
        comps += (i ? "," : "") + layer.components[i];
        const std::string& t = info.channels[size_t(layer.channels[i])].type;
        if (types.find(t) == std::string::npos) types += (types.empty() ? "" : "/") + t;
    }
    return (layer.name.empty() ? std::string("(root)") : layer.name) + "  [" + comps + "] " + types + where(info, layer);
}

}  // namespace atrous::io

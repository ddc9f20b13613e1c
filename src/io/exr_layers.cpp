#include "io/exr_layers.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfTestFile.h>
#include <half.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "atrous/error.h"
#include "io/image_io.h"

namespace atrous::io {

namespace {

std::string lastComponent(const std::string& name) {
    const size_t dot = name.rfind('.');
    return dot == std::string::npos ? name : name.substr(dot + 1);
}
std::string withoutLastComponent(const std::string& name) {
    const size_t dot = name.rfind('.');
    return dot == std::string::npos ? std::string() : name.substr(0, dot);
}

const char* typeName(Imf::PixelType t) {
    switch (t) {
        case Imf::HALF: return "half";
        case Imf::FLOAT: return "float";
        case Imf::UINT: return "uint";
        default: return "unknown";
    }
}

bool isAlpha(const std::string& c) { return c == "A" || c == "a" || c == "alpha" || c == "Alpha"; }

size_t pixelBytes(Imf::PixelType t) { return t == Imf::HALF ? 2 : 4; }

std::string describeSize(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace

std::string ExrLayer::prefix() const { return withoutLastComponent(name); }
std::string ExrLayer::passName() const { return lastComponent(name); }

bool isExrFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char magic[4] = {0, 0, 0, 0};
    in.read(reinterpret_cast<char*>(magic), 4);
    return in.gcount() == 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01;
}

ExrInfo inspectExr(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(path + ": file not found");
    if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": is a directory, not an EXR file");
    if (!isExrFile(path)) throw InputError(path + ": not an OpenEXR file (no EXR magic number)");
    ExrInfo info;
    info.path = path;
    try {
        Imf::MultiPartInputFile file(path.c_str());
        const int parts = file.parts();
        for (int p = 0; p < parts; ++p) {
            const Imf::Header& hd = file.header(p);
            ExrPartInfo part;
            part.name = hd.hasName() ? hd.name() : std::string();
            part.type = hd.hasType() ? hd.type() : std::string(Imf::SCANLINEIMAGE);
            const Imath::Box2i dw = hd.dataWindow();
            const long w = long(dw.max.x) - dw.min.x + 1, h = long(dw.max.y) - dw.min.y + 1;
            if (w <= 0 || h <= 0 || w > kMaxImageDim || h > kMaxImageDim)
                throw InputError(path + ": part " + std::to_string(p) + (part.name.empty() ? "" : " '" + part.name + "'") +
                                 ": unsupported image size " + std::to_string(w) + "x" + std::to_string(h));
            part.width = int(w);
            part.height = int(h);
            for (auto it = hd.channels().begin(); it != hd.channels().end(); ++it) {
                ExrChannelInfo ch;
                ch.part = p;
                ch.name = it.name();
                ch.type = typeName(it.channel().type);
                const bool qualified = parts > 1 && !part.name.empty() && ch.name.rfind(part.name + ".", 0) != 0;
                ch.fullName = qualified ? part.name + "." + ch.name : ch.name;
                info.channels.push_back(ch);
            }
            info.parts.push_back(part);
        }
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot read EXR header (" + e.what() + ")");
    }
    if (info.parts.empty()) throw InputError(path + ": EXR file has no parts");
    info.width = info.parts[0].width;
    info.height = info.parts[0].height;
    std::map<std::string, size_t> layerIndex;
    for (size_t i = 0; i < info.channels.size(); ++i) {
        const std::string layerName = withoutLastComponent(info.channels[i].fullName);
        auto it = layerIndex.find(layerName);
        if (it == layerIndex.end()) {
            it = layerIndex.emplace(layerName, info.layers.size()).first;
            info.layers.push_back(ExrLayer{layerName, {}, {}});
        }
        info.layers[it->second].channels.push_back(int(i));
        info.layers[it->second].components.push_back(lastComponent(info.channels[i].fullName));
    }
    return info;
}

std::vector<int> pickComponents(const ExrInfo& info, const ExrLayer& layer, int count) {
    (void)info;
    auto find = [&](const char* c) -> int {
        for (size_t i = 0; i < layer.components.size(); ++i)
            if (layer.components[i] == c) return layer.channels[i];
        return -1;
    };
    std::vector<int> usable;
    for (size_t i = 0; i < layer.components.size(); ++i)
        if (!isAlpha(layer.components[i])) usable.push_back(layer.channels[i]);
    if (usable.empty()) return {};
    if (count == 1) {
        for (const char* c : {"Z", "V", "Y", "R", "X", "z", "y", "r", "x"})
            if (find(c) >= 0) return {find(c)};
        return {usable[0]};
    }
    static const char* const kTriples[][3] = {{"R", "G", "B"}, {"X", "Y", "Z"}, {"r", "g", "b"},
                                              {"x", "y", "z"}, {"U", "V", "W"}, {"u", "v", "w"}};
    if (count == 2) {
        for (const auto& t : kTriples) {
            const int a = find(t[0]), b = find(t[1]);
            if (a >= 0 && b >= 0) return {a, b};
        }
    }
    for (const auto& t : kTriples) {
        const int a = find(t[0]), b = find(t[1]), c = find(t[2]);
        if (a >= 0 && b >= 0 && c >= 0) return {a, b, c};
    }
    if (usable.size() == 1) return {usable[0]};
    if (int(usable.size()) >= count) return std::vector<int>(usable.begin(), usable.begin() + count);
    return {};
}

std::vector<Image> readExrChannelSets(const ExrInfo& info, const std::vector<std::vector<int>>& sets,
                                      const std::vector<std::string>& whats) {
    const int w = info.width, h = info.height;
    std::vector<Image> images;
    for (size_t k = 0; k < sets.size(); ++k) {
        if (sets[k].empty() || sets[k].size() > 3)
            throw InputError(info.path + ": " + whats[k] + ": no channels to read");
        images.emplace_back(w, h, 3);
    }
    // A channel taken by two sets is read once and copied: (source plane, destination plane).
    std::vector<std::pair<const float*, float*>> copies;
    std::map<int, const float*> readInto;
    std::string what;
    try {
        Imf::MultiPartInputFile file(info.path.c_str());
        // One frame buffer per part: each part is decoded once for all the sets.
        std::map<int, Imf::FrameBuffer> buffers;
        for (size_t k = 0; k < sets.size(); ++k) {
            what = whats[k];
            for (size_t j = 0; j < sets[k].size(); ++j) {
                const ExrChannelInfo& ch = info.channels.at(size_t(sets[k][j]));
                const ExrPartInfo& part = info.parts[size_t(ch.part)];
                if (part.width != w || part.height != h)
                    throw InputError(info.path + ": part '" + part.name + "' (" + what + ") is " +
                                     describeSize(part.width, part.height) + " but the first part is " + describeSize(w, h));
                if (part.type.rfind("deep", 0) == 0)
                    throw InputError(info.path + ": part '" + part.name + "' (" + what + ") is a deep image, which atrous cannot read");
                float* plane = images[k].view().channel(int(j));
                auto seen = readInto.find(sets[k][j]);
                if (seen != readInto.end()) {
                    copies.emplace_back(seen->second, plane);
                    continue;
                }
                readInto.emplace(sets[k][j], plane);
                const Imath::Box2i dw = file.header(ch.part).dataWindow();
                const size_t xs = sizeof(float), ys = sizeof(float) * size_t(w);
                char* base = reinterpret_cast<char*>(plane) - dw.min.x * long(xs) - dw.min.y * long(ys);
                buffers[ch.part].insert(ch.name.c_str(), Imf::Slice(Imf::FLOAT, base, xs, ys, 1, 1, 0.0));
            }
        }
        what = sets.size() == 1 ? whats[0] : "its passes";
        for (auto& [p, fb] : buffers) {
            Imf::InputPart part(file, p);
            part.setFrameBuffer(fb);
            const Imath::Box2i dw = part.header().dataWindow();
            part.readPixels(dw.min.y, dw.max.y);
        }
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(info.path + ": cannot read " + what + " (" + e.what() + ")");
    }
    const size_t plane = size_t(w) * size_t(h);
    for (const auto& [from, to] : copies) std::copy(from, from + plane, to);
    for (size_t k = 0; k < sets.size(); ++k) {
        float* d = images[k].data();
        if (sets[k].size() == 1) {
            std::copy(d, d + plane, d + plane);
            std::copy(d, d + plane, d + 2 * plane);
        } else if (sets[k].size() == 2) {
            std::fill(d + 2 * plane, d + 3 * plane, 0.0f);
        }
    }
    return images;
}

Image readExrChannels(const ExrInfo& info, const std::vector<int>& channels, const std::string& what) {
    return std::move(readExrChannelSets(info, {channels}, {what})[0]);
}

namespace {

// Pixels of every channel of one part, at the channel's own type, in one block per channel.
struct PartPixels {
    Imf::Header header;
    std::vector<std::pair<std::string, Imf::PixelType>> channels;
    std::vector<std::vector<char>> data;
};

std::vector<PartPixels> readAllParts(const ExrInfo& source) {
    std::vector<PartPixels> parts;
    try {
        Imf::MultiPartInputFile file(source.path.c_str());
        for (int p = 0; p < file.parts(); ++p) {
            PartPixels pp;
            pp.header = file.header(p);
            const std::string type = pp.header.hasType() ? pp.header.type() : std::string(Imf::SCANLINEIMAGE);
            if (type.rfind("deep", 0) == 0)
                throw InputError(source.path + ": part " + std::to_string(p) + " is a deep image: cannot copy it");
            const Imath::Box2i dw = pp.header.dataWindow();
            const size_t w = size_t(dw.max.x - dw.min.x + 1), h = size_t(dw.max.y - dw.min.y + 1);
            Imf::FrameBuffer fb;
            for (auto it = pp.header.channels().begin(); it != pp.header.channels().end(); ++it) {
                const Imf::Channel& c = it.channel();
                if (c.xSampling != 1 || c.ySampling != 1)
                    throw InputError(source.path + ": channel '" + std::string(it.name()) +
                                     "' is subsampled: atrous cannot copy it");
                const size_t bytes = pixelBytes(c.type);
                pp.channels.emplace_back(it.name(), c.type);
                pp.data.emplace_back(w * h * bytes);
            }
            for (size_t i = 0; i < pp.channels.size(); ++i) {
                const size_t bytes = pixelBytes(pp.channels[i].second);
                char* base = pp.data[i].data() - dw.min.x * long(bytes) - dw.min.y * long(bytes * w);
                fb.insert(pp.channels[i].first.c_str(), Imf::Slice(pp.channels[i].second, base, bytes, bytes * w));
            }
            Imf::InputPart part(file, p);
            part.setFrameBuffer(fb);
            part.readPixels(dw.min.y, dw.max.y);
            // Tiled parts are written back as scanlines (the pixels are the same).
            pp.header.setType(Imf::SCANLINEIMAGE);
            if (pp.header.hasTileDescription()) pp.header.erase("tiles");
            if (pp.header.lineOrder() == Imf::RANDOM_Y) pp.header.lineOrder() = Imf::INCREASING_Y;
            parts.push_back(std::move(pp));
        }
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(source.path + ": cannot read EXR (" + e.what() + ")");
    }
    return parts;
}

// Adds the float planes of `layer` as channels "<prefix><component>" to a part.
void addLayerChannels(PartPixels& pp, const ExrOutLayer& layer, const std::string& prefix, const std::string& path) {
    const Imath::Box2i dw = pp.header.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    if (!layer.image || layer.image->width() != w || layer.image->height() != h ||
        layer.image->channels() < int(layer.components.size()))
        throw InputError(path + ": layer '" + layer.name + "' does not match the file's size " + describeSize(w, h));
    for (size_t c = 0; c < layer.components.size(); ++c) {
        const std::string name = prefix + layer.components[c];
        if (pp.header.channels().findChannel(name))
            throw InputError(path + ": the file already has a channel '" + name + "' (choose another pass name)");
        pp.header.channels().insert(name, Imf::Channel(Imf::FLOAT));
        const float* plane = layer.image->view().channel(int(c));
        std::vector<char> bytes(size_t(w) * size_t(h) * sizeof(float));
        std::memcpy(bytes.data(), plane, bytes.size());
        pp.channels.emplace_back(name, Imf::FLOAT);
        pp.data.push_back(std::move(bytes));
    }
}

void writeParts(const std::string& path, std::vector<PartPixels>& parts) {
    writeFileAtomically(path, [&](const std::string& tmp) {
        try {
            std::vector<Imf::Header> headers;
            for (auto& pp : parts) headers.push_back(pp.header);
            Imf::MultiPartOutputFile file(tmp.c_str(), headers.data(), int(headers.size()));
            for (size_t p = 0; p < parts.size(); ++p) {
                PartPixels& pp = parts[p];
                const Imath::Box2i dw = pp.header.dataWindow();
                const size_t w = size_t(dw.max.x - dw.min.x + 1);
                Imf::FrameBuffer fb;
                for (size_t i = 0; i < pp.channels.size(); ++i) {
                    const size_t bytes = pixelBytes(pp.channels[i].second);
                    char* base = pp.data[i].data() - dw.min.x * long(bytes) - dw.min.y * long(bytes * w);
                    fb.insert(pp.channels[i].first.c_str(), Imf::Slice(pp.channels[i].second, base, bytes, bytes * w));
                }
                Imf::OutputPart out(file, int(p));
                out.setFrameBuffer(fb);
                out.writePixels(dw.max.y - dw.min.y + 1);
            }
        } catch (const InputError&) {
            throw;
        } catch (const std::exception& e) {
            throw RuntimeError(path + ": cannot write EXR (" + e.what() + ")");
        }
    });
}

}  // namespace

void writeExrWithLayers(const std::string& outPath, const ExrInfo& source, const std::vector<ExrOutLayer>& added) {
    std::vector<PartPixels> parts = readAllParts(source);
    if (parts.size() == 1) {
        for (const ExrOutLayer& l : added) addLayerChannels(parts[0], l, l.name.empty() ? "" : l.name + ".", outPath);
    } else {
        const std::string viewLayer = withoutLastComponent(source.parts[0].name);
        std::set<std::string> names;
        for (const auto& pp : parts)
            if (pp.header.hasName()) names.insert(pp.header.name());
        for (const ExrOutLayer& l : added) {
            PartPixels pp;
            pp.header = parts[0].header;
            pp.header.channels() = Imf::ChannelList();
            pp.header.setName(viewLayer.empty() ? l.name : viewLayer + "." + l.name);
            if (!names.insert(pp.header.name()).second)
                throw InputError(outPath + ": the file already has a part '" + pp.header.name() + "' (choose another pass name)");
            // Blender names the channels of a part "<part name>.<component>".
            const bool qualified = parts[0].channels.empty() ? false
                                   : parts[0].channels[0].first.rfind(source.parts[0].name + ".", 0) == 0;
            addLayerChannels(pp, l, qualified ? pp.header.name() + "." : "", outPath);
            parts.push_back(std::move(pp));
        }
    }
    writeParts(outPath, parts);
}

void writeLayeredExr(const std::string& path, const std::vector<ExrOutLayer>& layers, bool multipart, bool halfFloat) {
    if (layers.empty()) throw InputError(path + ": no layers to write");
    const int w = layers[0].image->width(), h = layers[0].image->height();
    std::vector<PartPixels> parts;
    auto newPart = [&](const std::string& name) {
        PartPixels pp;
        pp.header = Imf::Header(w, h);
        pp.header.compression() = Imf::ZIP_COMPRESSION;
        if (!name.empty() || multipart) pp.header.setName(name.empty() ? "rgba" : name);
        pp.header.setType(Imf::SCANLINEIMAGE);
        return pp;
    };
    if (!multipart) parts.push_back(newPart(""));
    for (const ExrOutLayer& l : layers) {
        if (multipart) parts.push_back(newPart(l.name));
        addLayerChannels(parts.back(), l, l.name.empty() ? "" : l.name + ".", path);
    }
    if (halfFloat) {
        for (auto& pp : parts) {
            Imf::ChannelList list;
            for (size_t i = 0; i < pp.channels.size(); ++i) {
                const size_t n = pp.data[i].size() / sizeof(float);
                std::vector<char> hb(n * sizeof(half));
                const float* f = reinterpret_cast<const float*>(pp.data[i].data());
                half* o = reinterpret_cast<half*>(hb.data());
                for (size_t k = 0; k < n; ++k) o[k] = half(f[k]);
                pp.data[i] = std::move(hb);
                pp.channels[i].second = Imf::HALF;
                list.insert(pp.channels[i].first, Imf::Channel(Imf::HALF));
            }
            pp.header.channels() = list;
        }
    }
    writeParts(path, parts);
}

}  // namespace atrous::io

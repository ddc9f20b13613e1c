#include "atrous/io/exr_layers.h"

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
#include <memory>
#include <set>

#include "atrous/error.h"
#include "io/exr_core.h"
#include "io/exr_limits.h"
#include "atrous/io/image_io.h"

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
    requireExrHeadersFit(path);
    ExrInfo info;
    info.path = path;
    try {
        Imf::MultiPartInputFile file(path.c_str());
        const int parts = file.parts();
        std::vector<const Imf::Header*> headers;
        std::vector<std::string> labels;
        for (int p = 0; p < parts; ++p) {
            const Imf::Header& hd = file.header(p);
            ExrPartInfo part;
            part.name = hd.hasName() ? hd.name() : std::string();
            part.type = hd.hasType() ? hd.type() : std::string(Imf::SCANLINEIMAGE);
            headers.push_back(&hd);
            labels.push_back(parts == 1 ? std::string() : "part " + std::to_string(p) + (part.name.empty() ? "" : " '" + part.name + "'"));
            const Imath::Box2i dw = hd.dataWindow();
            part.x0 = dw.min.x;
            part.y0 = dw.min.y;
            part.width = int(std::min<long>(long(dw.max.x) - dw.min.x + 1, kMaxImageDim + 1L));
            part.height = int(std::min<long>(long(dw.max.y) - dw.min.y + 1, kMaxImageDim + 1L));
            for (auto it = hd.channels().begin(); it != hd.channels().end(); ++it) {
                ExrChannelInfo ch;
                ch.part = p;
                ch.name = it.name();
                ch.type = typeName(it.channel().type);
                ch.xSampling = it.channel().xSampling;
                ch.ySampling = it.channel().ySampling;
                const bool qualified = parts > 1 && !part.name.empty() && ch.name.rfind(part.name + ".", 0) != 0;
                ch.fullName = qualified ? part.name + "." + ch.name : ch.name;
                info.channels.push_back(ch);
            }
            info.parts.push_back(part);
        }
        if (parts > 0) {
            // Every part's size against what the file can hold, before anything is allocated.
            requireExrFits(path, headers, labels);
            const ExrWindow win = exrImageWindow(path, file.header(0));
            info.x0 = win.x0;
            info.y0 = win.y0;
            info.width = win.width;
            info.height = win.height;
        }
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot read EXR header (" + e.what() + ")");
    }
    if (info.parts.empty()) throw InputError(path + ": EXR file has no parts");
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
                                      const std::vector<std::string>& whats, const std::vector<int>& outChannels) {
    auto outOf = [&](size_t k) { return k < outChannels.size() ? std::max(outChannels[k], int(sets[k].size())) : 3; };
    const int w = info.width, h = info.height;
    const ExrWindow win{info.x0, info.y0, w, h};
    // Every channel of every set is checked before anything is allocated or decoded.
    for (size_t k = 0; k < sets.size(); ++k) {
        if (sets[k].empty() || sets[k].size() > 3)
            throw InputError(info.path + ": " + whats[k] + ": no channels to read");
        for (int c : sets[k]) {
            const ExrChannelInfo& ch = info.channels.at(size_t(c));
            const ExrPartInfo& part = info.parts[size_t(ch.part)];
            const std::string label = part.name.empty() ? "part " + std::to_string(ch.part) : "part '" + part.name + "'";
            if (part.type.rfind("deep", 0) == 0)
                throw InputError(info.path + ": " + label + " (" + whats[k] + ") is a deep image, which atrous cannot read");
            const Imath::Box2i dw(Imath::V2i(part.x0, part.y0), Imath::V2i(part.x0 + part.width - 1, part.y0 + part.height - 1));
            if (!exrCovers(dw, win))
                throw InputError(info.path + ": " + label + " (" + whats[k] + ") has the data window (" + std::to_string(part.x0) +
                                 "," + std::to_string(part.y0) + ")-(" + std::to_string(dw.max.x) + "," + std::to_string(dw.max.y) +
                                 "), which does not cover the image's (" + std::to_string(win.x0) + "," + std::to_string(win.y0) +
                                 ")-(" + std::to_string(win.x0 + w - 1) + "," + std::to_string(win.y0 + h - 1) + ")");
        }
    }
    // A channel taken by two sets is read once and copied: (source plane, destination plane).
    std::vector<std::pair<int, std::pair<size_t, int>>> copies;  // channel -> (set, component)
    std::map<int, std::vector<std::pair<size_t, int>>> byPart;   // part -> the (set, component) it fills
    std::map<int, std::pair<size_t, int>> firstUse;
    for (size_t k = 0; k < sets.size(); ++k)
        for (size_t j = 0; j < sets[k].size(); ++j) {
            const int c = sets[k][j];
            auto seen = firstUse.find(c);
            if (seen != firstUse.end()) {
                copies.push_back({c, {k, int(j)}});
                continue;
            }
            firstUse.emplace(c, std::make_pair(k, int(j)));
            byPart[info.channels[size_t(c)].part].push_back({k, int(j)});
        }
    for (const auto& [p, uses] : byPart)
        for (const auto& use : uses) {
            const ExrChannelInfo& ch = info.channels[size_t(sets[use.first][size_t(use.second)])];
            if (ch.xSampling != 1 || ch.ySampling != 1)
                throw InputError(info.path + ": channel '" + ch.fullName + "' (" + whats[use.first] + ") is subsampled (" +
                                 std::to_string(ch.xSampling) + "x" + std::to_string(ch.ySampling) +
                                 "), which atrous cannot read");
        }
    auto partLabel = [&](int p) {
        return info.parts[size_t(p)].name.empty() ? "part " + std::to_string(p) : "part '" + info.parts[size_t(p)].name + "'";
    };
    auto requestsOf = [&](const std::vector<std::pair<size_t, int>>& uses, std::vector<Image>& images) {
        std::vector<ExrPlaneRequest> r;
        for (const auto& use : uses)
            r.push_back({info.channels[size_t(sets[use.first][size_t(use.second)])].name, images[use.first].view().channel(use.second)});
        return r;
    };
    std::string what = sets.size() == 1 ? whats[0] : "its passes";
    std::vector<Image> images;
    try {
        // Scanline parts (every renderer's output seen so far) through OpenEXR's Core API, chunks in
        // parallel; their chunks are located and checked before anything is allocated (exr_core.h).
        ExrCoreFile core(info.path);
        std::vector<int> classic;
        for (const auto& [p, uses] : byPart) {
            if (core.decodes(p))
                core.locate(p, win, partLabel(p));
            else
                classic.push_back(p);
        }
        std::unique_ptr<Imf::MultiPartInputFile> file;
        if (!classic.empty()) {
            file = std::make_unique<Imf::MultiPartInputFile>(info.path.c_str());
            // Rule 3 of exr_limits.h for tiled parts: their rows decoded into one row first.
            if (exrNeedsProof(uint64_t(sets.size()) * 12 * uint64_t(w) * uint64_t(h), exrFileBytes(info.path)))
                for (int p : classic) {
                    Imf::InputPart part(*file, p);
                    std::vector<std::string> names;
                    for (const auto& use : byPart[p]) names.push_back(info.channels[size_t(sets[use.first][size_t(use.second)])].name);
                    proveExrRows(part, names, win.y0, win.y0 + h - 1);
                }
        }
        // Every plane is written below (decoded, copied, or filled): no zero fill first.
        for (size_t k = 0; k < sets.size(); ++k) images.push_back(Image::uninitialized(w, h, outOf(k)));
        for (const auto& [p, uses] : byPart) {
            const std::vector<ExrPlaneRequest> req = requestsOf(uses, images);
            if (std::find(classic.begin(), classic.end(), p) == classic.end()) {
                core.decode(p, req, win, partLabel(p));
                continue;
            }
            Imf::InputPart part(*file, p);
            std::vector<std::string> names;
            std::vector<float*> planes;
            for (const auto& r : req) names.push_back(r.channel), planes.push_back(r.plane);
            readExrPlanes(part, names, planes, win);
        }
    } catch (const InputError&) {
        throw;
    } catch (const RuntimeError& e) {
        throw RuntimeError(info.path + ": " + e.what());
    } catch (const std::bad_alloc&) {
        throw RuntimeError(info.path + ": out of host memory reading " + what);
    } catch (const std::exception& e) {
        throw InputError(info.path + ": cannot read " + what + " (" + e.what() + ")");
    }
    const size_t plane = size_t(w) * size_t(h);
    for (const auto& [c, to] : copies) {
        const auto& from = firstUse.at(c);
        const float* src = images[from.first].view().channel(from.second);
        std::copy(src, src + plane, images[to.first].view().channel(to.second));
    }
    for (size_t k = 0; k < sets.size(); ++k) {
        float* d = images[k].data();
        for (int c = int(sets[k].size()); c < images[k].channels(); ++c) {
            if (sets[k].size() == 1)
                std::copy(d, d + plane, d + size_t(c) * plane);  // one channel: repeated
            else
                std::fill(d + size_t(c) * plane, d + size_t(c + 1) * plane, 0.0f);  // two: B = 0
        }
    }
    return images;
}

Image readExrChannels(const ExrInfo& info, const std::vector<int>& channels, const std::string& what) {
    return std::move(readExrChannelSets(info, {channels}, {what}, {})[0]);
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
            Imf::InputPart part(file, p);
            Imf::FrameBuffer fb;
            std::vector<std::string> names;
            uint64_t partBytes = 0;
            for (auto it = pp.header.channels().begin(); it != pp.header.channels().end(); ++it) {
                const Imf::Channel& c = it.channel();
                if (c.xSampling != 1 || c.ySampling != 1)
                    throw InputError(source.path + ": channel '" + std::string(it.name()) +
                                     "' is subsampled: atrous cannot copy it");
                names.push_back(it.name());
                partBytes += uint64_t(w) * h * pixelBytes(c.type);
            }
            // exr_limits.h, rule 3: the chunks are proven before the copy's planes are allocated.
            if (!names.empty() && exrNeedsProof(partBytes, exrFileBytes(source.path)))
                proveExrRows(part, names, dw.min.y, dw.max.y);
            for (auto it = pp.header.channels().begin(); it != pp.header.channels().end(); ++it) {
                pp.channels.emplace_back(it.name(), it.channel().type);
                pp.data.emplace_back(w * h * pixelBytes(it.channel().type));
            }
            for (size_t i = 0; i < pp.channels.size(); ++i) {
                const size_t bytes = pixelBytes(pp.channels[i].second);
                char* base = pp.data[i].data() - dw.min.x * long(bytes) - dw.min.y * long(bytes * w);
                fb.insert(pp.channels[i].first.c_str(), Imf::Slice(pp.channels[i].second, base, bytes, bytes * w));
            }
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

// Adds the float planes of `layer` as channels "<prefix><component>" to a part. The image's pixel
// (0, 0) is the file's pixel `origin` (the image window of exr_limits.h), inside the part's data
// window; the part's pixels outside the image are 0.
void addLayerChannels(PartPixels& pp, const ExrOutLayer& layer, const std::string& prefix, const std::string& path,
                      Imath::V2i origin) {
    const Imath::Box2i dw = pp.header.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    const int ox = origin.x - dw.min.x, oy = origin.y - dw.min.y;
    if (!layer.image || layer.image->channels() < int(layer.components.size()) || ox < 0 || oy < 0 ||
        ox + layer.image->width() > w || oy + layer.image->height() > h)
        throw InputError(path + ": layer '" + layer.name + "' does not match the file's size " + describeSize(w, h));
    const int iw = layer.image->width(), ih = layer.image->height();
    for (size_t c = 0; c < layer.components.size(); ++c) {
        const std::string name = prefix + layer.components[c];
        if (pp.header.channels().findChannel(name))
            throw InputError(path + ": the file already has a channel '" + name + "' (choose another pass name)");
        pp.header.channels().insert(name, Imf::Channel(Imf::FLOAT));
        const float* plane = layer.image->view().channel(int(c));
        std::vector<char> bytes(size_t(w) * size_t(h) * sizeof(float));
        if (iw == w && ih == h) {
            std::memcpy(bytes.data(), plane, bytes.size());
        } else {
            float* dst = reinterpret_cast<float*>(bytes.data());
            for (int y = 0; y < ih; ++y)
                std::memcpy(dst + size_t(y + oy) * size_t(w) + size_t(ox), plane + size_t(y) * size_t(iw), size_t(iw) * sizeof(float));
        }
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
        for (const ExrOutLayer& l : added)
            addLayerChannels(parts[0], l, l.name.empty() ? "" : l.name + ".", outPath, Imath::V2i(source.x0, source.y0));
    } else {
        const std::string viewLayer = withoutLastComponent(source.parts[0].name);
        std::set<std::string> names;
        for (const auto& pp : parts)
            if (pp.header.hasName()) names.insert(pp.header.name());
        for (const ExrOutLayer& l : added) {
            PartPixels pp;
            pp.header = parts[0].header;
            pp.header.channels() = Imf::ChannelList();
            // The new part holds the image window alone (parts may have their own data windows).
            if (l.image)
                pp.header.dataWindow() = Imath::Box2i(Imath::V2i(source.x0, source.y0),
                                                      Imath::V2i(source.x0 + l.image->width() - 1, source.y0 + l.image->height() - 1));
            pp.header.setName(viewLayer.empty() ? l.name : viewLayer + "." + l.name);
            if (!names.insert(pp.header.name()).second)
                throw InputError(outPath + ": the file already has a part '" + pp.header.name() + "' (choose another pass name)");
            // Blender names the channels of a part "<part name>.<component>".
            const bool qualified = parts[0].channels.empty() ? false
                                   : parts[0].channels[0].first.rfind(source.parts[0].name + ".", 0) == 0;
            addLayerChannels(pp, l, qualified ? pp.header.name() + "." : "", outPath, Imath::V2i(source.x0, source.y0));
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
        addLayerChannels(parts.back(), l, l.name.empty() ? "" : l.name + ".", path, Imath::V2i(0, 0));
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

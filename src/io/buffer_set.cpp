#include "atrous/io/buffer_set.h"

#include <algorithm>
#include <filesystem>
#include <iterator>

#include "atrous/error.h"
#include "atrous/io/image_io.h"

namespace fs = std::filesystem;

namespace atrous::io {

namespace {

// The name of each buffer in a render directory ("" = none: the material ids come with ids.exr).
const char* const kDirBuffer[kBufferCount] = {"color", "variance", "albedo",   "normal", "position",
                                              "depth", "ids",      "",         "emission", "motion"};

std::string sizeOf(const Image& i) { return std::to_string(i.width()) + "x" + std::to_string(i.height()); }

// Object and material index passes (1 channel each) as atrous's ids buffer: R object, G material.
Image composeIds(const Image* object, const Image* material, int w, int h) {
    Image ids(w, h, 2);
    const size_t n = ids.plane();
    if (object) std::copy(object->data(), object->data() + n, ids.data());
    if (material) std::copy(material->data(), material->data() + n, ids.data() + n);
    return ids;
}

}  // namespace

Frame BufferSet::inputs() const { return refsOf(*this); }

Frame refsOf(const BufferSet& set) {
    Frame r;
    for (int b = 0; b < kBufferCount; ++b)
        if (Buffer(b) != Buffer::MaterialId) r.set(Buffer(b), &set.image[b]);  // its values are the ids' channel 1
    return r;
}

Frame refsOf(const SequenceFrame& f) {
    Frame r;
    r.set(Buffer::Color, &f.color).set(Buffer::Variance, &f.variance).set(Buffer::Albedo, &f.albedo);
    r.set(Buffer::Normal, &f.normal).set(Buffer::Position, &f.position).set(Buffer::Depth, &f.depth);
    r.set(Buffer::ObjectId, &f.ids).set(Buffer::Emission, &f.emission).set(Buffer::Motion, &f.motion);
    return r;
}


namespace {

// --layer names a view layer of every layered file it is applied to.
void requireViewLayer(const ExrInfo& info, const std::string& viewLayer) {
    if (viewLayer.empty()) return;
    for (const ExrLayer& l : info.layers)
        if (l.prefix() == viewLayer) return;
    throw InputError(info.path + ": --layer '" + viewLayer + "': no pass under that view layer (layers: " + layerList(info) + ")");
}

}  // namespace

Image readBufferFile(const std::string& path, Buffer b, const std::vector<PassRequest>& passes,
                     const std::string& viewLayer, std::string* from, bool* layered) {
    if (from) *from = path;
    if (layered) *layered = false;
    if (fs::is_regular_file(path) && isExrFile(path)) {
        const ExrInfo info = inspectExr(path);
        // Root R,G,B (atrous's own files, ids with mesh and material in R and G) are read whole.
        // (A file without channels has no layers: readImage refuses it below.)
        if (info.layers.size() > 1 || (info.layers.size() == 1 && !info.layers[0].name.empty())) {
            requireViewLayer(info, viewLayer);
            const PassChoice c = passForFile(info, b, passes, viewLayer);
            if (from && c.layer >= 0) *from = path + " (layer " + info.layers[size_t(c.layer)].name + ", " + c.rule + ")";
            if (layered) *layered = true;
            return readPass(info, c, b);
        }
    }
    // Held as the filters read them: depth 1 plane, ids 2 (atrous's ids.exr: R mesh, G material),
    // motion 2, the rest 3.
    int channels = 3;
    Image img = readImage(path, &channels, b == Buffer::ObjectId ? 2 : bufferChannels(b));
    requireComponents(b, channels, path);
    conformBuffer(b, img);
    return img;
}

std::vector<std::string> inputFiles(const BufferFiles& f) {
    std::vector<std::string> files;
    std::error_code ec;
    if (!f.in.empty()) {
        if (fs::is_directory(f.in, ec)) {
            for (const char* buffer : kDirBuffer)
                for (const std::string& name : dirBufferNames(buffer)) files.push_back((fs::path(f.in) / name).string());
        } else {
            files.push_back(f.in);
        }
    }
    for (const std::string& p : f.file)
        if (!p.empty()) files.push_back(p);
    return files;
}

std::vector<std::string> dirBufferNames(const std::string& buffer) {
    // atrous's name first; then LuxCore's (its film outputs, named as in its documentation).
    static const std::vector<std::pair<const char*, std::vector<std::string>>> kNames = {
        {"color", {"color.exr", "RGB.exr"}},
        {"variance", {"variance.exr"}},
        {"albedo", {"albedo.exr", "ALBEDO.exr"}},
        {"normal", {"normal.exr", "AVG_SHADING_NORMAL.exr", "SHADING_NORMAL.exr"}},
        {"position", {"position.exr", "POSITION.exr"}},
        {"depth", {"depth.exr", "DEPTH.exr"}},
        {"ids", {"ids.exr"}},
        {"emission", {"emission.exr", "EMISSION.exr"}},
        {"motion", {"motion.exr"}},
        {"reference", {"reference.exr"}},
    };
    for (const auto& [name, files] : kNames)
        if (buffer == name) return files;
    return {};
}

std::string dirBufferFile(const std::string& dir, const std::string& buffer) {
    for (const std::string& name : dirBufferNames(buffer)) {
        std::error_code ec;
        const fs::path p = fs::path(dir) / name;
        if (fs::exists(p, ec)) return p.string();
    }
    return "";
}

std::string withSourceFile(const std::string& msg, const std::function<std::string(const std::string&)>& fileOf,
                           const std::string& fallback) {
    static const char* const kNames[] = {"color", "variance", "albedo", "normal", "position", "depth", "ids", "emission", "motion"};
    for (const char* prefix : {"", "SVGF frame: the "})
        for (const char* name : kNames)
            if (msg.rfind(std::string(prefix) + name + " buffer", 0) == 0) {
                const std::string file = fileOf(name);
                if (!file.empty()) return file + ": " + msg;
            }
    return fallback.empty() ? msg : fallback + ": " + msg;
}

BufferSet loadBuffers(const BufferFiles& f) {
    requireDistinctPasses(f.passes);
    BufferSet s;
    bool layered[kBufferCount] = {};  // read from a layered EXR (where --pass and --layer apply)
    std::string dir;
    if (!f.in.empty()) {
        std::error_code ec;
        if (!fs::exists(f.in, ec)) throw InputError("--in '" + f.in + "': no such file or directory");
        if (fs::is_directory(f.in, ec)) {
            dir = f.in;
        } else {
            s.layered = std::make_shared<ExrInfo>(inspectExr(f.in));
        }
    }
    // Where each buffer comes from, before anything is decoded: an explicit file, the render
    // directory's file, or the layered file's pass.
    std::string pathOf[kBufferCount];
    PassMap m;
    bool present[kBufferCount] = {};
    for (int b = 0; b < kBufferCount; ++b) {
        pathOf[b] = f.file[b];
        if (pathOf[b].empty() && !dir.empty() && kDirBuffer[b][0]) pathOf[b] = dirBufferFile(dir, kDirBuffer[b]);
        present[b] = !pathOf[b].empty();
    }
    if (s.layered) {
        m = mapPasses(*s.layered, f.passes, f.viewLayer);
        for (int b = 0; b < kBufferCount; ++b) present[b] = present[b] || m.pass[size_t(b)].found();
    }
    // The caller's choice of what to decode (the buffers its method reads); the rest are noted.
    bool want[kBufferCount];
    for (int b = 0; b < kBufferCount; ++b) {
        want[b] = b == int(Buffer::Color) || !f.wanted || f.wanted(Buffer(b), present);
        if (Buffer(b) == Buffer::MaterialId) want[b] = want[int(Buffer::ObjectId)];
        if (present[b] && !want[b]) {
            s.skipped.push_back(Buffer(b));
            layered[b] = true;  // a --pass for it is not a flag that cannot apply: it is not needed
        }
    }
    if (s.layered) {
        const ExrInfo& info = *s.layered;
        if (!m[Buffer::Color].found() && f.file[int(Buffer::Color)].empty())
            throw InputError(f.in + ": no colour pass (layers: " + layerList(info) + "); name one with --pass color=LAYER");
        std::vector<std::pair<Buffer, const PassChoice*>> wanted;
        for (int b = 0; b < kBufferCount; ++b)
            if (m.pass[size_t(b)].found() && f.file[b].empty() && want[b]) wanted.emplace_back(Buffer(b), &m.pass[size_t(b)]);
        std::vector<Image> images = readPasses(info, wanted);
        Image object, material;
        for (size_t k = 0; k < wanted.size(); ++k) {
            const int b = int(wanted[k].first);
            const PassChoice& c = *wanted[k].second;
            Image& img = images[k];
            if (Buffer(b) == Buffer::Motion && c.layer >= 0 && info.layers[size_t(c.layer)].passName() == "Vector") {
                // Blender's Vector pass: X, Y = offset to the pixel's position in the previous frame
                // with y up; atrous's motion has y down (rows). Measured on the corpus's Cycles orbit
                // (scripts/corpus): median reprojection error 0.007 px with (X, -Y), 3.8 px with (X, Y).
                float* g = img.data() + img.plane();
                for (size_t i = 0; i < img.plane(); ++i) g[i] = -g[i];
                s.notes.push_back("motion: Blender's Vector pass (X, -Y: y up in Blender, down in atrous)");
            }
            const std::string label = c.layer >= 0 ? info.layers[size_t(c.layer)].name : info.channels[size_t(c.channels[0])].fullName;
            s.from[b] = f.in + " (" + (label.empty() ? std::string("root R,G,B") : label) + ", " + c.rule + ")";
            Image& dst = Buffer(b) == Buffer::ObjectId ? object : Buffer(b) == Buffer::MaterialId ? material : s.image[b];
            dst = std::move(img);
            layered[b] = true;
        }
        if (!object.empty() || !material.empty()) {
            const Image& any = object.empty() ? material : object;
            s.image[int(Buffer::ObjectId)] = composeIds(object.empty() ? nullptr : &object,
                                                        material.empty() ? nullptr : &material, any.width(), any.height());
        }
    }
    for (int b = 0; b < kBufferCount; ++b) {
        const std::string& path = pathOf[b];
        if (path.empty() || !want[b]) continue;
        // A layered file given for the ids (`--ids aovs.exr`) gives its object-index pass only;
        // atrous's own ids.exr (root R, G) is read whole: mesh and material ids.
        s.image[b] = readBufferFile(path, Buffer(b), f.passes, f.viewLayer, &s.from[b], &layered[b]);
        if (Buffer(b) == Buffer::ObjectId) layered[int(Buffer::MaterialId)] = layered[b];
    }
    // --pass and --layer pick layers of layered EXRs: refused where no layered file is read for them.
    const bool anyLayered = std::any_of(std::begin(layered), std::end(layered), [](bool v) { return v; });
    if (!f.viewLayer.empty() && !anyLayered)
        throw InputError("--layer '" + f.viewLayer + "': picks a view layer of a layered EXR, and none of the inputs is one");
    for (const PassRequest& r : f.passes) {
        const int b = int(r.buffer);
        if (layered[b]) continue;
        const std::string what = std::string("--pass ") + bufferName(r.buffer) + "=" + r.name;
        if (!s.from[b].empty())
            throw InputError(what + ": " + bufferName(r.buffer) + " is read from '" + s.from[b] +
                             "', a plain image (--pass picks a layer of a layered EXR)");
        throw InputError(what + ": no layered EXR among the inputs gives " + bufferName(r.buffer) +
                         " (--pass picks a layer of a layered EXR)");
    }
    if (s.image[int(Buffer::Color)].empty()) {
        if (!dir.empty()) throw InputError("--in '" + dir + "': no color.exr (or RGB.exr, LuxCore's) in it");
        throw InputError("no colour given: --color FILE, --in RENDER_DIR or --in LAYERED.exr");
    }
    const Image& color = s.image[int(Buffer::Color)];
    for (int b = 0; b < kBufferCount; ++b) {
        const Image& img = s.image[b];
        if (img.empty() || b == int(Buffer::Color)) continue;
        if (img.width() != color.width() || img.height() != color.height())
            throw InputError(std::string(bufferName(Buffer(b))) + " buffer '" + s.from[b] + "' is " + sizeOf(img) +
                             " but the color '" + s.from[int(Buffer::Color)] + "' is " + sizeOf(color));
    }
    return s;
}

}  // namespace atrous::io

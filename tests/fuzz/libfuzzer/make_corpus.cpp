// Writes the libFuzzer targets' seed corpora (tests/fuzz/libfuzzer/corpus/<target>/): small,
// valid (and a few deliberately odd) inputs of every kind the readers take, made with atrous's own
// writers (the files the CLI writes) and with OpenEXR directly (every compression, half and uint
// channels, tiled parts, luminance/chroma, offset data windows, Blender's and Mitsuba's layouts).
// Deterministic: running it again gives the same bytes.
//
//   build-fuzz/make_corpus tests/fuzz/libfuzzer/corpus
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfRgbaFile.h>
#include <ImfTiledOutputFile.h>
#include <ImfTiledOutputPart.h>
#include <half.h>
#include <stb_image_write.h>

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "atrous/image.h"
#include "atrous/io/exr_layers.h"
#include "atrous/io/image_io.h"

namespace atrous::filters {
extern const std::uint8_t kLearnedDefaultWeights[];
extern const std::size_t kLearnedDefaultWeightsSize;
}  // namespace atrous::filters

namespace fs = std::filesystem;
using atrous::Image;

namespace {

std::string gRoot;

std::string dir(const std::string& target) {
    const std::string d = gRoot + "/" + target;
    fs::create_directories(d);
    return d;
}

void writeBytes(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

std::string readBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

const float kNan = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();

// ------------------------------------------------------------------------------------------ EXR

using Fill = std::function<float(int x, int y)>;
struct Chan {
    std::string name;
    Imf::PixelType type = Imf::FLOAT;
    Fill f;
};
struct Part {
    std::string name;  // "" = no name attribute (single-part files only)
    int w = 8, h = 6;
    int x0 = 0, y0 = 0;  // data window origin
    Imf::Compression comp = Imf::ZIP_COMPRESSION;
    bool tiled = false;
    std::vector<Chan> chans;
};

Fill ramp(float a, float b) {
    return [=](int x, int y) { return a + b * float(x + 3 * y); };
}
Fill constant(float v) {
    return [=](int, int) { return v; };
}
// A few special values among ordinary ones.
Fill odd(float base) {
    return [=](int x, int y) {
        const int i = x + 8 * y;
        return i == 3 ? kNan : i == 7 ? kInf : i == 11 ? -kInf : i == 13 ? -1.0f : i == 17 ? 1e10f : base + 0.01f * float(i);
    };
}

std::vector<Chan> rgb(const std::string& prefix, Imf::PixelType t, Fill r, Fill g, Fill b) {
    return {{prefix + "R", t, r}, {prefix + "G", t, g}, {prefix + "B", t, b}};
}

// A multipart file's parts share one display window: the first part's data window.
Imf::Header headerOf(const Part& p, bool multipart, const Part& first) {
    const Imath::Box2i dw(Imath::V2i(p.x0, p.y0), Imath::V2i(p.x0 + p.w - 1, p.y0 + p.h - 1));
    const Imath::Box2i display(Imath::V2i(first.x0, first.y0), Imath::V2i(first.x0 + first.w - 1, first.y0 + first.h - 1));
    Imf::Header h(display, dw);
    h.compression() = p.comp;
    for (const Chan& c : p.chans) h.channels().insert(c.name, Imf::Channel(c.type));
    if (!p.name.empty() || multipart) h.setName(p.name);
    if (p.tiled) {
        h.setTileDescription(Imf::TileDescription(4, 4, Imf::ONE_LEVEL));
        if (multipart) h.setType(Imf::TILEDIMAGE);
    } else if (multipart) {
        h.setType(Imf::SCANLINEIMAGE);
    }
    return h;
}

// Every channel as a plane of its own type (OpenEXR's writers do not convert).
struct Planes {
    std::vector<std::vector<char>> data;
    Imf::FrameBuffer fb;
    explicit Planes(const Part& p) {
        for (const Chan& c : p.chans) {
            const size_t bytes = c.type == Imf::HALF ? 2 : 4;
            data.emplace_back(size_t(p.w) * p.h * bytes);
            for (int y = 0; y < p.h; ++y)
                for (int x = 0; x < p.w; ++x) {
                    char* at = data.back().data() + (size_t(y) * p.w + x) * bytes;
                    const float v = c.f(x, y);
                    if (c.type == Imf::HALF) {
                        const half hv(v);
                        std::memcpy(at, &hv, 2);
                    } else if (c.type == Imf::UINT) {
                        const uint32_t u = std::isfinite(v) && v > 0 ? uint32_t(std::min(v, 4e9f)) : 0u;
                        std::memcpy(at, &u, 4);
                    } else {
                        std::memcpy(at, &v, 4);
                    }
                }
        }
        for (size_t i = 0; i < p.chans.size(); ++i) {
            const size_t bytes = p.chans[i].type == Imf::HALF ? 2 : 4;
            char* base = data[i].data() - (p.x0 + p.y0 * long(p.w)) * long(bytes);
            fb.insert(p.chans[i].name, Imf::Slice(p.chans[i].type, base, bytes, bytes * size_t(p.w)));
        }
    }
};

void writeExrParts(const std::string& path, const std::vector<Part>& parts) {
    if (parts.size() == 1) {
        const Part& p = parts[0];
        Planes planes(p);
        if (p.tiled) {
            Imf::TiledOutputFile f(path.c_str(), headerOf(p, false, p));
            f.setFrameBuffer(planes.fb);
            f.writeTiles(0, f.numXTiles() - 1, 0, f.numYTiles() - 1);
        } else {
            Imf::OutputFile f(path.c_str(), headerOf(p, false, p));
            f.setFrameBuffer(planes.fb);
            f.writePixels(p.h);
        }
        return;
    }
    std::vector<Imf::Header> headers;
    for (const Part& p : parts) headers.push_back(headerOf(p, true, parts[0]));
    Imf::MultiPartOutputFile file(path.c_str(), headers.data(), int(headers.size()));
    for (size_t i = 0; i < parts.size(); ++i) {
        Planes planes(parts[i]);
        if (parts[i].tiled) {
            Imf::TiledOutputPart out(file, int(i));
            out.setFrameBuffer(planes.fb);
            out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
        } else {
            Imf::OutputPart out(file, int(i));
            out.setFrameBuffer(planes.fb);
            out.writePixels(parts[i].h);
        }
    }
}

Image image(int w, int h, int channels, float base) {
    Image img(w, h, channels);
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) img(x, y, c) = base + 0.1f * float(c) + 0.02f * float(x + w * y);
    return img;
}

void exrSingle() {
    const std::string d = dir("exr_single");
    atrous::io::writeExr(d + "/atrous_rgb_zip.exr", image(8, 6, 3, 0.25f));
    const Imf::PixelType H = Imf::HALF, F = Imf::FLOAT;
    struct Seed {
        const char* name;
        Part part;
    };
    const std::vector<Seed> seeds = {
        {"rgb_half_none.exr", {"", 6, 4, 0, 0, Imf::NO_COMPRESSION, false, rgb("", H, ramp(0, 1), ramp(1, 0.5f), odd(0.5f))}},
        {"rgb_float_piz.exr", {"", 8, 6, 0, 0, Imf::PIZ_COMPRESSION, false, rgb("", F, ramp(0, 1), odd(2), constant(3))}},
        {"rgba_half_rle.exr", {"", 8, 6, 0, 0, Imf::RLE_COMPRESSION, false,
                               {{"R", H, ramp(0, 1)}, {"G", H, constant(0)}, {"B", H, constant(1)}, {"A", H, constant(1)}}}},
        {"y_zips.exr", {"", 8, 6, 0, 0, Imf::ZIPS_COMPRESSION, false, {{"Y", H, ramp(0.1f, 0.1f)}}}},
        {"z_only_none.exr", {"", 5, 3, 0, 0, Imf::NO_COMPRESSION, false, {{"Z", F, odd(1)}}}},
        {"uint_b44.exr", {"", 8, 8, 0, 0, Imf::B44_COMPRESSION, false, rgb("", Imf::UINT, constant(7), ramp(0, 1), constant(0))}},
        {"rgb_tiled_b44a.exr", {"", 9, 7, 0, 0, Imf::B44A_COMPRESSION, true, rgb("", H, ramp(0, 1), constant(2), odd(1))}},
        {"rgb_offset_pxr24.exr", {"", 7, 5, 3, -2, Imf::PXR24_COMPRESSION, false, rgb("", F, ramp(0, 1), ramp(1, 1), ramp(2, 1))}},
        {"rgb_dwaa.exr", {"", 8, 6, 0, 0, Imf::DWAA_COMPRESSION, false, rgb("", H, ramp(0, 1), ramp(1, 1), ramp(2, 1))}},
        {"mitsuba_aov_half.exr", {"", 6, 4, 0, 0, Imf::ZIP_COMPRESSION, false,
                                  {{"R", H, ramp(0, 1)}, {"G", H, ramp(0, 1)}, {"B", H, ramp(0, 1)}, {"albedo.R", H, constant(0.5f)},
                                   {"albedo.G", H, constant(0.5f)}, {"albedo.B", H, constant(0.5f)}, {"nn.X", H, constant(0)},
                                   {"nn.Y", H, constant(1)}, {"nn.Z", H, constant(0)}, {"dd.T", H, ramp(1, 1)}}}},
        {"no_rgb_two_channels.exr", {"", 4, 4, 0, 0, Imf::NO_COMPRESSION, false, {{"U", F, constant(1)}, {"W", F, constant(2)}}}},
    };
    for (const Seed& s : seeds) writeExrParts(d + "/" + s.name, {s.part});
    // Luminance/chroma (Y, RY, BY; RY and BY subsampled 2x2): RgbaOutputFile writes it.
    {
        const int w = 8, h = 6;
        std::vector<Imf::Rgba> px(size_t(w) * h);
        for (int i = 0; i < w * h; ++i) px[size_t(i)] = Imf::Rgba(0.1f * float(i % 7), 0.5f, 1.0f - 0.02f * float(i), 1.0f);
        Imf::RgbaOutputFile f((d + "/yc_piz.exr").c_str(), Imf::Header(w, h, 1.0f, Imath::V2f(0, 0), 1.0f, Imf::INCREASING_Y,
                                                                          Imf::PIZ_COMPRESSION),
                              Imf::WRITE_YC);
        f.setFrameBuffer(px.data(), 1, size_t(w));
        f.writePixels(h);
    }
}

std::vector<Part> blender5(const std::string& view, int w, int h, Imf::Compression comp) {
    const Imf::PixelType F = Imf::FLOAT, H = Imf::HALF;
    auto part = [&](const std::string& pass, std::vector<std::pair<std::string, Fill>> comps, Imf::PixelType t) {
        Part p{view + "." + pass, w, h, 0, 0, comp, false, {}};
        for (auto& [c, f] : comps) p.chans.push_back({view + "." + pass + "." + c, t, f});
        return p;
    };
    return {
        part("Combined", {{"R", odd(0.5f)}, {"G", ramp(0, 0.1f)}, {"B", constant(0.2f)}, {"A", constant(1)}}, F),
        part("Depth", {{"Z", odd(3)}}, F),
        part("Normal", {{"X", constant(0)}, {"Y", ramp(0.5f, 0.2f)}, {"Z", constant(0.1f)}}, H),
        part("Vector", {{"X", ramp(0, 0.5f)}, {"Y", constant(-1)}, {"Z", constant(0)}, {"W", constant(0)}}, F),
        part("Denoising Albedo", {{"R", constant(30)}, {"G", odd(0.5f)}, {"B", constant(-2)}}, H),
        part("Object Index", {{"X", ramp(0, 1)}}, F),
        part("Emission", {{"R", constant(0)}, {"G", constant(4)}, {"B", constant(0)}}, H),
    };
}

void exrLayered() {
    const std::string d = dir("exr_layered");
    writeExrParts(d + "/blender5_multipart_zip.exr", blender5("ViewLayer", 6, 4, Imf::ZIP_COMPRESSION));
    // Blender before 5: one part, the same channels.
    {
        Part one{"", 6, 4, 0, 0, Imf::PIZ_COMPRESSION, false, {}};
        for (const Part& p : blender5("ViewLayer", 6, 4, Imf::PIZ_COMPRESSION))
            for (const Chan& c : p.chans) one.chans.push_back(c);
        writeExrParts(d + "/blender4_single_piz.exr", {one});
    }
    // Two view layers (ambiguous without --layer), RLE, one part each.
    {
        std::vector<Part> parts = blender5("Front", 4, 3, Imf::RLE_COMPRESSION);
        parts.resize(3);
        for (Part& p : blender5("Back", 4, 3, Imf::NO_COMPRESSION)) {
            if (parts.size() < 6) parts.push_back(p);
        }
        writeExrParts(d + "/two_view_layers.exr", parts);
    }
    // Mitsuba's aov integrator: half floats, root R,G,B and named AOVs.
    fs::copy_file(gRoot + "/exr_single/mitsuba_aov_half.exr", d + "/mitsuba_aov_half.exr", fs::copy_options::overwrite_existing);
    // atrous's own layered writer (Blender 5's layout) and a copy with a pass added.
    {
        Image color = image(5, 4, 3, 0.3f), albedo = image(5, 4, 3, 0.6f), normal = image(5, 4, 3, -0.2f), depth = image(5, 4, 1, 2.0f);
        std::vector<atrous::io::ExrOutLayer> layers = {{"View.Combined", &color, {"R", "G", "B"}},
                                                       {"View.Denoising Albedo", &albedo, {"R", "G", "B"}},
                                                       {"View.Denoising Normal", &normal, {"X", "Y", "Z"}},
                                                       {"View.Denoising Depth", &depth, {"Z"}}};
        atrous::io::writeLayeredExr(d + "/atrous_multipart.exr", layers, true);
        atrous::io::writeLayeredExr(d + "/atrous_single_half.exr", layers, false, true);
        const atrous::io::ExrInfo info = atrous::io::inspectExr(d + "/atrous_multipart.exr");
        atrous::io::writeExrWithLayers(d + "/atrous_add_pass.exr", info, {{"Denoised", &color}});
    }
    // Odd structures: a tiled part, parts of two sizes, an offset data window, an alpha-only layer.
    {
        std::vector<Part> parts = blender5("VL", 4, 4, Imf::ZIP_COMPRESSION);
        parts.resize(3);
        parts[1].tiled = true;
        parts[2].w = 3;
        writeExrParts(d + "/tiled_and_other_size.exr", parts);
        std::vector<Part> off = blender5("VL", 4, 3, Imf::ZIPS_COMPRESSION);
        off.resize(2);
        off[1].x0 = 2, off[1].y0 = 1;
        off.push_back({"VL.Alpha", 4, 3, 0, 0, Imf::NO_COMPRESSION, false, {{"VL.Alpha.A", Imf::HALF, constant(1)}}});
        writeExrParts(d + "/offset_window_alpha_only.exr", off);
    }
}

// ----------------------------------------------------------------------------------- PFM, PNG

std::string pfm(const char* magic, int w, int h, const char* scale, const std::vector<float>& v, bool bigEndian) {
    std::string s = std::string(magic) + "\n" + std::to_string(w) + " " + std::to_string(h) + "\n" + scale + "\n";
    for (float f : v) {
        uint32_t u;
        std::memcpy(&u, &f, 4);
        if (bigEndian) u = __builtin_bswap32(u);
        s.append(reinterpret_cast<const char*>(&u), 4);
    }
    return s;
}

void pfmSeeds() {
    const std::string d = dir("pfm");
    atrous::io::writePfm(d + "/atrous_rgb.pfm", image(6, 4, 3, 0.5f));
    std::vector<float> grey;
    for (int i = 0; i < 12; ++i) grey.push_back(i == 5 ? kNan : i == 6 ? kInf : 0.1f * float(i));
    writeBytes(d + "/grey_little.pfm", pfm("Pf", 4, 3, "-1.0", grey, false));
    std::vector<float> col(2 * 2 * 3, 0.75f);
    writeBytes(d + "/rgb_big_endian.pfm", pfm("PF", 2, 2, "1.0", col, true));
    writeBytes(d + "/rgb_scale_crlf.pfm", "PF\r\n2 1\r\n-2.5\n" + pfm("", 0, 0, "", {1, 2, 3, 4, 5, 6}, false).substr(4));
}

void pngSeeds() {
    const std::string d = dir("png");
    atrous::io::writePng(d + "/atrous_rgb.png", image(8, 6, 3, 0.2f));
    std::vector<unsigned char> px(8 * 8 * 4);
    for (size_t i = 0; i < px.size(); ++i) px[i] = (unsigned char)(i * 37 % 251);
    stbi_write_png((d + "/grey.png").c_str(), 6, 5, 1, px.data(), 6);
    stbi_write_png((d + "/grey_alpha.png").c_str(), 6, 5, 2, px.data(), 12);
    stbi_write_png((d + "/rgba.png").c_str(), 6, 5, 4, px.data(), 24);
    stbi_write_bmp((d + "/rgb.bmp.png").c_str(), 6, 5, 3, px.data());
    stbi_write_tga((d + "/rgb.tga.png").c_str(), 6, 5, 3, px.data());
    stbi_write_jpg((d + "/rgb.jpg.png").c_str(), 8, 8, 3, px.data(), 80);
    std::vector<float> hdr(10 * 3 * 3);
    for (size_t i = 0; i < hdr.size(); ++i) hdr[i] = 0.05f * float(i);
    stbi_write_hdr((d + "/rle.hdr").c_str(), 10, 3, 3, hdr.data());
    stbi_write_hdr((d + "/flat.hdr").c_str(), 4, 2, 3, hdr.data());  // narrower than 8: not run-length encoded
}

// --------------------------------------------------------------------------------- text seeds

void text(const std::string& target, const std::string& name, const std::string& body) { writeBytes(dir(target) + "/" + name, body); }

void sceneSeeds() {
    text("scene_json", "example.json", readBytes(std::string(ATROUS_SOURCE_DIR) + "/scenes/example.json"));
    text("scene_json", "mesh_texture_env.json", R"({
  "camera": {"position": [0, 1, 4], "lookAt": [0, 0.5, 0], "fov": 45},
  "materials": {"tex": {"type": "diffuse", "texture": "tex.png"}, "lamp": {"type": "light", "emission": [5, 5, 5]}},
  "objects": [
    {"type": "mesh", "name": "quad", "file": "mesh.obj", "transform": {"scale": [1, 2, -1], "rotateY": 45, "translate": [0, 0, 1]}},
    {"type": "mesh", "file": "mesh.obj", "material": "tex", "motion": {"translate": [0.5, 0, 0], "rotateY": 20}},
    {"type": "sphere", "center": [0, 3, 0], "radius": 0.5, "material": "lamp", "motion": {"pivot": [0, 0, 0], "rotateY": 5}}
  ],
  "lights": [{"type": "environment", "file": "env.exr", "scale": 0.5}]
})");
    text("scene_json", "keyframes_point.json", R"({
  "camera": {"position": [0, 0, 5], "lookAt": [0, 0, 0], "up": [0, 1, 0],
             "keyframes": [{"t": 0, "position": [0, 0, 5], "target": [0, 0, 0]},
                           {"t": 0.5, "position": [1, 0, 5], "lookAt": [0, 0, 0], "fov": 30},
                           {"t": 1, "position": [2, 1, 5], "target": [0, 0, 0], "up": [0, 1, 0.1]}]},
  "materials": {"m": {"type": "mirror", "albedo": 0.9}, "c": {"type": "plastic", "checker": {"color1": 1, "color2": [0, 0.5, 0], "scale": 3}}},
  "objects": [{"type": "quad", "corner": [-1, -1, 0], "edge1": [2, 0, 0], "edge2": [0, 2, 0], "material": "c"},
              {"type": "sphere", "center": 0.5, "radius": 0.25, "material": "m"}],
  "lights": [{"type": "point", "position": [0, 2, 2], "intensity": 10}, {"type": "environment", "color": [0.1, 0.2, 0.3]}]
})");
    text("scene_json", "sky.json", R"({"camera": {"position": [0, 1, 3], "lookAt": [0, 1, 0]},
  "materials": {"g": {"type": "conductor", "albedo": [1, 0.8, 0.4], "roughness": 0.3}, "d": {"type": "dielectric", "ior": 1.33}},
  "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 0.5, "material": "g"},
              {"type": "sphere", "center": [1, 1, 0], "radius": 0.3, "material": "d"}],
  "lights": [{"type": "sky", "sunDirection": [0.3, 1, 0.2], "sunRadius": 2, "sunRadiance": 1000, "scale": 0.1}]})");
    // An image after the JSON, named aux.<ext> (scene_json.cpp).
    std::string aux = pfm("PF", 4, 2, "-1.0", std::vector<float>(24, 2.0f), false);
    text("scene_json", "aux_env_texture.json", R"({"camera": {"position": [0, 0, 3], "lookAt": [0, 0, 0]},
  "materials": {"t": {"texture": "aux.pfm", "roughness": 0.5}},
  "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "t"}],
  "lights": [{"type": "environment", "file": "aux.pfm", "scale": 2}]})" "\n#--\n" + aux);
    text("scene_json", "bad_values.json", R"({"camera": {"position": [0, 0, 1e39], "lookAt": [0, 0, 0], "_note": "range errors"},
  "objects": [{"type": "quad", "corner": 1e9, "edge1": [1e9, 0, 0], "edge2": [0, 1, 0], "material": "none"}]})");
}

void objSeeds() {
    const std::string sep = "\n#--\n";
    const std::string tex = readBytes(gRoot + "/png/atrous_rgb.png");
    text("obj_mtl", "tetrahedron.obj",
         readBytes(std::string(ATROUS_SOURCE_DIR) + "/scenes/tetrahedron.obj") + sep + readBytes(std::string(ATROUS_SOURCE_DIR) + "/scenes/tetrahedron.mtl"));
    text("obj_mtl", "textured_quad.obj",
         "mtllib m.mtl\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
         "usemtl tex\nf 1/1/1 2/2/1 3/3/1 4/4/1\ng back\nusemtl glow\nf -4//1 -2//1 -3//1\n" +
             sep + "newmtl tex\nKd 1 1 1\nmap_Kd t.png\nnewmtl glow\nKe 3 2 1\nKd 0 0 0\n" + sep + tex);
    text("obj_mtl", "materials.obj",
         "mtllib m.mtl\nv -1 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 1 0\nusemtl mirror\nf 1 2 3\nusemtl glass\nf 1 3 4\n"
         "usemtl metal\nf 2 3 4\nusemtl missing\nf 1 2 4\ns 1\nl 1 2\np 3\n" +
             sep +
             "newmtl mirror\nillum 3\nKs 0.9 0.9 0.9\nnewmtl glass\nillum 7\nNi 1.45\nd 0.5\n"
             "newmtl metal\nPm 1\nPr 0.3\nKd 0.9 0.6 0.2\nmap_Kd -s 1 1 1 t.pfm\n" +
             sep + pfm("PF", 2, 2, "-1.0", std::vector<float>(12, 0.5f), false));
    // The findings fixed in scene_obj.cpp (tests/fuzz_regression_test.cpp): exponents and skin weight joint ids beyond int.
    text("obj_mtl", "finding_exponent_overflow.obj",
         "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nt crease 0/1/0 1e-2147483648\nv 1e-2147483649 0 0\nusemtl a\nf 1 2 3\n" + sep +
             "newmtl a\nKd 1e-21474836480 1 1\nmap_Kd -s 1e-2147483648 1 1 t.png\n");
    text("obj_mtl", "finding_vw_joint_overflow.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nvw 1 0 0.5 3e9 0.5\nvw 2 " + std::string(40, '7') + " 1\nvw 3 " + std::string(400, '7') + "e-2000 1\nf 1 2 3\n");
    text("obj_mtl", "polygon_no_mtl.obj", "# a pentagon, triangulated\nv 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 3 0\nv -1 1 0\nvt 0.5 0.5\nf 1/1 2/1 3/1 4/1 5/1\n");
}

void weightSeeds() {
    const std::string d = dir("weights");
    const std::string good(reinterpret_cast<const char*>(atrous::filters::kLearnedDefaultWeights),
                           atrous::filters::kLearnedDefaultWeightsSize);
    writeBytes(d + "/builtin_v3.bin", good);
    auto fnv = [](std::string& s) {
        uint32_t h = 0x811C9DC5u;
        for (size_t i = 0; i + 4 < s.size(); ++i) h = (h ^ uint8_t(s[i])) * 0x01000193u;
        for (int k = 0; k < 4; ++k) s[s.size() - 4 + size_t(k)] = char(uint8_t(h >> (8 * k)));
    };
    std::string nan = good;
    const float n = kNan;
    std::memcpy(&nan[28 + 4 * 100], &n, 4);
    fnv(nan);
    writeBytes(d + "/nan_weight.bin", nan);
    std::string v2 = good.substr(0, 32);
    v2[4] = 2;
    writeBytes(d + "/version2_header.bin", v2);
    writeBytes(d + "/truncated_header.bin", good.substr(0, 24));
}

void passSeeds() {
    text("pass_resolver", "blender5.txt",
         "PViewLayer.Combined\nCViewLayer.Combined.R\nCViewLayer.Combined.G\nCViewLayer.Combined.B\nCViewLayer.Combined.A\n"
         "PViewLayer.Denoising Albedo\nHViewLayer.Denoising Albedo.R\nHViewLayer.Denoising Albedo.G\nHViewLayer.Denoising Albedo.B\n"
         "PViewLayer.Normal\nCViewLayer.Normal.X\nCViewLayer.Normal.Y\nCViewLayer.Normal.Z\n"
         "PViewLayer.Depth\nCViewLayer.Depth.Z\nPViewLayer.Vector\nCX\nCY\nCZ\nCW\nPViewLayer.IndexOB\nCX\n");
    text("pass_resolver", "mitsuba.txt",
         "P\nHR\nHG\nHB\nHalbedo.R\nHalbedo.G\nHalbedo.B\nHnn.X\nHnn.Y\nHnn.Z\nHdd.T\nHshape_index.I\nRalbedo=albedo\nRdepth=dd.T\nBnormal\n");
    text("pass_resolver", "two_view_layers.txt",
         "S640 480\nCFront.Combined.R\nCFront.Combined.G\nCFront.Combined.B\nCBack.Combined.R\nCBack.Combined.G\nCBack.Combined.B\n"
         "CFront.Noisy Image.R\nCFront.Noisy Image.G\nCFront.Noisy Image.B\nCBack.Alpha.A\nLFront\nRids=Back.Combined\n");
    text("pass_resolver", "requests.txt",
         "PA\nS8 8\nTtiledimage\nCR\nCG\nCB\nPB\nS4 4\nTdeepscanline\nUZ\nCA.x\nRcolor=A\nRmotion=B.Z\nRnormal=x\nRbogus=1\nR=\n"
         "Lnothing\nBids\nBalbedo\nBfoo\n");
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s tests/fuzz/libfuzzer/corpus\n", argv[0]);
        return 2;
    }
    gRoot = fs::absolute(argv[1]).lexically_normal().string();
    try {
        exrSingle();
        exrLayered();
        pfmSeeds();
        pngSeeds();
        sceneSeeds();
        objSeeds();
        weightSeeds();
        passSeeds();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "make_corpus: %s\n", e.what());
        return 1;
    }
    for (const auto& t : fs::directory_iterator(gRoot)) {
        size_t n = 0, bytes = 0;
        for (const auto& f : fs::directory_iterator(t.path())) ++n, bytes += fs::file_size(f.path());
        std::printf("%-14s %2zu files %7zu bytes\n", t.path().filename().c_str(), n, bytes);
    }
    return 0;
}

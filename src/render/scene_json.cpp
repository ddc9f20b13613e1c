// JSON scene files (docs/scenes.md): Scene::load and Scene::parse. Every key and value is checked
// (unknown keys, ranges of scene_limits.h), and every error names the file and the key at fault.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <sstream>

#include "atrous/error.h"
#include "atrous/render.h"
#include "atrous/io/image_io.h"
#include "render/scene_builder.h"
#include "render/scene_data.h"
#include "render/scene_limits.h"
#include "render/scene_obj.h"
#include "render/scene_sky.h"

namespace atrous {
namespace pt {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct JsonContext {
    std::string source;  // file name for messages
    fs::path baseDir;
};

[[noreturn]] void fail(const JsonContext& c, const std::string& what) { throw InputError(c.source + ": " + what); }

// Every key of the object `j` must be one of `allowed` (a typo such as "albdo" would otherwise be
// ignored and the default rendered without a word). Keys starting with '_' are comments.
void checkKeys(const JsonContext& c, const json& j, const std::string& where, std::initializer_list<const char*> allowed) {
    if (!j.is_object()) return;
    for (auto it = j.begin(); it != j.end(); ++it) {
        const std::string& k = it.key();
        if (!k.empty() && k[0] == '_') continue;
        bool ok = false;
        for (const char* a : allowed) ok = ok || k == a;
        if (!ok) {
            std::string list;
            for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
            fail(c, (where.empty() ? std::string() : where + ": ") + "unknown key \"" + k + "\" (expected " + list + ")");
        }
    }
}

// A number of the scene file under `rule` (scene_limits.h), read as a double so that a value beyond
// float's range (1e39) is rejected instead of turning into Inf.
float checkedNumber(const JsonContext& c, const json& v, const std::string& where, const char* key, const ValueRule& rule) {
    const double d = v.get<double>();
    if (!allowed(rule, d)) fail(c, where + ": \"" + key + "\" " + rule.text + " (got " + formatValue(d) + ")");
    return float(d);
}

// A triple: an array of 3 numbers, or one number for all three; each component under `rule`.
Vec3 getVec3(const JsonContext& c, const json& j, const char* key, const std::string& where, Vec3 def,
             const ValueRule& rule, bool required = false) {
    if (!j.contains(key)) {
        if (required) fail(c, where + ": missing \"" + key + "\"");
        return def;
    }
    const json& v = j.at(key);
    if (v.is_number()) return Vec3(checkedNumber(c, v, where, key, rule));
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
        fail(c, where + ": \"" + key + "\" must be a number or an array of 3 numbers");
    return Vec3(checkedNumber(c, v[0], where, key, rule), checkedNumber(c, v[1], where, key, rule),
                checkedNumber(c, v[2], where, key, rule));
}

float getFloat(const JsonContext& c, const json& j, const char* key, const std::string& where, float def,
               const ValueRule& rule, bool required = false) {
    if (!j.contains(key)) {
        if (required) fail(c, where + ": missing \"" + key + "\"");
        return def;
    }
    if (!j.at(key).is_number()) fail(c, where + ": \"" + key + "\" must be a number");
    return checkedNumber(c, j.at(key), where, key, rule);
}

// A point computed from checked values (a quad's far corner, a transformed vertex) is checked again.
void checkCoordinate(const JsonContext& c, Vec3 p, const std::string& what) {
    if (!allowed(kCoordinateRule, p.x) || !allowed(kCoordinateRule, p.y) || !allowed(kCoordinateRule, p.z))
        fail(c, what + " " + kCoordinateRule.text + " (got " + formatValue(p.x) + ", " + formatValue(p.y) + ", " +
                    formatValue(p.z) + ")");
}

// The look-at test, written so that NaN fails it (a NaN compared with <= is false).
bool usableLookAt(Vec3 eye, Vec3 target, Vec3 up) {
    const Vec3 f = target - eye;
    const float lf = length(f), lu = length(up);
    return lf > 0.0f && lu > 0.0f && length(cross(f, up)) > 1e-6f * lf * lu;
}

std::string getString(const JsonContext& c, const json& j, const char* key, const std::string& where, bool required = true) {
    if (!j.contains(key)) {
        if (required) fail(c, where + ": missing \"" + key + "\"");
        return "";
    }
    if (!j.at(key).is_string()) fail(c, where + ": \"" + key + "\" must be a string");
    return j.at(key).get<std::string>();
}

std::string resolvePath(const JsonContext& c, const std::string& p) {
    fs::path path(p);
    return (path.is_absolute() ? path : c.baseDir / path).lexically_normal().string();
}

Material parseMaterial(const JsonContext& c, SceneBuilder& b, const json& j, const std::string& where) {
    if (!j.is_object()) fail(c, where + ": must be an object");
    checkKeys(c, j, where, {"type", "albedo", "emission", "roughness", "ior", "texture", "checker"});
    std::string type = j.contains("type") ? getString(c, j, "type", where) : "diffuse";
    Material m;
    if (type == "diffuse" || type == "lambertian") m.type = MaterialType::Diffuse;
    else if (type == "mirror") m.type = MaterialType::Mirror;
    else if (type == "dielectric" || type == "glass") m.type = MaterialType::Dielectric;
    else if (type == "conductor" || type == "metal") m.type = MaterialType::Conductor;
    else if (type == "plastic") m.type = MaterialType::Plastic;
    else if (type == "emissive" || type == "light") m.type = MaterialType::Diffuse;
    else fail(c, where + ": unknown material type \"" + type + "\" (diffuse, mirror, dielectric, conductor, plastic, emissive)");
    Vec3 defAlbedo = (m.type == MaterialType::Diffuse || m.type == MaterialType::Plastic) ? Vec3(0.8f) : Vec3(1.0f);
    if (type == "emissive" || type == "light") defAlbedo = Vec3(0.0f);
    m.albedo = getVec3(c, j, "albedo", where, defAlbedo, kReflectanceRule);
    m.emission = getVec3(c, j, "emission", where, Vec3(0.0f), kRadianceRule);
    if ((type == "emissive" || type == "light") && !j.contains("emission")) fail(c, where + ": missing \"emission\"");
    m.roughness = getFloat(c, j, "roughness", where, 0.2f, kRoughnessRule);
    m.ior = getFloat(c, j, "ior", where, 1.5f, kIorRule);
    if (m.roughness < 0.0f || m.roughness > 1.0f) fail(c, where + ": \"roughness\" must be in [0, 1]");
    if (m.ior < 1.0f || m.ior > 4.0f) fail(c, where + ": \"ior\" must be in [1, 4]");
    if (m.emission.x < 0 || m.emission.y < 0 || m.emission.z < 0) fail(c, where + ": \"emission\" must be >= 0");
    // A reflectance above 1 creates energy (and the albedo buffer, clamped, would not match).
    auto checkReflectance = [&](Vec3 v, const std::string& what) {
        if (!(v.x >= 0 && v.y >= 0 && v.z >= 0 && v.x <= 1 && v.y <= 1 && v.z <= 1))
            fail(c, what + " must be in [0, 1]");
    };
    checkReflectance(m.albedo, where + ": \"albedo\"");
    if (j.contains("texture")) {
        std::string path = resolvePath(c, getString(c, j, "texture", where));
        m.texture = b.addTexture(atrous::readImage(path), /*reflectance=*/true);  // InputError names the texture file
    }
    if (j.contains("checker")) {
        const json& ch = j.at("checker");
        if (!ch.is_object()) fail(c, where + ": \"checker\" must be an object");
        checkKeys(c, ch, where + ".checker", {"color1", "color2", "scale"});
        m.checker = 1;
        m.albedo = getVec3(c, ch, "color1", where + ".checker", Vec3(0.8f), kReflectanceRule);
        m.albedo2 = getVec3(c, ch, "color2", where + ".checker", Vec3(0.2f), kReflectanceRule);
        checkReflectance(m.albedo, where + ".checker: \"color1\"");
        checkReflectance(m.albedo2, where + ".checker: \"color2\"");
        m.checkerScale = getFloat(c, ch, "scale", where + ".checker", 8.0f, kCheckerScaleRule);
        if (!(m.checkerScale > 0.0f)) fail(c, where + ".checker: \"scale\" must be in (0, 1e6] (got 0)");
    }
    return m;
}


Transform parseTransform(const JsonContext& c, const json& j, const std::string& where) {
    Transform t;
    if (!j.contains("transform")) return t;
    const json& tj = j.at("transform");
    if (!tj.is_object()) fail(c, where + ": \"transform\" must be an object");
    checkKeys(c, tj, where + ".transform", {"scale", "rotateY", "translate"});
    t.scale = getVec3(c, tj, "scale", where + ".transform", Vec3(1.0f), kTransformScaleRule);
    if (t.scale.x == 0.0f || t.scale.y == 0.0f || t.scale.z == 0.0f) fail(c, where + ".transform: \"scale\" must be non-zero");
    t.rotY = getFloat(c, tj, "rotateY", where + ".transform", 0.0f, kAngleRule) * kPi / 180.0f;
    t.translate = getVec3(c, tj, "translate", where + ".transform", Vec3(0.0f), kCoordinateRule);
    return t;
}

// An environment map's texels are radiance: NaN/Inf and negatives become 0 (addTexture), and a
// finite texel beyond kMaxRadiance (after the light's scale) is an error naming the file.
void checkEnvMap(const JsonContext& c, const Image& img, const std::string& file, float scale) {
    const float* p = img.data();
    for (size_t i = 0; i < size_t(img.width()) * img.height() * 3; ++i)
        if (std::isfinite(p[i]) && double(p[i]) * scale > kMaxRadiance) {
            const size_t px = i % (size_t(img.width()) * img.height());
            fail(c, file + ": environment texel (" + std::to_string(px % img.width()) + ", " +
                        std::to_string(px / img.width()) + ") times \"scale\" " + kRadianceRule.text + " (got " +
                        formatValue(double(p[i]) * scale) + ")");
        }
}

// Centre of the bounding box of mesh `mesh` (triangles and spheres).
Vec3 meshBoundsCentre(const SceneData& d, int mesh) {
    Vec3 lo(1e30f), hi(-1e30f);
    for (size_t t = 0; t < d.triMesh.size(); ++t)
        if (d.triMesh[t] == mesh)
            for (int k = 0; k < 3; ++k) {
                lo = minv(lo, d.positions[d.indices[3 * t + k]]);
                hi = maxv(hi, d.positions[d.indices[3 * t + k]]);
            }
    for (const Sphere& s : d.spheres)
        if (s.mesh == mesh) {
            lo = minv(lo, s.center - Vec3(s.radius));
            hi = maxv(hi, s.center + Vec3(s.radius));
        }
    return lo.x <= hi.x ? (lo + hi) * 0.5f : Vec3(0.0f);
}

// "camera.keyframes": [{"t", "position", "target" (or "lookAt"), optional "up", "fov"}, ...] with
// t strictly increasing; up and fov default to the camera's.
std::vector<CameraKey> parseKeyframes(const JsonContext& c, const json& j, Vec3 up, float fov) {
    if (!j.is_array() || j.empty()) fail(c, "camera.keyframes: must be a non-empty array of keyframe objects");
    std::vector<CameraKey> keys;
    for (size_t i = 0; i < j.size(); ++i) {
        std::string where = "camera.keyframes[" + std::to_string(i) + "]";
        const json& k = j[i];
        if (!k.is_object()) fail(c, where + ": must be an object");
        checkKeys(c, k, where, {"t", "position", "target", "lookAt", "up", "fov"});
        CameraKey key;
        key.t = getFloat(c, k, "t", where, 0.0f, kCoordinateRule, true);
        key.position = getVec3(c, k, "position", where, Vec3(0.0f), kCoordinateRule, true);
        const char* targetKey = k.contains("target") ? "target" : "lookAt";
        key.target = getVec3(c, k, targetKey, where, Vec3(0.0f), kCoordinateRule, true);
        key.up = getVec3(c, k, "up", where, up, kCoordinateRule);
        key.fovDeg = getFloat(c, k, "fov", where, fov, kAnyFiniteRule);
        if (!(key.fovDeg > 0.5f && key.fovDeg < 179.0f)) fail(c, where + ": \"fov\" must be in (0.5, 179) degrees");
        if (!usableLookAt(key.position, key.target, key.up))
            fail(c, where + ": \"target\" must differ from \"position\" and not be along \"up\"");
        if (!keys.empty() && !(key.t > keys.back().t))
            fail(c, where + ": \"t\" must be greater than the previous keyframe's (" + std::to_string(keys.back().t) + ")");
        keys.push_back(key);
    }
    return keys;
}

std::shared_ptr<SceneData> parseJsonScene(const std::string& text, const JsonContext& c) {
    json root;
    try {
        root = json::parse(text);
    } catch (const json::exception& e) {
        fail(c, std::string("malformed JSON (") + e.what() + ")");
    }
    if (!root.is_object()) fail(c, "the scene must be a JSON object");
    SceneBuilder b(fs::path(c.source).stem().string());
    try {
        // Camera.
        checkKeys(c, root, "", {"camera", "materials", "objects", "lights"});
        if (!root.contains("camera") || !root["camera"].is_object()) fail(c, "missing \"camera\" object");
        const json& cam = root["camera"];
        checkKeys(c, cam, "camera", {"position", "lookAt", "up", "fov", "keyframes"});
        Vec3 eye = getVec3(c, cam, "position", "camera", Vec3(0.0f), kCoordinateRule, true);
        Vec3 at = getVec3(c, cam, "lookAt", "camera", Vec3(0.0f), kCoordinateRule, true);
        Vec3 up = getVec3(c, cam, "up", "camera", Vec3(0, 1, 0), kCoordinateRule);
        float fov = getFloat(c, cam, "fov", "camera", 40.0f, kAnyFiniteRule);
        if (!(fov > 0.5f && fov < 179.0f)) fail(c, "camera: \"fov\" must be in (0.5, 179) degrees");
        if (!usableLookAt(eye, at, up))
            fail(c, "camera: \"lookAt\" must differ from \"position\" and not be along \"up\"");
        b.setCamera(eye, at, up, fov, at);
        if (cam.contains("keyframes")) b.d.cameraKeys = parseKeyframes(c, cam.at("keyframes"), up, fov);

        // Materials.
        std::map<std::string, int> materials;
        if (root.contains("materials")) {
            if (!root["materials"].is_object()) fail(c, "\"materials\" must be an object of name: material");
            for (auto it = root["materials"].begin(); it != root["materials"].end(); ++it)
                materials[it.key()] = b.addMaterial(it.key(), parseMaterial(c, b, it.value(), "materials." + it.key()));
        }
        auto materialRef = [&](const json& o, const std::string& where, bool required) -> int {
            if (!o.contains("material")) {
                if (required) fail(c, where + ": missing \"material\"");
                return -1;
            }
            std::string name = getString(c, o, "material", where);
            auto it = materials.find(name);
            if (it == materials.end()) fail(c, where + ": unknown material \"" + name + "\"");
            return it->second;
        };

        // Objects.
        if (!root.contains("objects") || !root["objects"].is_array()) fail(c, "missing \"objects\" array");
        int index = 0;
        for (const json& o : root["objects"]) {
            std::string where = "objects[" + std::to_string(index++) + "]";
            if (!o.is_object()) fail(c, where + ": must be an object");
            std::string type = getString(c, o, "type", where);
            std::string name = o.contains("name") ? getString(c, o, "name", where) : type + std::to_string(index - 1);
            const int meshCount = int(b.d.meshNames.size());
            if (type == "sphere") {
                checkKeys(c, o, where, {"type", "name", "material", "motion", "center", "radius"});
                Vec3 center = getVec3(c, o, "center", where, Vec3(0.0f), kCoordinateRule, true);
                float radius = getFloat(c, o, "radius", where, 1.0f, kCoordinateRule, true);
                if (!(radius > 0.0f)) fail(c, where + ": \"radius\" must be > 0");
                b.addSphere(center, radius, materialRef(o, where, true), b.addMesh(name));
            } else if (type == "quad") {
                checkKeys(c, o, where, {"type", "name", "material", "motion", "corner", "edge1", "edge2"});
                Vec3 p = getVec3(c, o, "corner", where, Vec3(0.0f), kCoordinateRule, true);
                Vec3 e1 = getVec3(c, o, "edge1", where, Vec3(0.0f), kCoordinateRule, true);
                Vec3 e2 = getVec3(c, o, "edge2", where, Vec3(0.0f), kCoordinateRule, true);
                checkCoordinate(c, p + e1 + e2, where + ": the far corner (corner + edge1 + edge2)");
                checkCoordinate(c, p + e1, where + ": corner + edge1");
                checkCoordinate(c, p + e2, where + ": corner + edge2");
                if (!(length(cross(e1, e2)) > 0.0f)) fail(c, where + ": \"edge1\" and \"edge2\" span no area");
                // Geometric normal = edge1 x edge2 (the side a one-sided emitter lights).
                b.addQuad(p, p + e1, p + e1 + e2, p + e2, materialRef(o, where, true), b.addMesh(name), cross(e1, e2));
            } else if (type == "mesh") {
                checkKeys(c, o, where, {"type", "name", "material", "motion", "file", "transform"});
                std::string file = resolvePath(c, getString(c, o, "file", where));
                loadObj(c.source, b, file, materialRef(o, where, false), b.addMesh(name), parseTransform(c, o, where));
            } else {
                fail(c, where + ": unknown object type \"" + type + "\" (sphere, quad, mesh)");
            }
            if (o.contains("motion")) {
                const json& mj = o.at("motion");
                if (!mj.is_object()) fail(c, where + ": \"motion\" must be an object");
                for (auto it = mj.begin(); it != mj.end(); ++it)
                    if (it.key() != "translate" && it.key() != "rotateY" && it.key() != "pivot")
                        fail(c, where + ".motion: unknown key \"" + it.key() + "\" (translate, rotateY, pivot)");
                MeshMotion m;
                m.translate = getVec3(c, mj, "translate", where + ".motion", Vec3(0.0f), kCoordinateRule);
                m.rotateYDeg = getFloat(c, mj, "rotateY", where + ".motion", 0.0f, kAngleRule);
                // Default pivot: the centre of the object's bounding box.
                m.pivot = mj.contains("pivot") ? getVec3(c, mj, "pivot", where + ".motion", Vec3(0.0f), kCoordinateRule)
                                                : meshBoundsCentre(b.d, meshCount);
                b.setMotion(meshCount, m);
            }
        }

        // Lights beyond emissive surfaces.
        if (root.contains("lights")) {
            if (!root["lights"].is_array()) fail(c, "\"lights\" must be an array");
            int li = 0;
            for (const json& l : root["lights"]) {
                std::string where = "lights[" + std::to_string(li++) + "]";
                if (!l.is_object()) fail(c, where + ": must be an object");
                std::string type = getString(c, l, "type", where);
                if (type == "point") {
                    checkKeys(c, l, where, {"type", "intensity", "position"});
                    Vec3 intensity = getVec3(c, l, "intensity", where, Vec3(0.0f), kRadianceRule, true);
                    if (intensity.x < 0 || intensity.y < 0 || intensity.z < 0) fail(c, where + ": \"intensity\" must be >= 0");
                    b.addPointLight(getVec3(c, l, "position", where, Vec3(0.0f), kCoordinateRule, true), intensity);
                } else if (type == "environment") {
                    checkKeys(c, l, where, {"type", "scale", "file", "color"});
                    float scale = getFloat(c, l, "scale", where, 1.0f, kScaleRule);
                    if (l.contains("file")) {
                        const std::string file = resolvePath(c, getString(c, l, "file", where));
                        Image map = atrous::readImage(file);
                        checkEnvMap(c, map, file, scale);
                        b.setEnvMap(map, scale);
                    } else {
                        Vec3 col = getVec3(c, l, "color", where, Vec3(0.0f), kRadianceRule, true);
                        if (!allowed(kRadianceRule, maxComponent(col) * scale))
                            fail(c, where + ": \"color\" times \"scale\" " + kRadianceRule.text + " (got " +
                                        formatValue(double(maxComponent(col)) * scale) + ")");
                        if (col.x < 0 || col.y < 0 || col.z < 0) fail(c, where + ": \"color\" must be >= 0");
                        b.setEnvConstant(col * scale);
                    }
                } else if (type == "sky") {
                    checkKeys(c, l, where, {"type", "sunDirection", "sunRadius", "sunRadiance", "scale"});
                    Vec3 sunIn = getVec3(c, l, "sunDirection", where, Vec3(-0.55f, 0.62f, 0.55f), kCoordinateRule);
                    Vec3 sun = normalize(sunIn);
                    if (!(length(sunIn) > 0.0f) || !isFinite(sun)) fail(c, where + ": \"sunDirection\" must be non-zero");
                    float radiusDeg = getFloat(c, l, "sunRadius", where, 0.5f, kAnyFiniteRule);
                    if (!(radiusDeg > 0.0f && radiusDeg < 45.0f)) fail(c, where + ": \"sunRadius\" must be in (0, 45) degrees");
                    Vec3 sunL = getVec3(c, l, "sunRadiance", where, Vec3(1.0f, 0.93f, 0.82f) * 20000.0f, kRadianceRule);
                    float scale = getFloat(c, l, "scale", where, 1.0f, kScaleRule);
                    if (!allowed(kRadianceRule, maxComponent(sunL) * scale))
                        fail(c, where + ": \"sunRadiance\" times \"scale\" " + kRadianceRule.text + " (got " +
                                    formatValue(double(maxComponent(sunL)) * scale) + ")");
                    b.setEnvMap(makeSkyMap(1024, 512, sun, radiusDeg * kPi / 180.0f, sunL), scale);
                } else {
                    fail(c, where + ": unknown light type \"" + type + "\" (point, environment, sky)");
                }
            }
        }
    } catch (const json::exception& e) {
        fail(c, std::string("bad value (") + e.what() + ")");
    }
    return b.finalize();
}

}  // namespace
}  // namespace pt

Scene Scene::load(const std::string& path) {
    if (path.find('\0') != std::string::npos)
        throw InputError(path.substr(0, path.find('\0')) + "...: the scene path contains a NUL byte");
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    if (!in || std::filesystem::is_directory(path, ec)) throw InputError(path + ": cannot open scene file");
    // A FIFO or a device (/dev/zero) would be read for ever; a scene file is text of a few KB.
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": not a regular file (a scene file)");
    constexpr uintmax_t kMaxSceneBytes = 16u << 20;
    if (std::filesystem::file_size(path, ec) > kMaxSceneBytes)
        throw InputError(path + ": scene file larger than 16 MiB (meshes belong in OBJ files it references)");
    std::stringstream ss;
    ss << in.rdbuf();
    return parse(ss.str(), std::filesystem::path(path).parent_path().string(), path);
}

Scene Scene::parse(const std::string& jsonText, const std::string& baseDir, const std::string& sourceName) {
    Scene s;
    s.mData = pt::parseJsonScene(jsonText, pt::JsonContext{sourceName, baseDir});
    return s;
}

}  // namespace atrous

// Scenes: the built-in ones, JSON scene files (docs/scenes.md) with OBJ/MTL meshes, and the
// finalisation every scene goes through (light list and its power distribution, the environment
// map's 2D sampling distribution).
#include <nlohmann/json.hpp>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <sstream>

#include "atrous/error.h"
#include "atrous/render.h"
#include "io/image_io.h"
#include "render/camera.h"
#include "render/lights.h"
#include "render/sampling.h"
#include "render/scene_data.h"
#include "render/scene_limits.h"

namespace atrous {
namespace pt {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// Builds SceneData step by step; finalize() derives the light list and distributions.
class SceneBuilder {
public:
    explicit SceneBuilder(std::string name) { d.name = std::move(name); }

    int addMaterial(const std::string& name, const Material& m) {
        d.materials.push_back(m);
        d.materialNames.push_back(name);
        return int(d.materials.size()) - 1;
    }
    int addMesh(const std::string& name) {
        d.meshNames.push_back(name);
        return int(d.meshNames.size()) - 1;
    }
    // `reflectance`: the texture is an albedo (diffuse colour), so texels are clamped to [0, 1]
    // like the JSON and MTL colours (a texel of 50 would create energy, and the albedo buffer, which
    // is clamped, would no longer match the image). Environment maps are radiance: never clamped.
    int addTexture(const Image& img, bool reflectance = false) {
        Texture t;
        t.offset = int64_t(d.texels.size());
        t.width = img.width();
        t.height = img.height();
        const float* p = img.data();
        for (size_t i = 0; i < size_t(img.width()) * img.height() * 3; ++i) {
            float v = p[i];
            v = std::isfinite(v) && v > 0.0f ? v : 0.0f;  // NaN/Inf/negatives never spread
            d.texels.push_back(reflectance ? std::min(v, 1.0f) : v);
        }
        d.textures.push_back(t);
        return int(d.textures.size()) - 1;
    }
    uint32_t addVertex(Vec3 p, Vec3 n = Vec3(0.0f), Vec2 uv = Vec2()) {
        d.positions.push_back(p);
        d.normals.push_back(n);
        d.uvs.push_back(uv);
        return uint32_t(d.positions.size() - 1);
    }
    void addTriangle(uint32_t a, uint32_t b, uint32_t c, int material, int mesh) {
        d.indices.push_back(a);
        d.indices.push_back(b);
        d.indices.push_back(c);
        d.triMaterial.push_back(material);
        d.triMesh.push_back(mesh);
        d.triLight.push_back(-1);
    }
    // Quad p0 p1 p2 p3 (in order around the edge) as two triangles, uv (0,0) (1,0) (1,1) (0,1).
    // When `facing` is non-zero the winding is chosen so the geometric normal points along it
    // (matters for one-sided emitters).
    void addQuad(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, int material, int mesh, Vec3 facing = Vec3(0.0f)) {
        uint32_t a = addVertex(p0, Vec3(0.0f), Vec2(0, 0)), b = addVertex(p1, Vec3(0.0f), Vec2(1, 0));
        uint32_t c = addVertex(p2, Vec3(0.0f), Vec2(1, 1)), e = addVertex(p3, Vec3(0.0f), Vec2(0, 1));
        if (dot(cross(p1 - p0, p2 - p0), facing) < 0.0f) {
            addTriangle(a, c, b, material, mesh);
            addTriangle(a, e, c, material, mesh);
        } else {
            addTriangle(a, b, c, material, mesh);
            addTriangle(a, c, e, material, mesh);
        }
    }
    void addSphere(Vec3 c, float r, int material, int mesh) { d.spheres.push_back(Sphere{c, r, material, mesh}); }
    void addPointLight(Vec3 p, Vec3 intensity) {
        Light l;
        l.type = LightType::Point;
        l.position = p;
        l.intensity = intensity;
        pointLights.push_back(l);
    }
    void setEnvConstant(Vec3 c) {
        d.env = Environment{};
        d.env.type = EnvType::Constant;
        d.env.color = c;
    }
    void setEnvMap(const Image& img, float scale) {
        d.env = Environment{};
        d.env.type = EnvType::Map;
        d.env.color = Vec3(scale);
        d.env.texture = addTexture(img);
    }
    void setCamera(const Camera& c) { d.camera = c; }
    // Look-at camera; the target is also what orbit and dolly paths turn about / move towards.
    void setCamera(Vec3 eye, Vec3 target, Vec3 up, float fovDeg, Vec3 pathTarget) {
        d.camera = makeLookAtCamera(eye, target, up, fovDeg);
        d.cameraTarget = pathTarget;
        d.cameraFovDeg = fovDeg;
    }
    void setMotion(int mesh, const MeshMotion& m) {
        if (d.meshMotion.size() <= size_t(mesh)) d.meshMotion.resize(size_t(mesh) + 1);
        d.meshMotion[size_t(mesh)] = m;
    }

    std::shared_ptr<SceneData> finalize();

    SceneData d;
    std::vector<Light> pointLights;
};

std::shared_ptr<SceneData> SceneBuilder::finalize() {
    // Bounding sphere of geometry and camera (ray offsets, environment light power).
    Vec3 lo(1e30f), hi(-1e30f);
    for (const Vec3& p : d.positions) { lo = minv(lo, p); hi = maxv(hi, p); }
    for (const Sphere& s : d.spheres) { lo = minv(lo, s.center - Vec3(s.radius)); hi = maxv(hi, s.center + Vec3(s.radius)); }
    lo = minv(lo, d.camera.position);
    hi = maxv(hi, d.camera.position);
    d.sceneRadius = maxf(1e-3f, 0.5f * length(hi - lo));

    // Lights: emissive triangles, point lights, the environment. Chosen proportionally to an
    // estimate of their power (luminance), which keeps dim lights from eating samples.
    std::vector<float> power;
    d.lights.clear();
    for (size_t t = 0; t < d.triMaterial.size(); ++t) {
        const Material& m = d.materials[d.triMaterial[t]];
        if (maxComponent(m.emission) <= 0.0f) continue;
        const uint32_t* idx = d.indices.data() + 3 * t;
        float area = 0.5f * length(cross(d.positions[idx[1]] - d.positions[idx[0]], d.positions[idx[2]] - d.positions[idx[0]]));
        if (area <= 0.0f) continue;
        Light l;
        l.type = LightType::Triangle;
        l.triangle = int32_t(t);
        d.triLight[t] = int32_t(d.lights.size());
        d.lights.push_back(l);
        power.push_back(kPi * area * maxf(1e-6f, luminance(m.emission)));
    }
    for (const Light& l : pointLights) {
        d.lights.push_back(l);
        power.push_back(4.0f * kPi * maxf(1e-6f, luminance(l.intensity)));
    }
    d.envDist.clear();
    if (d.env.type == EnvType::Map) {
        const Texture& t = d.textures[d.env.texture];
        const int w = t.width, h = t.height;
        // func(u, v) = luminance * sin(theta): the lat-long map's texel solid angle goes with
        // sin(theta), so this samples directions in proportion to radiance.
        d.env.condCdf = 0;
        d.env.condInt = int64_t(h) * (w + 1);
        d.env.margCdf = d.env.condInt + h;
        d.envDist.assign(size_t(d.env.margCdf) + h + 1, 0.0f);
        std::vector<double> rowInt(h);
        size_t plane = size_t(w) * h;
        double total = 0.0;
        for (int y = 0; y < h; ++y) {
            float sinTheta = std::sin((y + 0.5f) * kPi / h);
            float* cdf = d.envDist.data() + size_t(y) * (w + 1);
            double acc = 0.0;
            std::vector<double> f(w);
            for (int x = 0; x < w; ++x) {
                const float* p = d.texels.data() + t.offset + size_t(y) * w + x;
                f[x] = std::max(0.0, double(luminance(Vec3(p[0], p[plane], p[2 * plane])))) * sinTheta;
                acc += f[x];
            }
            double run = 0.0;
            cdf[0] = 0.0f;
            for (int x = 0; x < w; ++x) {
                run += f[x];
                cdf[x + 1] = acc > 0.0 ? float(run / acc) : float(x + 1) / float(w);
            }
            cdf[w] = 1.0f;
            rowInt[y] = acc / w;
            d.envDist[size_t(d.env.condInt) + y] = float(acc / w);
            total += acc / w;
        }
        float* marg = d.envDist.data() + d.env.margCdf;
        double run = 0.0;
        marg[0] = 0.0f;
        for (int y = 0; y < h; ++y) {
            run += rowInt[y];
            marg[y + 1] = total > 0.0 ? float(run / total) : float(y + 1) / float(h);
        }
        marg[h] = 1.0f;
        d.env.margInt = float(total / h);
        // Average radiance over the sphere (sin-weighted mean of the map's luminance) for the power.
        double avg = 0.0, wsum = 0.0;
        for (int y = 0; y < h; ++y) {
            double st = std::sin((y + 0.5) * kPi / h);
            avg += rowInt[y];
            wsum += st;
        }
        float avgL = wsum > 0.0 ? float(avg / wsum) * luminance(d.env.color) : 0.0f;
        if (total > 0.0) {
            d.env.lightIndex = int32_t(d.lights.size());
            Light l;
            l.type = LightType::Environment;
            d.lights.push_back(l);
            power.push_back(kPi * d.sceneRadius * d.sceneRadius * 4.0f * kPi * maxf(1e-6f, avgL));
        }
    } else if (d.env.type == EnvType::Constant && maxComponent(d.env.color) > 0.0f) {
        d.env.lightIndex = int32_t(d.lights.size());
        Light l;
        l.type = LightType::Environment;
        d.lights.push_back(l);
        power.push_back(kPi * d.sceneRadius * d.sceneRadius * 4.0f * kPi * maxf(1e-6f, luminance(d.env.color)));
    }
    d.lightCdf.assign(d.lights.size() + 1, 0.0f);
    double sum = 0.0;
    for (float p : power) sum += p;
    double run = 0.0;
    for (size_t i = 0; i < power.size(); ++i) {
        run += power[i];
        d.lightCdf[i + 1] = float(run / sum);
    }
    if (!power.empty()) d.lightCdf.back() = 1.0f;
    return std::make_shared<SceneData>(std::move(d));
}

Material diffuse(Vec3 albedo) {
    Material m;
    m.type = MaterialType::Diffuse;
    m.albedo = albedo;
    return m;
}

Material emissive(Vec3 radiance) {
    Material m = diffuse(Vec3(0.0f));
    m.emission = radiance;
    return m;
}

// ---- procedural sky with a sun ----

// Radiance of a clear sky: a blue zenith fading to a bright horizon, a warm glow around the sun,
// a dim ground below the horizon. Not a physical sky model; chosen to look plausible and give the
// strong, small sun that makes fireflies (what the denoisers must survive).
Vec3 skyRadiance(Vec3 dir, Vec3 sun) {
    if (dir.y < 0.0f) return Vec3(0.16f, 0.15f, 0.13f) * 0.6f;
    float up = std::pow(std::max(0.0f, dir.y), 0.45f);
    Vec3 horizon(0.55f, 0.6f, 0.68f), zenith(0.12f, 0.24f, 0.55f);
    Vec3 c = horizon * (1.0f - up) + zenith * up;
    float cs = std::max(0.0f, dot(dir, sun));
    c += Vec3(0.9f, 0.7f, 0.45f) * (0.35f * std::pow(cs, 24.0f));
    return c;
}

Image makeSkyMap(int w, int h, Vec3 sunDir, float sunAngularRadius, Vec3 sunRadiance) {
    Image img(w, h, 3);
    const float cosSun = std::cos(sunAngularRadius);
    const int ss = 4;  // supersampling so the sun's disk has soft, correct coverage
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            Vec3 acc(0.0f);
            for (int j = 0; j < ss; ++j)
                for (int i = 0; i < ss; ++i) {
                    Vec3 dir = latLongToDirection((x + (i + 0.5f) / ss) / w, (y + (j + 0.5f) / ss) / h);
                    acc += dot(dir, sunDir) >= cosSun ? sunRadiance : skyRadiance(dir, sunDir);
                }
            acc = acc / float(ss * ss);
            for (int c = 0; c < 3; ++c) img(x, y, c) = acc[c];
        }
    return img;
}

// ---- built-in scenes ----

// The Cornell box (Cornell University Program of Computer Graphics measurements, in metres /100
// of the original millimetre-ish units), camera as in the original photograph.
void addCornellRoom(SceneBuilder& b, bool areaLight, Vec3 lightRadiance, int floorMaterial = -1) {
    int white = b.addMaterial("white", diffuse(Vec3(0.725f, 0.71f, 0.68f)));
    int red = b.addMaterial("red", diffuse(Vec3(0.63f, 0.065f, 0.05f)));
    int green = b.addMaterial("green", diffuse(Vec3(0.14f, 0.45f, 0.091f)));
    const float s = 0.01f;
    auto P = [s](float x, float y, float z) { return Vec3(x * s, y * s, z * s); };
    int floorMat = floorMaterial >= 0 ? floorMaterial : white;
    b.addQuad(P(552.8f, 0, 0), P(0, 0, 0), P(0, 0, 559.2f), P(549.6f, 0, 559.2f), floorMat, b.addMesh("floor"));
    b.addQuad(P(556, 548.8f, 0), P(556, 548.8f, 559.2f), P(0, 548.8f, 559.2f), P(0, 548.8f, 0), white, b.addMesh("ceiling"));
    b.addQuad(P(549.6f, 0, 559.2f), P(0, 0, 559.2f), P(0, 548.8f, 559.2f), P(556, 548.8f, 559.2f), white, b.addMesh("back"));
    b.addQuad(P(0, 0, 559.2f), P(0, 0, 0), P(0, 548.8f, 0), P(0, 548.8f, 559.2f), green, b.addMesh("right_wall"));
    b.addQuad(P(552.8f, 0, 0), P(549.6f, 0, 559.2f), P(556, 548.8f, 559.2f), P(556, 548.8f, 0), red, b.addMesh("left_wall"));
    if (areaLight) {
        int light = b.addMaterial("light", emissive(lightRadiance));
        // Slightly below the ceiling, facing down.
        b.addQuad(P(343, 548.7f, 227), P(343, 548.7f, 332), P(213, 548.7f, 332), P(213, 548.7f, 227), light,
                  b.addMesh("light"), Vec3(0, -1, 0));
    }
    // Paths turn about the middle of the box.
    b.setCamera(P(278, 273, -800), P(278, 273, 0), Vec3(0, 1, 0), 39.3f, P(278, 273, 279.6f));
}

void addCornellBlocks(SceneBuilder& b) {
    int white = 0;  // "white" is the room's first material
    const float s = 0.01f;
    auto P = [s](float x, float y, float z) { return Vec3(x * s, y * s, z * s); };
    int shortBox = b.addMesh("short_box");
    b.addQuad(P(130, 165, 65), P(82, 165, 225), P(240, 165, 272), P(290, 165, 114), white, shortBox);
    b.addQuad(P(290, 0, 114), P(290, 165, 114), P(240, 165, 272), P(240, 0, 272), white, shortBox);
    b.addQuad(P(130, 0, 65), P(130, 165, 65), P(290, 165, 114), P(290, 0, 114), white, shortBox);
    b.addQuad(P(82, 0, 225), P(82, 165, 225), P(130, 165, 65), P(130, 0, 65), white, shortBox);
    b.addQuad(P(240, 0, 272), P(240, 165, 272), P(82, 165, 225), P(82, 0, 225), white, shortBox);
    int tallBox = b.addMesh("tall_box");
    b.addQuad(P(423, 330, 247), P(265, 330, 296), P(314, 330, 456), P(472, 330, 406), white, tallBox);
    b.addQuad(P(423, 0, 247), P(423, 330, 247), P(472, 330, 406), P(472, 0, 406), white, tallBox);
    b.addQuad(P(472, 0, 406), P(472, 330, 406), P(314, 330, 456), P(314, 0, 456), white, tallBox);
    b.addQuad(P(314, 0, 456), P(314, 330, 456), P(265, 330, 296), P(265, 0, 296), white, tallBox);
    b.addQuad(P(265, 0, 296), P(265, 330, 296), P(423, 330, 247), P(423, 0, 247), white, tallBox);
}

// Emitted radiance of the Cornell ceiling light (the classic scene's spectrum reduced to RGB,
// scaled so a plain clamp + sRGB preview is well exposed).
const Vec3 kCornellLight(17.0f, 12.0f, 4.0f);

std::shared_ptr<SceneData> buildCornell() {
    SceneBuilder b("cornell");
    addCornellRoom(b, true, kCornellLight);
    addCornellBlocks(b);
    return b.finalize();
}

std::shared_ptr<SceneData> buildCornellPoint() {
    SceneBuilder b("cornell-point");
    addCornellRoom(b, false, Vec3(0.0f));
    addCornellBlocks(b);
    // A point light 0.9 m below the ceiling's centre: hard shadows (the SURE paper's Cornell). Closer
    // to the ceiling, the hot spot it makes there turns all indirect light into fireflies.
    b.addPointLight(Vec3(2.78f, 4.6f, 2.795f), Vec3(30.0f, 24.0f, 17.0f));
    return b.finalize();
}

std::shared_ptr<SceneData> buildCornellSpheres() {
    SceneBuilder b("cornell-spheres");
    Material checker = diffuse(Vec3(0.75f, 0.74f, 0.72f));
    checker.checker = 1;
    checker.albedo2 = Vec3(0.12f, 0.12f, 0.14f);
    checker.checkerScale = 8.0f;
    addCornellRoom(b, true, kCornellLight);
    int floorMat = b.addMaterial("checker", checker);
    // The floor quad is the room's first mesh (two triangles): give it the checker material.
    b.d.triMaterial[0] = floorMat;
    b.d.triMaterial[1] = floorMat;
    Material mirror;
    mirror.type = MaterialType::Mirror;
    mirror.albedo = Vec3(0.95f);
    Material glass;
    glass.type = MaterialType::Dielectric;
    glass.albedo = Vec3(1.0f);
    glass.ior = 1.5f;
    b.addSphere(Vec3(1.75f, 1.0f, 3.6f), 1.0f, b.addMaterial("mirror", mirror), b.addMesh("mirror_sphere"));
    b.addSphere(Vec3(3.8f, 1.0f, 1.9f), 1.0f, b.addMaterial("glass", glass), b.addMesh("glass_sphere"));
    return b.finalize();
}

std::shared_ptr<SceneData> buildSphereEnv() {
    SceneBuilder b("sphere-env");
    Material checker = diffuse(Vec3(0.7f, 0.7f, 0.68f));
    checker.checker = 1;
    checker.albedo2 = Vec3(0.18f, 0.2f, 0.22f);
    checker.checkerScale = 60.0f;  // 2 m checks on the 120 m ground
    int floorMat = b.addMaterial("checker", checker);
    Material mirror;
    mirror.type = MaterialType::Mirror;
    mirror.albedo = Vec3(0.95f);
    int mirrorMat = b.addMaterial("mirror", mirror);
    int red = b.addMaterial("red", diffuse(Vec3(0.7f, 0.12f, 0.08f)));
    Material gold;
    gold.type = MaterialType::Conductor;
    gold.albedo = Vec3(1.0f, 0.78f, 0.34f);
    gold.roughness = 0.25f;
    int goldMat = b.addMaterial("gold", gold);
    Material plastic;
    plastic.type = MaterialType::Plastic;
    plastic.albedo = Vec3(0.1f, 0.25f, 0.6f);
    plastic.roughness = 0.08f;
    plastic.ior = 1.5f;
    int plasticMat = b.addMaterial("blue_plastic", plastic);
    const float half = 60.0f;  // far enough that the horizon meets the sky
    b.addQuad(Vec3(-half, 0, -half), Vec3(half, 0, -half), Vec3(half, 0, half), Vec3(-half, 0, half), floorMat,
              b.addMesh("ground"), Vec3(0, 1, 0));
    b.addSphere(Vec3(0.0f, 1.0f, 0.0f), 1.0f, mirrorMat, b.addMesh("mirror_sphere"));
    b.addSphere(Vec3(-2.2f, 0.6f, 0.8f), 0.6f, red, b.addMesh("red_sphere"));
    b.addSphere(Vec3(2.1f, 0.7f, 0.6f), 0.7f, goldMat, b.addMesh("gold_sphere"));
    b.addSphere(Vec3(0.9f, 0.4f, 2.0f), 0.4f, plasticMat, b.addMesh("plastic_sphere"));
    Vec3 sun = normalize(Vec3(-0.55f, 0.62f, 0.55f));
    // Sun: 0.5 degree angular radius (a little larger than the real one so a 1024-wide map
    // resolves it), radiance ~2e4 (the sun's irradiance ~3x the sky's).
    b.setEnvMap(makeSkyMap(1024, 512, sun, 0.5f * kPi / 180.0f, Vec3(1.0f, 0.93f, 0.82f) * 20000.0f), 1.0f);
    b.setCamera(Vec3(0.0f, 2.2f, 7.0f), Vec3(0.0f, 0.7f, 0.0f), Vec3(0, 1, 0), 38.0f, Vec3(0.0f, 0.7f, 0.0f));
    return b.finalize();
}

// The Cornell box with motion (for temporal denoisers): the short box turns 40 degrees about its
// centre and a blue sphere floats from right to left above it over the sequence (t in [0, 1]).
std::shared_ptr<SceneData> buildCornellMoving() {
    SceneBuilder b("cornell-moving");
    addCornellRoom(b, true, kCornellLight);
    addCornellBlocks(b);
    MeshMotion turn;
    turn.rotateYDeg = 40.0f;
    turn.pivot = Vec3(1.855f, 0.0f, 1.69f);  // the short box's footprint centre
    b.setMotion(b.d.meshNames.size() - 2, turn);  // "short_box" (addCornellBlocks: short, then tall)
    int blue = b.addMaterial("blue", diffuse(Vec3(0.1f, 0.2f, 0.7f)));
    int sphere = b.addMesh("moving_sphere");
    b.addSphere(Vec3(4.3f, 2.35f, 1.2f), 0.5f, blue, sphere);
    MeshMotion slide;
    slide.translate = Vec3(-3.0f, 0.0f, 0.0f);
    b.setMotion(sphere, slide);
    return b.finalize();
}

// ---- JSON scenes ----

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
        m.texture = b.addTexture(io::readImage(path), /*reflectance=*/true);  // InputError names the texture file
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

// Applies scale, then a rotation about +y (degrees), then a translation.
struct Transform {
    Vec3 scale = Vec3(1.0f);
    float rotY = 0.0f;
    Vec3 translate = Vec3(0.0f);
    Vec3 point(Vec3 p) const {
        p = p * scale;
        float cs = std::cos(rotY), sn = std::sin(rotY);
        return Vec3(cs * p.x + sn * p.z, p.y, -sn * p.x + cs * p.z) + translate;
    }
    Vec3 normal(Vec3 n) const {
        n = n / scale;  // inverse transpose of the scale
        float cs = std::cos(rotY), sn = std::sin(rotY);
        return normalize(Vec3(cs * n.x + sn * n.z, n.y, -sn * n.x + cs * n.z));
    }
};

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

// What tinyobjloader does not check, read from the OBJ text before it parses it: a face index
// beyond int's range (atoi wraps 99999999999999999999 to -1, the last vertex), a face with more
// than kMaxFaceVertices vertices (its ear clipping is quadratic: a 200k-vertex face ran for
// minutes), and the mtllib names (tinyobjloader only warns when one is missing).
std::vector<std::string> prescanObj(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<std::string> mtllibs;
    std::string line;
    size_t lineNo = 0;
    long long counts[3] = {0, 0, 0};  // v, vt, vn so far: a relative (negative) index must stay within them
    long long maxIndex[3] = {0, 0, 0};  // the largest absolute index, checked against the totals at the end
    size_t maxLine[3] = {0, 0, 0};
    std::string maxToken[3];
    while (std::getline(in, line)) {
        ++lineNo;
        size_t i = line.find_first_not_of(" \t");
        if (i == std::string::npos) continue;
        const bool face = line.compare(i, 2, "f ") == 0 || line.compare(i, 2, "f\t") == 0;
        const bool lib = line.compare(i, 7, "mtllib ") == 0 || line.compare(i, 7, "mtllib\t") == 0;
        // v, vt, vn: every value a finite number (tinyobjloader reads "nan" or "x" as 0 and 1e39 as Inf).
        const size_t vlen = line.compare(i, 2, "v ") == 0 ? 2 : (line.compare(i, 3, "vt ") == 0 || line.compare(i, 3, "vn ") == 0) ? 3 : 0;
        if (vlen) {
            ++counts[vlen == 2 ? 0 : (line[i + 1] == 't' ? 1 : 2)];
            std::istringstream vals(line.substr(i + vlen));
            std::string tok;
            while (vals >> tok) {
                char* end = nullptr;
                const double x = std::strtod(tok.c_str(), &end);
                if (end == tok.c_str() || *end != '\0' || !std::isfinite(x) || std::fabs(x) > 3.0e38)
                    throw InputError(path + ": line " + std::to_string(lineNo) + ": \"" + tok + "\" is not a finite number");
            }
            continue;
        }
        if (lib) {
            std::istringstream names(line.substr(i + 7));
            std::string n;
            while (names >> n) mtllibs.push_back(n);
            continue;
        }
        if (!face) continue;
        size_t count = 0;
        for (size_t k = i + 1; k < line.size();) {
            while (k < line.size() && (line[k] == ' ' || line[k] == '\t' || line[k] == '\r')) ++k;
            if (k >= line.size()) break;
            const size_t tokenStart = k;
            while (k < line.size() && line[k] != ' ' && line[k] != '\t' && line[k] != '\r') ++k;
            ++count;
            // Each of v/vt/vn: an optional sign and digits; more than 10 digits or above INT_MAX is out of range.
            const std::string token = line.substr(tokenStart, k - tokenStart);
            size_t p = 0;
            int part = 0;
            while (p <= token.size()) {
                size_t q = token.find('/', p);
                if (q == std::string::npos) q = token.size();
                std::string num = token.substr(p, q - p);
                if (!num.empty() && (num[0] == '-' || num[0] == '+')) num.erase(0, 1);
                size_t digits = num.find_first_not_of("0123456789");
                if (digits == std::string::npos) digits = num.size();
                const std::string d = num.substr(0, digits);
                const size_t nz = d.find_first_not_of('0');
                const std::string sig = nz == std::string::npos ? "" : d.substr(nz);
                if (sig.size() > 10 || (sig.size() == 10 && sig > "2147483647"))
                    throw InputError(path + ": line " + std::to_string(lineNo) + ": face index \"" + token +
                                     "\" is out of range");
                const long long value = sig.empty() ? 0 : std::stoll(sig);
                const bool negative = q > p && token[p] == '-';
                if (part < 3 && !d.empty() && (value == 0 || (negative && value > counts[part])))
                    throw InputError(path + ": line " + std::to_string(lineNo) + ": face index \"" + token +
                                     "\" refers to a missing " + (part == 0 ? "vertex" : part == 1 ? "texture coordinate" : "normal"));
                if (part < 3 && !negative && value > maxIndex[part]) {
                    maxIndex[part] = value;
                    maxLine[part] = lineNo;
                    maxToken[part] = token;
                }
                ++part;
                p = q + 1;
            }
            if (count > size_t(kMaxFaceVertices))
                throw InputError(path + ": line " + std::to_string(lineNo) + ": face with more than " +
                                 std::to_string(kMaxFaceVertices) + " vertices");
        }
    }
    for (int k = 0; k < 3; ++k)
        if (maxIndex[k] > counts[k])
            throw InputError(path + ": line " + std::to_string(maxLine[k]) + ": face index \"" + maxToken[k] +
                             "\" refers to a missing " + (k == 0 ? "vertex" : k == 1 ? "texture coordinate" : "normal") +
                             " (the file has " + std::to_string(counts[k]) + ")");
    return mtllibs;
}

// An MTL file's numbers, before tinyobjloader reads them ("nan" or "x" as 0, 1e39 as Inf): every
// value of a colour or scalar statement is a finite number.
void prescanMtl(const std::string& mtl, const std::string& objPath) {
    static const char* const kNumeric[] = {"Ka", "Kd", "Ks", "Ke", "Kt", "Tf", "Ni", "Ns", "d", "Tr",
                                           "Pr", "Pm", "Ps", "Pc", "Pcr", "aniso", "anisor"};
    std::ifstream in(mtl, std::ios::binary);
    std::string line;
    size_t lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        std::istringstream words(line);
        std::string key, tok;
        if (!(words >> key)) continue;
        bool numeric = false;
        for (const char* k : kNumeric) numeric = numeric || key == k;
        if (!numeric) continue;
        while (words >> tok) {
            if (tok == "spectral" || tok == "xyz") break;
            char* end = nullptr;
            const double x = std::strtod(tok.c_str(), &end);
            if (end == tok.c_str() || *end != '\0' || !std::isfinite(x) || std::fabs(x) > 3.0e38)
                throw InputError(mtl + ": line " + std::to_string(lineNo) + ": " + key + " value \"" + tok +
                                 "\" is not a finite number (material file of " + objPath + ")");
        }
    }
}

// The rule of scene_limits.h for one MTL value: the same ranges as the JSON scene's.
void checkMtlValue(const std::string& objPath, const std::string& mtl, const std::string& material, const char* key,
                   const float* v, int n, const ValueRule& rule) {
    for (int i = 0; i < n; ++i)
        if (!allowed(rule, v[i]))
            throw InputError(objPath + ": material \"" + material + "\" (" + mtl + "): " + key + " " + rule.text +
                             " (got " + formatValue(v[i]) + ")");
}

void loadObj(const JsonContext& c, SceneBuilder& b, const std::string& path, int overrideMaterial, int mesh,
             const Transform& xf) {
    tinyobj::ObjReaderConfig cfg;
    cfg.triangulate = true;
    cfg.vertex_color = false;
    cfg.mtl_search_path = fs::path(path).parent_path().string();
    tinyobj::ObjReader reader;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw InputError(path + ": cannot open OBJ file (referenced by " + c.source + ")");
    const std::vector<std::string> mtllibs = prescanObj(path);
    std::string mtlNames;
    for (const std::string& m : mtllibs) {
        const std::string full = (fs::path(path).parent_path() / m).lexically_normal().string();
        if (!fs::is_regular_file(full, ec))
            throw InputError(path + ": mtllib " + m + ": material file not found (" + full + ")");
        prescanMtl(full, path);
        mtlNames += (mtlNames.empty() ? "" : ", ") + full;
    }
    if (mtlNames.empty()) mtlNames = "no mtllib";
    if (!reader.ParseFromFile(path, cfg)) {
        std::string err = reader.Error();
        while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
        throw InputError(path + ": malformed OBJ (" + (err.empty() ? "parse error" : err) + ")");
    }
    const tinyobj::attrib_t& a = reader.GetAttrib();
    const auto& shapes = reader.GetShapes();
    const auto& mtls = reader.GetMaterials();
    // MTL materials -> ours: Kd (and map_Kd), Ke, illum 3 = mirror, illum 7 or d < 1 = glass (Ni),
    // PBR metallic > 0.5 = conductor (Pr roughness). Values follow the JSON scene's rules
    // (scene_limits.h): Kd, Ks in [0, 1], Ke in [0, 1e8], Ni in [1, 4] when set, Pr in [0, 1].
    std::vector<int> mtlIds(mtls.size(), -1);
    int defaultMaterial = -1;
    auto materialFor = [&](int mtlIndex) -> int {
        if (overrideMaterial >= 0) return overrideMaterial;
        if (mtlIndex < 0 || mtlIndex >= int(mtls.size())) {
            if (defaultMaterial < 0) defaultMaterial = b.addMaterial(path + ":default", diffuse(Vec3(0.8f)));
            return defaultMaterial;
        }
        if (mtlIds[mtlIndex] >= 0) return mtlIds[mtlIndex];
        const tinyobj::material_t& t = mtls[mtlIndex];
        checkMtlValue(path, mtlNames, t.name, "Kd", t.diffuse, 3, kReflectanceRule);
        checkMtlValue(path, mtlNames, t.name, "Ke", t.emission, 3, kRadianceRule);
        checkMtlValue(path, mtlNames, t.name, "d", &t.dissolve, 1, kAnyFiniteRule);
        checkMtlValue(path, mtlNames, t.name, "Pm", &t.metallic, 1, kAnyFiniteRule);
        Material m = diffuse(Vec3(t.diffuse[0], t.diffuse[1], t.diffuse[2]));
        m.emission = Vec3(t.emission[0], t.emission[1], t.emission[2]);
        if (t.illum == 3 || t.illum == 5) {
            checkMtlValue(path, mtlNames, t.name, "Ks", t.specular, 3, kReflectanceRule);
            m.type = MaterialType::Mirror;
            m.albedo = Vec3(t.specular[0], t.specular[1], t.specular[2]);
            if (maxComponent(m.albedo) <= 0.0f) m.albedo = Vec3(1.0f);
        } else if (t.illum == 7 || t.dissolve < 1.0f) {
            if (t.ior > 1.0f) checkMtlValue(path, mtlNames, t.name, "Ni", &t.ior, 1, kIorRule);
            m.type = MaterialType::Dielectric;
            m.albedo = Vec3(1.0f);
            m.ior = t.ior > 1.0f ? t.ior : 1.5f;
        } else if (t.metallic > 0.5f) {
            checkMtlValue(path, mtlNames, t.name, "Pr", &t.roughness, 1, kRoughnessRule);
            m.type = MaterialType::Conductor;
            m.roughness = t.roughness > 0.0f ? t.roughness : 0.2f;
        }
        if (!t.diffuse_texname.empty()) {
            std::string tex = (fs::path(path).parent_path() / t.diffuse_texname).lexically_normal().string();
            try {
                m.texture = b.addTexture(io::readImage(tex), /*reflectance=*/true);
            } catch (const InputError& e) {
                throw InputError(std::string(e.what()) + " (map_Kd of material \"" + t.name + "\" in " + mtlNames +
                                 ", used by " + path + ")");
            }
        }
        m.albedo = minv(maxv(m.albedo, Vec3(0.0f)), Vec3(1.0f));
        mtlIds[mtlIndex] = b.addMaterial(t.name, m);
        return mtlIds[mtlIndex];
    };
    const size_t numV = a.vertices.size() / 3, numN = a.normals.size() / 3, numT = a.texcoords.size() / 2;
    size_t triangles = 0;
    const bool mirrored = xf.scale.x * xf.scale.y * xf.scale.z < 0.0f;
    for (const auto& shape : shapes) {
        const auto& idx = shape.mesh.indices;
        for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
            if (shape.mesh.num_face_vertices[f] != 3) throw InputError(path + ": face with " + std::to_string(shape.mesh.num_face_vertices[f]) + " vertices after triangulation");
            uint32_t v[3];
            for (int k = 0; k < 3; ++k) {
                const tinyobj::index_t& ix = idx[3 * f + k];
                if (ix.vertex_index < 0 || size_t(ix.vertex_index) >= numV)
                    throw InputError(path + ": malformed OBJ (face " + std::to_string(f + 1) + " refers to a missing vertex)");
                Vec3 p(a.vertices[3 * ix.vertex_index], a.vertices[3 * ix.vertex_index + 1], a.vertices[3 * ix.vertex_index + 2]);
                if (!isFinite(p)) throw InputError(path + ": malformed OBJ (vertex is not a finite number)");
                const Vec3 world = xf.point(p);
                if (!allowed(kCoordinateRule, world.x) || !allowed(kCoordinateRule, world.y) || !allowed(kCoordinateRule, world.z))
                    throw InputError(path + ": vertex " + std::to_string(ix.vertex_index + 1) + " after the transform " +
                                     kCoordinateRule.text + " (got " + formatValue(world.x) + ", " + formatValue(world.y) +
                                     ", " + formatValue(world.z) + ")");
                if (size_t(ix.normal_index + 1) > numN || size_t(ix.texcoord_index + 1) > numT)
                    throw InputError(path + ": malformed OBJ (face " + std::to_string(f + 1) + " refers to a missing " +
                                     (size_t(ix.normal_index + 1) > numN ? "normal)" : "texture coordinate)"));
                Vec3 n(0.0f);
                if (ix.normal_index >= 0 && size_t(ix.normal_index) < numN) {
                    n = xf.normal(Vec3(a.normals[3 * ix.normal_index], a.normals[3 * ix.normal_index + 1], a.normals[3 * ix.normal_index + 2]));
                    if (!isFinite(n)) n = Vec3(0.0f);
                }
                Vec2 uv;
                if (ix.texcoord_index >= 0 && size_t(ix.texcoord_index) < numT) {
                    uv = Vec2(a.texcoords[2 * ix.texcoord_index], a.texcoords[2 * ix.texcoord_index + 1]);
                    if (!allowed(kTexcoordRule, uv.x) || !allowed(kTexcoordRule, uv.y))
                        throw InputError(path + ": texture coordinate (vt) " + std::to_string(ix.texcoord_index + 1) + " " +
                                         kTexcoordRule.text + " (got " + formatValue(uv.x) + " " + formatValue(uv.y) + ")");
                }
                v[k] = b.addVertex(world, n, uv);
            }
            int mi = f < shape.mesh.material_ids.size() ? shape.mesh.material_ids[f] : -1;
            // A mirroring transform (an odd number of negative scale factors) reverses the
            // vertices' winding; swapping two keeps each face's front (which side is outside for
            // glass, which side a one-sided emitter lights) where the file put it.
            if (mirrored)
                b.addTriangle(v[0], v[2], v[1], materialFor(mi), mesh);
            else
                b.addTriangle(v[0], v[1], v[2], materialFor(mi), mesh);
            ++triangles;
        }
    }
    if (triangles == 0) throw InputError(path + ": OBJ file contains no triangles");
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
                loadObj(c, b, file, materialRef(o, where, false), b.addMesh(name), parseTransform(c, o, where));
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
                        Image map = io::readImage(file);
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

// ---- public API ----

const std::vector<std::string>& builtinSceneNames() {
    static const std::vector<std::string> names = {"cornell", "cornell-point", "cornell-spheres", "sphere-env", "cornell-moving"};
    return names;
}

Scene Scene::builtin(const std::string& name) {
    Scene s;
    if (name == "cornell") s.mData = pt::buildCornell();
    else if (name == "cornell-point") s.mData = pt::buildCornellPoint();
    else if (name == "cornell-spheres") s.mData = pt::buildCornellSpheres();
    else if (name == "sphere-env") s.mData = pt::buildSphereEnv();
    else if (name == "cornell-moving") s.mData = pt::buildCornellMoving();
    else {
        std::string list;
        for (const auto& n : builtinSceneNames()) list += (list.empty() ? "" : ", ") + n;
        throw InputError("--scene: unknown scene \"" + name + "\" (built-in scenes: " + list + "; or a .json file)");
    }
    return s;
}

Scene Scene::load(const std::string& path) {
    if (path.find('\0') != std::string::npos)
        throw InputError(path.substr(0, path.find('\0')) + "...: the scene path contains a NUL byte");
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    if (!in || std::filesystem::is_directory(path, ec)) throw InputError(path + ": cannot open scene file");
    std::stringstream ss;
    ss << in.rdbuf();
    return parse(ss.str(), std::filesystem::path(path).parent_path().string(), path);
}

Scene Scene::parse(const std::string& jsonText, const std::string& baseDir, const std::string& sourceName) {
    Scene s;
    s.mData = pt::parseJsonScene(jsonText, pt::JsonContext{sourceName, baseDir});
    return s;
}

Scene Scene::loadByNameOrFile(const std::string& nameOrPath) {
    std::error_code ec;
    bool json = nameOrPath.size() >= 5 && nameOrPath.compare(nameOrPath.size() - 5, 5, ".json") == 0;
    if (json || std::filesystem::exists(nameOrPath, ec)) return load(nameOrPath);
    return builtin(nameOrPath);
}

const std::string& Scene::name() const { return mData->name; }

int Scene::materialId(const std::string& name) const {
    for (size_t i = 0; i < mData->materialNames.size(); ++i)
        if (mData->materialNames[i] == name) return int(i);
    return -1;
}

int Scene::meshId(const std::string& name) const {
    for (size_t i = 0; i < mData->meshNames.size(); ++i)
        if (mData->meshNames[i] == name) return int(i);
    return -1;
}

}  // namespace atrous

// SceneBuilder: assembles a SceneData step by step (materials, meshes, textures, triangles, quads,
// spheres, lights, camera, motion); finalize() derives the light list with its power distribution
// and the environment map's 2D sampling distribution. Used by the built-in scenes
// (scene_builtin.cpp) and the scene-file parser (scene_json.cpp, scene_obj.cpp).
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "atrous/image.h"
#include "render/camera.h"
#include "render/scene_data.h"

namespace atrous::pt {

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

Material diffuse(Vec3 albedo);
Material emissive(Vec3 radiance);  // black diffuse with emitted radiance

}  // namespace atrous::pt

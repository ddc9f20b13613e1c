// The scene as flat arrays of plain structs, so the same data (and the shading code that reads it
// through SceneView) can be copied to a GPU later: triangles as vertex/normal/uv/index arrays with
// per-triangle material, mesh and light ids; analytic spheres; materials as one POD with a type
// enum; lights as POD arrays; textures as planar float images in one texel array.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "atrous/camera.h"
#include "atrous/math.h"

namespace atrous::pt {

enum class MaterialType : int32_t {
    Diffuse = 0,     // Lambertian, reflectance `albedo` (or texture / checker)
    Mirror = 1,      // ideal specular reflection tinted by `albedo` (delta)
    Dielectric = 2,  // smooth glass: Fresnel reflection / refraction with index `ior` (delta)
    Conductor = 3,   // rough metal: GGX with roughness alpha, Schlick Fresnel with F0 = albedo
    Plastic = 4,     // rough plastic: GGX dielectric coat (ior) over a Lambertian base (albedo)
};

struct Material {
    MaterialType type = MaterialType::Diffuse;
    Vec3 albedo = Vec3(0.8f);
    Vec3 emission = Vec3(0.0f);  // emitted radiance (one-sided: front face of triangles)
    int32_t texture = -1;        // image texture index replacing albedo, -1 = none
    int32_t checker = 0;         // 1: procedural checker between albedo and albedo2
    Vec3 albedo2 = Vec3(0.2f);
    float checkerScale = 8.0f;   // checks per unit of uv
    float roughness = 0.2f;      // GGX alpha (not squared)
    float ior = 1.5f;
};

struct Sphere {
    Vec3 center;
    float radius = 1.0f;
    int32_t material = 0;
    int32_t mesh = 0;
};

// A texture is planar float RGB: texels[offset + c * width * height + y * width + x].
struct Texture {
    int64_t offset = 0;
    int32_t width = 0;
    int32_t height = 0;
};

enum class LightType : int32_t { Triangle = 0, Point = 1, Environment = 2 };

struct Light {
    LightType type = LightType::Triangle;
    int32_t triangle = -1;  // Triangle: global triangle index (emission from its material)
    Vec3 position;          // Point
    Vec3 intensity;         // Point: radiant intensity, W/sr per channel
};

enum class EnvType : int32_t { None = 0, Constant = 1, Map = 2 };

// Environment: radiance arriving from direction d (y up). A Map is a lat-long texture with
// u = atan2(d.z, d.x) / 2pi + 1/2, v = acos(d.y) / pi (row 0 = up), importance-sampled through a
// 2D piecewise-constant distribution of luminance * sin(theta).
struct Environment {
    EnvType type = EnvType::None;
    Vec3 color = Vec3(0.0f);  // Constant: the radiance; Map: a scale
    int32_t texture = -1;
    int32_t lightIndex = -1;  // its index in the light list (for the MIS pdf of BSDF samples)
    // Distribution (Map only): conditional CDFs per row (height x (width+1)), row integrals
    // (height), marginal CDF (height+1) and total integral, all in envDist (see sampling.h).
    int64_t condCdf = 0, condInt = 0, margCdf = 0;
    float margInt = 0.0f;
};


// Non-owning view of the whole scene: what the shading code (host or device) reads.
struct SceneView {
    const Vec3* positions = nullptr;  // per vertex
    const Vec3* normals = nullptr;    // per vertex; (0,0,0) = use the geometric normal
    const Vec2* uvs = nullptr;        // per vertex
    const uint32_t* indices = nullptr;  // 3 per triangle
    const int32_t* triMaterial = nullptr;
    const int32_t* triMesh = nullptr;
    const int32_t* triLight = nullptr;  // light index of an emissive triangle, else -1
    int32_t numTriangles = 0;
    const Sphere* spheres = nullptr;
    int32_t numSpheres = 0;
    const Material* materials = nullptr;
    int32_t numMaterials = 0;
    const Texture* textures = nullptr;
    const float* texels = nullptr;
    const Light* lights = nullptr;
    const float* lightCdf = nullptr;  // numLights + 1 entries, lightCdf[numLights] = 1
    int32_t numLights = 0;
    const float* envDist = nullptr;
    Environment env;
    Camera camera;
    float sceneRadius = 1.0f;  // bounding-sphere radius (ray offsets)
};

// Animation (host only, src/render/animation.h). Time t runs over [0, 1] for the whole sequence.
// A camera keyframe: pose at time t (smoothly interpolated between keys, Catmull-Rom).
struct CameraKey {
    float t = 0.0f;
    Vec3 position, target;
    Vec3 up = Vec3(0.0f, 1.0f, 0.0f);
    float fovDeg = 40.0f;
};

// Rigid motion of one mesh, linear in t: at time t the rest geometry is rotated about the
// vertical axis through `pivot` by rotateYDeg * t degrees, then translated by translate * t.
struct MeshMotion {
    Vec3 translate = Vec3(0.0f);
    float rotateYDeg = 0.0f;
    Vec3 pivot = Vec3(0.0f);
    bool moving() const { return translate.x != 0.0f || translate.y != 0.0f || translate.z != 0.0f || rotateYDeg != 0.0f; }
};

// Host owner of the arrays (std::vector: host only; kernels see SceneView).
struct SceneData {
    std::string name;
    std::vector<Vec3> positions, normals;
    std::vector<Vec2> uvs;
    std::vector<uint32_t> indices;
    std::vector<int32_t> triMaterial, triMesh, triLight;
    std::vector<Sphere> spheres;
    std::vector<Material> materials;
    std::vector<std::string> materialNames;
    std::vector<std::string> meshNames;  // mesh id -> object name
    std::vector<Texture> textures;
    std::vector<float> texels;
    std::vector<Light> lights;
    std::vector<float> lightCdf;
    std::vector<float> envDist;
    Environment env;
    Camera camera;
    float sceneRadius = 1.0f;
    // Animation: the rest pose above is time 0 of "static" paths; orbit and dolly paths start
    // from `camera` and turn about / move towards `cameraTarget`.
    Vec3 cameraTarget = Vec3(0.0f);
    float cameraFovDeg = 40.0f;
    std::vector<CameraKey> cameraKeys;    // empty = no keyframed path
    std::vector<MeshMotion> meshMotion;   // per mesh id (may be shorter: missing = static)
    bool posed = false;                   // true for a scene already moved to some time t

    SceneView view() const {
        SceneView v;
        v.positions = positions.data();
        v.normals = normals.data();
        v.uvs = uvs.data();
        v.indices = indices.data();
        v.triMaterial = triMaterial.data();
        v.triMesh = triMesh.data();
        v.triLight = triLight.data();
        v.numTriangles = int32_t(triMaterial.size());
        v.spheres = spheres.data();
        v.numSpheres = int32_t(spheres.size());
        v.materials = materials.data();
        v.numMaterials = int32_t(materials.size());
        v.textures = textures.data();
        v.texels = texels.data();
        v.lights = lights.data();
        v.lightCdf = lightCdf.data();
        v.numLights = int32_t(lights.size());
        v.envDist = envDist.data();
        v.env = env;
        v.camera = camera;
        v.sceneRadius = sceneRadius;
        return v;
    }
};

}  // namespace atrous::pt

// The built-in scenes (Scene::builtin): three variants of the Cornell box, the box with mirror
// and glass spheres, spheres on a ground plane under the procedural sky, and the box with motion.
#include <memory>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/render.h"
#include "render/scene_builder.h"
#include "render/scene_data.h"
#include "render/scene_sky.h"

namespace atrous {
namespace pt {
namespace {

// A diffuse checker between albedo and albedo2, `scale` checks per unit of uv.
Material checkerDiffuse(Vec3 albedo, Vec3 albedo2, float scale) {
    Material m = diffuse(albedo);
    m.checker = 1;
    m.albedo2 = albedo2;
    m.checkerScale = scale;
    return m;
}

Material mirrorOf(Vec3 albedo) {
    Material m;
    m.type = MaterialType::Mirror;
    m.albedo = albedo;
    return m;
}

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
    const Material checker = checkerDiffuse(Vec3(0.75f, 0.74f, 0.72f), Vec3(0.12f, 0.12f, 0.14f), 8.0f);
    addCornellRoom(b, true, kCornellLight);
    int floorMat = b.addMaterial("checker", checker);
    // The floor quad is the room's first mesh (two triangles): give it the checker material.
    b.d.triMaterial[0] = floorMat;
    b.d.triMaterial[1] = floorMat;
    const Material mirror = mirrorOf(Vec3(0.95f));
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
    // 2 m checks on the 120 m ground.
    int floorMat = b.addMaterial("checker", checkerDiffuse(Vec3(0.7f, 0.7f, 0.68f), Vec3(0.18f, 0.2f, 0.22f), 60.0f));
    int mirrorMat = b.addMaterial("mirror", mirrorOf(Vec3(0.95f)));
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

}  // namespace
}  // namespace pt

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
        throw ParamError("scene", "scene", "must be a built-in scene (" + list + ") or a .json file", "'" + name + "'");
    }
    return s;
}

}  // namespace atrous

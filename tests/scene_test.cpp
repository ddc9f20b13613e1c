// Scene construction: built-ins, the JSON format (docs/scenes.md), OBJ/MTL meshes, and the
// errors a bad scene file produces.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "atrous/error.h"
#include "atrous/render.h"
#include "atrous/io/image_io.h"
#include "render/scene_data.h"
#include "test_util.h"

namespace atrous {
namespace {

void writeText(const std::string& path, const std::string& text) {
    std::ofstream(path) << text;
}

// The InputError message thrown by f, or "" if none.
template <class F>
std::string errorOf(F f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(SceneBuiltin, AllNamesBuildWithLightsAndGeometry) {
    ASSERT_EQ(builtinSceneNames().size(), 5u);  // cornell, cornell-point, cornell-spheres, sphere-env, cornell-moving
    for (const auto& name : builtinSceneNames()) {
        Scene s = Scene::builtin(name);
        const auto& d = s.data();
        EXPECT_EQ(s.name(), name);
        EXPECT_GT(d.lights.size(), 0u) << name;
        EXPECT_GT(d.triMaterial.size() + d.spheres.size(), 0u) << name;
        EXPECT_EQ(d.indices.size(), 3 * d.triMaterial.size());
        EXPECT_FLOAT_EQ(d.lightCdf.back(), 1.0f);
        EXPECT_EQ(d.meshNames.size() > 0, true);
    }
    EXPECT_EQ(Scene::builtin("cornell").data().lights.size(), 2u);  // the light quad's two triangles
    EXPECT_EQ(Scene::builtin("cornell-point").data().lights[0].type, pt::LightType::Point);
    EXPECT_EQ(Scene::builtin("sphere-env").data().env.type, pt::EnvType::Map);
    EXPECT_GE(Scene::builtin("cornell-spheres").materialId("mirror"), 0);
    EXPECT_GE(Scene::builtin("cornell-spheres").materialId("glass"), 0);
}

TEST(SceneBuiltin, UnknownNameIsNamed) {
    std::string msg = errorOf([] { Scene::builtin("kitchen"); });
    EXPECT_NE(msg.find("kitchen"), std::string::npos) << msg;
    EXPECT_NE(msg.find("cornell"), std::string::npos) << "lists the built-ins: " << msg;
    msg = errorOf([] { Scene::loadByNameOrFile("kitchen"); });
    EXPECT_NE(msg.find("kitchen"), std::string::npos);
}

TEST(SceneJson, ExampleSceneLoads) {
    Scene s = Scene::loadByNameOrFile(std::string(ATROUS_SOURCE_DIR) + "/scenes/example.json");
    const auto& d = s.data();
    EXPECT_EQ(s.name(), "example");
    EXPECT_EQ(d.spheres.size(), 4u);
    // floor quad (2) + tetrahedron (4) + lamp quad (2)
    EXPECT_EQ(d.triMaterial.size(), 8u);
    int tet = s.meshId("tetrahedron");
    ASSERT_GE(tet, 0);
    int orange = s.materialId("orange");  // from tetrahedron.mtl
    ASSERT_GE(orange, 0);
    EXPECT_NEAR(d.materials[orange].albedo.x, 0.8f, 1e-6f);
    // Lights: 2 lamp triangles, the point light, the environment.
    EXPECT_EQ(d.lights.size(), 4u);
    EXPECT_EQ(d.env.type, pt::EnvType::Constant);
    // The transform (scale 0.6, translate) put the tetrahedron's vertices at distance
    // 0.6 * sqrt(3) from (-1.9, 0.6, 0.6).
    for (size_t t = 0; t < d.triMaterial.size(); ++t) {
        if (d.triMesh[t] != tet) continue;
        EXPECT_EQ(d.triMaterial[t], orange);
        for (int k = 0; k < 3; ++k) {
            Vec3 p = d.positions[d.indices[3 * t + k]];
            EXPECT_NEAR(length(p - Vec3(-1.9f, 0.6f, 0.6f)), 0.6f * std::sqrt(3.0f), 1e-4f);
        }
    }
}

TEST(SceneJson, TextureAndMaterialOverride) {
    test::TempDir tmp;
    Image tex(4, 4, 3);
    tex.fill(0.25f);
    atrous::writeImage(tmp / "tex.exr", tex);
    writeText(tmp / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
    writeText(tmp / "s.json", R"({"camera": {"position": [0,0,3], "lookAt": [0,0,0]},
      "materials": {"t": {"type": "diffuse", "texture": "tex.exr"}},
      "objects": [{"type": "mesh", "file": "tri.obj", "material": "t"}],
      "lights": [{"type": "point", "position": [0,0,2], "intensity": 1}]})");
    Scene s = Scene::load(tmp / "s.json");
    ASSERT_EQ(s.data().textures.size(), 1u);
    EXPECT_EQ(s.data().triMaterial[0], s.materialId("t"));
    // An albedo texture is a reflectance: texels above 1 are clamped (an environment map is not).
    Image hot(2, 2, 3);
    hot.fill(50.0f);
    atrous::writeImage(tmp / "hot.exr", hot);
    writeText(tmp / "h.json", R"({"camera": {"position": [0,0,3], "lookAt": [0,0,0]},
      "materials": {"t": {"type": "diffuse", "texture": "hot.exr"}},
      "objects": [{"type": "mesh", "file": "tri.obj", "material": "t"}],
      "lights": [{"type": "environment", "file": "hot.exr"}]})");
    Scene h = Scene::load(tmp / "h.json");
    const auto& hd = h.data();
    const int albedoTex = hd.materials[h.materialId("t")].texture;
    ASSERT_GE(albedoTex, 0);
    EXPECT_EQ(hd.texels[size_t(hd.textures[albedoTex].offset)], 1.0f);
    ASSERT_GE(hd.env.texture, 0);
    EXPECT_EQ(hd.texels[size_t(hd.textures[hd.env.texture].offset)], 50.0f);
    EXPECT_EQ(s.data().materials[s.materialId("t")].texture, 0);
}

TEST(SceneJson, UnderscoreKeysAreComments) {
    test::TempDir tmp;
    writeText(tmp / "s.json", R"({"_comment": "a test scene", "camera": {"position": [0,0,3], "lookAt": [0,0,0], "_why": "x"},
      "materials": {"m": {"type": "diffuse", "_note": 1}},
      "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "material": "m", "_todo": []}],
      "lights": [{"type": "point", "position": [0,0,2], "intensity": 1, "_": 0}]})");
    EXPECT_NO_THROW(Scene::load(tmp / "s.json"));
}

TEST(SceneJson, MirroringTransformKeepsTheFaceFront) {
    // A negative scale mirrors the mesh and reverses its winding; the loader swaps two vertices so
    // the geometric normal (e1 x e2, the renderer's front side) still agrees with the file's
    // shading normal. Before, a mirrored glass cube refracted inside out and a one-sided emitter
    // went black.
    test::TempDir tmp;
    writeText(tmp / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n");
    for (const char* scale : {"[1, 1, 1]", "[-1, 1, 1]", "[-1, -2, 1]", "[-1, -1, -1]"}) {
        writeText(tmp / "s.json", std::string(R"({"camera": {"position": [0,0,3], "lookAt": [0,0,0]},
          "materials": {"m": {"type": "diffuse"}},
          "objects": [{"type": "mesh", "file": "tri.obj", "material": "m", "transform": {"scale": )") + scale + R"(}}],
          "lights": [{"type": "point", "position": [0,0,2], "intensity": 1}]})");
        Scene s = Scene::load(tmp / "s.json");
        const auto& d = s.data();
        ASSERT_EQ(d.indices.size(), 3u);
        const Vec3 a = d.positions[d.indices[0]], b = d.positions[d.indices[1]], c = d.positions[d.indices[2]];
        const Vec3 ng = cross(b - a, c - a);
        const Vec3 ns = d.normals[d.indices[0]];
        EXPECT_GT(dot(ng, ns), 0.0f) << "scale " << scale << ": geometric and shading normal disagree";
    }
}

TEST(SceneJson, MtlMaterialsTexturesAndSky) {
    test::TempDir tmp;
    Image tex(2, 2, 3);
    tex.fill(0.5f);
    atrous::writeImage(tmp / "kd.exr", tex);
    writeText(tmp / "m.mtl", "newmtl lamp\nKd 0 0 0\nKe 5 5 5\nnewmtl chrome\nKs 0.9 0.9 0.9\nillum 3\n"
                             "newmtl tex\nKd 1 1 1\nmap_Kd kd.exr\nnewmtl glass\nNi 1.33\nillum 7\n");
    writeText(tmp / "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                             "usemtl lamp\nf 1 2 3\nusemtl chrome\nf 2 4 3\nusemtl tex\nf 1 3 2\nusemtl glass\nf 3 4 2\n");
    writeText(tmp / "s.json", R"({"camera": {"position": [0,0,3], "lookAt": [0,0,0]},
      "objects": [{"type": "mesh", "file": "m.obj"}],
      "lights": [{"type": "sky", "sunDirection": [0, 1, 0.2], "sunRadius": 2}]})");
    Scene s = Scene::load(tmp / "s.json");
    const auto& d = s.data();
    auto mat = [&](const char* name) { return d.materials.at(s.materialId(name)); };
    EXPECT_EQ(mat("lamp").emission.x, 5.0f);
    EXPECT_EQ(mat("chrome").type, pt::MaterialType::Mirror);
    EXPECT_GE(mat("tex").texture, 0);
    EXPECT_EQ(mat("glass").type, pt::MaterialType::Dielectric);
    EXPECT_NEAR(mat("glass").ior, 1.33f, 1e-6f);
    EXPECT_EQ(d.triLight[0], 0);  // the emissive triangle is an area light
    EXPECT_EQ(d.env.type, pt::EnvType::Map);
    EXPECT_EQ(d.lights.size(), 2u);  // area light + sky

    // A texture named by the MTL that is missing is reported with its path.
    writeText(tmp / "m.mtl", "newmtl tex\nKd 1 1 1\nmap_Kd missing_kd.png\n");
    std::string msg = errorOf([&] { Scene::load(tmp / "s.json"); });
    EXPECT_NE(msg.find("missing_kd.png"), std::string::npos) << msg;
}

struct BadScene {
    const char* json;
    const char* expect;  // substring of the error message
};

TEST(SceneJson, BadFilesNameTheFileAndTheProblem) {
    test::TempDir tmp;
    writeText(tmp / "bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
    writeText(tmp / "empty.obj", "# nothing\nv 0 0 0\n");
    const BadScene cases[] = {
        {"{ not json", "malformed JSON"},
        {"[1, 2]", "JSON object"},
        {R"({"objects": []})", "camera"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}})", "objects"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0], "fov": "wide"}, "objects": []})", "fov"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "material": "nope"}]})", "unknown material \"nope\""},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "objects": [{"type": "cone"}]})", "unknown object type"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "materials": {"m": {"type": "velvet"}}, "objects": []})", "unknown material type"},
        // Unknown keys (typos) are named, with the keys that are allowed there.
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "materials": {"m": {"albdo": [1,0,0]}}, "objects": []})", "materials.m: unknown key \"albdo\""},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0], "fovy": 30}, "objects": []})", "camera: unknown key \"fovy\""},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "colour": 1}]})", "objects[0]: unknown key \"colour\""},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "objects": [], "light": []})", "unknown key \"light\""},
        // Reflectances above 1 would create energy.
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "materials": {"m": {"albedo": 5}}, "objects": []})", "\"albedo\" must be in [0, 1]"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "materials": {"m": {"checker": {"color1": 10}}}, "objects": []})", "\"color1\" must be in [0, 1]"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "materials": {"m": {}}, "objects": [{"type": "sphere", "center": [0,0,0], "radius": -1, "material": "m"}]})", "radius"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "objects": [{"type": "mesh", "file": "missing.obj"}]})", "missing.obj"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "objects": [{"type": "mesh", "file": "bad.obj"}]})", "bad.obj"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "objects": [{"type": "mesh", "file": "empty.obj"}]})", "no triangles"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "materials": {"m": {"texture": "nowhere.png"}}, "objects": []})", "nowhere.png"},
        {R"({"camera": {"position": [0,0,1], "lookAt": [0,0,0]}, "objects": [], "lights": [{"type": "environment", "file": "sky.exr"}]})", "sky.exr"},
    };
    int i = 0;
    for (const auto& c : cases) {
        std::string file = tmp / ("case" + std::to_string(i++) + ".json");
        writeText(file, c.json);
        std::string msg = errorOf([&] { Scene::load(file); });
        EXPECT_NE(msg.find(c.expect), std::string::npos) << c.json << "\n -> " << msg;
        // Errors about the scene itself name the scene file; errors about a referenced file name that file.
        bool namesScene = msg.find(file) != std::string::npos;
        bool namesReferenced = msg.find(".obj") != std::string::npos || msg.find(".png") != std::string::npos ||
                               msg.find(".exr") != std::string::npos;
        EXPECT_TRUE(namesScene || namesReferenced) << msg;
    }
    std::string msg = errorOf([&] { Scene::load(tmp / "does_not_exist.json"); });
    EXPECT_NE(msg.find("does_not_exist.json"), std::string::npos) << msg;
}

}  // namespace
}  // namespace atrous

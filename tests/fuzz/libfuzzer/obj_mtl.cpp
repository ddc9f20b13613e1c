// libFuzzer target: OBJ/MTL meshes through the scene loader's atrous::pt::loadObj (what a scene's
// {"type": "mesh", "file": ...} calls), then SceneBuilder::finalize. The input is the OBJ text,
// then "\n#--\n" and the MTL text (written as m.mtl: the OBJ names it with "mtllib m.mtl"), then
// "\n#--\n" and the bytes of a texture the MTL may name as t.png, t.exr or t.pfm (map_Kd). The
// transform is the identity, a mirror, or a scale and a turn, by the input's size.
//
// Contract (fuzz_common.h): loadObj returns or throws InputError, and the scene it built holds
// only values within their rules (checkScene: vertices within +-1e9, texcoords within +-1e6,
// MTL colours and emission in range, indices in range, a finite light CDF).
//
// Inputs whose MTL has a '/' or '\', or whose OBJ names an mtllib with one, are skipped: a path
// could then leave the scratch directory.
#include <sstream>

#include "fuzz_common.h"
#include "render/scene_builder.h"
#include "render/scene_obj.h"

using namespace atrous_fuzz;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    targetName() = "obj_mtl";
    return 0;
}

static bool leavesScratch(const std::string& obj, const std::string& mtl) {
    if (mtl.find_first_of("/\\") != std::string::npos) return true;
    std::istringstream lines(obj);
    std::string line;
    while (std::getline(lines, line)) {
        const size_t i = line.find_first_not_of(" \t");
        if (i != std::string::npos && line.compare(i, 6, "mtllib") == 0 && line.find_first_of("/\\", i) != std::string::npos)
            return true;
    }
    return false;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::vector<std::string> parts = splitSections(data, size, "\n#--\n", 3);
    if (leavesScratch(parts[0], parts[1])) return 0;
    const std::string obj = writeScratch("m.obj", parts[0]);
    writeScratch("m.mtl", parts[1]);
    for (const char* name : {"t.png", "t.exr", "t.pfm"}) writeScratch(name, parts[2]);
    atrous::pt::Transform xf;
    if (size % 3 == 1) xf.scale = atrous::Vec3(-1.0f, 1.0f, 1.0f);
    if (size % 3 == 2) {
        xf.scale = atrous::Vec3(1000.0f);
        xf.rotY = 0.5f;
        xf.translate = atrous::Vec3(1.0f, 2.0f, 3.0f);
    }
    atrous::pt::SceneBuilder b("fuzz");
    const int mesh = b.addMesh("mesh");
    if (!returnsOrInputError("loadObj", [&] { atrous::pt::loadObj("fuzz.json", b, obj, -1, mesh, xf); })) return 0;
    std::shared_ptr<atrous::pt::SceneData> d;
    if (!returnsOrInputError("SceneBuilder::finalize", [&] { d = b.finalize(); })) return 0;
    checkScene(*d, "loadObj");
    return 0;
}

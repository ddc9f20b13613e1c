// libFuzzer target: scene JSON through atrous::Scene::parse (parse only, nothing is rendered).
// The input is the JSON text, optionally followed by "\n#--\n" and the bytes of an image that the
// scene may name as "aux.exr", "aux.png", "aux.pfm" or "aux.hdr" (a texture or an environment map).
// The scene's directory (the target's scratch directory) also holds valid files to refer to:
// mesh.obj (a textured quad with mesh.mtl, tex.png), env.exr, tex.png.
//
// Contract (fuzz_common.h): parse returns a Scene or throws InputError, and every value of the
// scene it returns is within its rule (src/render/scene_limits.h: checkScene), with its light CDF
// and environment distribution finite.
//
// Inputs with '/' or '\' in the JSON are skipped: a path could then leave the scratch directory
// (and a '\' escape could spell a '/').
#include "atrous/render.h"
#include "fuzz_common.h"
#include "atrous/io/image_io.h"

using namespace atrous_fuzz;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    targetName() = "scene_json";
    Image tex(4, 4, 3), env(8, 4, 3);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x)
            for (int c = 0; c < 3; ++c) {
                if (x < 4) tex(x, y, c) = float((x + y + c) % 2);
                env(x, y, c) = 0.5f + float(y * 8 + x + c);
            }
    atrous::io::writePng(scratchDir() + "/tex.png", tex);
    atrous::io::writeExr(scratchDir() + "/env.exr", env);
    writeScratch("mesh.mtl", "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd tex.png\nnewmtl e\nKe 4 4 4\n");
    writeScratch("mesh.obj",
                 "mtllib mesh.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
                 "usemtl m\nf 1/1/1 2/2/1 3/3/1\nusemtl e\nf 1/1/1 3/3/1 4/4/1\n");
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::vector<std::string> parts = splitSections(data, size, "\n#--\n", 2);
    const std::string& json = parts[0];
    if (json.find_first_of("/\\") != std::string::npos) return 0;
    for (const char* name : {"aux.exr", "aux.png", "aux.pfm", "aux.hdr"}) writeScratch(name, parts[1]);
    atrous::Scene scene;
    if (!returnsOrInputError("Scene::parse", [&] { scene = atrous::Scene::parse(json, scratchDir(), "fuzz.json"); }))
        return 0;
    checkScene(scene.data(), "Scene::parse");
    return 0;
}

// Scenes (atrous/render.h): the public Scene API. The parts live beside it: scene_builder.{h,cpp}
// (SceneBuilder and the finalisation every scene goes through: light list and its power
// distribution, the environment map's 2D sampling distribution), scene_sky.{h,cpp} (the procedural
// sky), scene_builtin.cpp (the built-in scenes), scene_json.cpp (JSON scene files, docs/scenes.md)
// and scene_obj.{h,cpp} (their OBJ/MTL meshes).
#include <filesystem>
#include <string>
#include <system_error>

#include "atrous/render.h"
#include "render/scene_data.h"

namespace atrous {

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

// OBJ/MTL meshes of a scene file ("type": "mesh", docs/scenes.md), read with tinyobjloader after
// a prescan of what it does not check.
#pragma once
#include <cmath>
#include <string>

#include "atrous/math.h"
#include "render/scene_builder.h"

namespace atrous::pt {

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

// Appends the triangles of the OBJ file `path` (transformed by `xf`) to mesh `mesh` of `b`, with
// `overrideMaterial` when >= 0 and the file's MTL materials otherwise. `referencedBy` (the scene
// file) appears in the message when the file cannot be opened. InputError names the file at fault.
void loadObj(const std::string& referencedBy, SceneBuilder& b, const std::string& path, int overrideMaterial,
             int mesh, const Transform& xf);

}  // namespace atrous::pt

// OBJ/MTL meshes (scene_obj.h): the prescans of the OBJ and MTL text, the MTL materials mapped to
// ours, the triangles appended to the scene.
#include "render/scene_obj.h"

#include <tiny_obj_loader.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "atrous/error.h"
#include "atrous/io/image_io.h"
#include "render/scene_limits.h"

namespace atrous::pt {
namespace {

namespace fs = std::filesystem;

// tinyobjloader reads a number's exponent into an int, checking for overflow only before each
// digit's multiply: "1e-2147483648" overflows it (undefined behaviour, found by the libFuzzer
// target obj_mtl, tests/fuzz/libfuzzer). Where it wraps (Debian's build), numbers that strtod and
// the checks below read as 0 come out as other values: "2e-21474836480" as 2, "3e-2147483649" as
// inf. True when `tok` starts with a number whose exponent has 10 or more significant digits; the
// prescans refuse such a token in any statement (v/vt/vn, t tags, MTL values and texture options).
bool exponentOutOfRange(const std::string& tok) {
    size_t i = 0;
    if (i < tok.size() && (tok[i] == '+' || tok[i] == '-')) ++i;
    while (i < tok.size() && std::isdigit(static_cast<unsigned char>(tok[i]))) ++i;
    if (i < tok.size() && tok[i] == '.') ++i;
    while (i < tok.size() && std::isdigit(static_cast<unsigned char>(tok[i]))) ++i;
    if (i >= tok.size() || (tok[i] != 'e' && tok[i] != 'E')) return false;
    ++i;
    if (i < tok.size() && (tok[i] == '+' || tok[i] == '-')) ++i;
    while (i < tok.size() && tok[i] == '0') ++i;
    size_t digits = 0;
    while (i < tok.size() && std::isdigit(static_cast<unsigned char>(tok[i]))) ++i, ++digits;
    return digits >= 10;
}

// One line of an OBJ or MTL file as tinyobjloader splits them: at "\n", "\r" or "\r\n" (a "\r"
// alone ends a line there; std::getline did not end it, so "#...\rvw 1 3e9" hid a statement from
// the prescans as a comment's tail: found by the libFuzzer target obj_mtl). False at the end.
bool objLine(std::istream& in, std::string& line) {
    line.clear();
    std::streambuf* sb = in.rdbuf();
    for (bool any = false;; any = true) {
        const int c = sb->sbumpc();
        if (c == '\n') return true;
        if (c == '\r') {
            if (sb->sgetc() == '\n') sb->sbumpc();
            return true;
        }
        if (c == EOF) return any;
        line += char(c);
    }
}

// Throws for a token of `line` with an exponent out of range (exponentOutOfRange); comment lines
// (a first token starting with '#', which tinyobjloader skips) are not looked at.
void requireExponentsInRange(const std::string& line, const std::string& file, size_t lineNo) {
    std::istringstream words(line);
    std::string tok;
    for (bool first = true; words >> tok; first = false) {
        if (first && tok[0] == '#') return;
        if (exponentOutOfRange(tok))
            throw InputError(file + ": line " + std::to_string(lineNo) + ": \"" + tok + "\" has an exponent out of range");
    }
}

// "FILE: line N: ", what every prescan message starts with.
std::string atLine(const std::string& file, size_t lineNo) { return file + ": line " + std::to_string(lineNo) + ": "; }

// v, vt, vn: every value a finite number (tinyobjloader reads "nan" or "x" as 0 and 1e39 as Inf).
void requireFiniteValues(const std::string& values, const std::string& path, size_t lineNo) {
    std::istringstream vals(values);
    std::string tok;
    while (vals >> tok) {
        char* end = nullptr;
        const double x = std::strtod(tok.c_str(), &end);
        if (end == tok.c_str() || *end != '\0' || !std::isfinite(x) || std::fabs(x) > 3.0e38)
            throw InputError(atLine(path, lineNo) + "\"" + tok + "\" is not a finite number");
    }
}

// vw: skin weights, a tinyobjloader extension atrous ignores ("vw vid joint weight joint weight
// ..."); tinyobjloader casts each joint id from a float to int, undefined beyond int's range and for
// NaN, which its own number parser makes of "7...7e-2000" (inf * 0) where strtod reads 0 (found by
// the libFuzzer target obj_mtl: "vw 1 777...7"). Each joint id is an integer of at most 9 digits (a
// fraction allowed): what a joint index looks like.
void requireJointIds(const std::string& values, const std::string& path, size_t lineNo) {
    std::istringstream vals(values);
    std::string tok;
    for (int k = 0; vals >> tok; ++k) {
        if (k % 2 == 0) continue;  // the vertex id (read with atoi) and the weights
        size_t p = tok[0] == '+' || tok[0] == '-' ? 1 : 0;
        const size_t digits = tok.find_first_not_of("0123456789", p);
        const size_t intDigits = (digits == std::string::npos ? tok.size() : digits) - p;
        const bool fraction = digits != std::string::npos && tok[digits] == '.' &&
                              tok.find_first_not_of("0123456789", digits + 1) == std::string::npos;
        if (intDigits == 0 || intDigits > 9 || (digits != std::string::npos && !fraction))
            throw InputError(atLine(path, lineNo) + "skin weight joint id \"" + tok +
                             "\" is not an integer of at most 9 digits");
    }
}

const char* objElementName(int part) { return part == 0 ? "vertex" : part == 1 ? "texture coordinate" : "normal"; }

// The face indices of an OBJ file against its v, vt and vn statements (0: v, 1: vt, 2: vn): a
// relative (negative) index must stay within the elements read so far, an absolute one within the
// file's totals (checked at the end, against the largest seen).
class ObjIndexCheck {
public:
    explicit ObjIndexCheck(const std::string& path) : mPath(path) {}

    void countElement(int part) { ++mCounts[part]; }

    // A face statement ("f" at column i): each corner's indices in int's range and referring to an
    // element, at most kMaxFaceVertices corners.
    void checkFace(const std::string& line, size_t i, size_t lineNo) {
        size_t count = 0;
        for (size_t k = i + 1; k < line.size();) {
            while (k < line.size() && (line[k] == ' ' || line[k] == '\t' || line[k] == '\r')) ++k;
            if (k >= line.size()) break;
            const size_t tokenStart = k;
            while (k < line.size() && line[k] != ' ' && line[k] != '\t' && line[k] != '\r') ++k;
            ++count;
            checkCorner(line.substr(tokenStart, k - tokenStart), lineNo);
            if (count > size_t(kMaxFaceVertices))
                throw InputError(atLine(mPath, lineNo) + "face with more than " + std::to_string(kMaxFaceVertices) +
                                 " vertices");
        }
    }

    // After the last line: every absolute index within the file's totals.
    void requireTotals() const {
        for (int k = 0; k < 3; ++k)
            if (mMaxIndex[k] > mCounts[k])
                throw InputError(atLine(mPath, mMaxLine[k]) + "face index \"" + mMaxToken[k] + "\" refers to a missing " +
                                 objElementName(k) + " (the file has " + std::to_string(mCounts[k]) + ")");
    }

private:
    // One corner, "v/vt/vn": each an optional sign and digits; more than 10 digits or above INT_MAX
    // is out of range.
    void checkCorner(const std::string& token, size_t lineNo) {
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
                throw InputError(atLine(mPath, lineNo) + "face index \"" + token + "\" is out of range");
            const long long value = sig.empty() ? 0 : std::stoll(sig);
            const bool negative = q > p && token[p] == '-';
            if (part < 3 && !d.empty() && (value == 0 || (negative && value > mCounts[part])))
                throw InputError(atLine(mPath, lineNo) + "face index \"" + token + "\" refers to a missing " +
                                 objElementName(part));
            if (part < 3 && !negative && value > mMaxIndex[part]) {
                mMaxIndex[part] = value;
                mMaxLine[part] = lineNo;
                mMaxToken[part] = token;
            }
            ++part;
            p = q + 1;
        }
    }

    const std::string& mPath;
    long long mCounts[3] = {0, 0, 0};    // v, vt, vn so far
    long long mMaxIndex[3] = {0, 0, 0};  // the largest absolute index
    size_t mMaxLine[3] = {0, 0, 0};
    std::string mMaxToken[3];
};

// Whether `line` has the statement `key` at column i, followed by a space or (when `tab`) a tab.
bool isStatement(const std::string& line, size_t i, const std::string& key, bool tab = true) {
    return line.compare(i, key.size() + 1, key + " ") == 0 || (tab && line.compare(i, key.size() + 1, key + "\t") == 0);
}

// What tinyobjloader does not check, read from the OBJ text before it parses it: a face index
// beyond int's range (atoi wraps 99999999999999999999 to -1, the last vertex), a face with more
// than kMaxFaceVertices vertices (its ear clipping is quadratic: a 200k-vertex face ran for
// minutes), and the mtllib names (tinyobjloader only warns when one is missing).
std::vector<std::string> prescanObj(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<std::string> mtllibs;
    ObjIndexCheck indices(path);
    std::string line;
    for (size_t lineNo = 1; objLine(in, line); ++lineNo) {
        const size_t i = line.find_first_not_of(" \t");
        if (i == std::string::npos) continue;
        requireExponentsInRange(line, path, lineNo);
        // v, vt, vn: a space after the keyword, as tinyobjloader reads them.
        const int part = isStatement(line, i, "v", false) ? 0 : isStatement(line, i, "vt", false) ? 1
                         : isStatement(line, i, "vn", false) ? 2 : -1;
        if (part >= 0) {
            indices.countElement(part);
            requireFiniteValues(line.substr(i + (part == 0 ? 2 : 3)), path, lineNo);
        } else if (isStatement(line, i, "vw")) {
            requireJointIds(line.substr(i + 3), path, lineNo);
        } else if (isStatement(line, i, "mtllib")) {
            std::istringstream names(line.substr(i + 7));
            std::string n;
            while (names >> n) mtllibs.push_back(n);
        } else if (isStatement(line, i, "f")) {
            indices.checkFace(line, i, lineNo);
        }
    }
    indices.requireTotals();
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
    while (objLine(in, line)) {
        ++lineNo;
        requireExponentsInRange(line, mtl, lineNo);
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

}  // namespace

void loadObj(const std::string& referencedBy, SceneBuilder& b, const std::string& path, int overrideMaterial,
             int mesh, const Transform& xf) {
    tinyobj::ObjReaderConfig cfg;
    cfg.triangulate = true;
    cfg.vertex_color = false;
    cfg.mtl_search_path = fs::path(path).parent_path().string();
    tinyobj::ObjReader reader;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw InputError(path + ": cannot open OBJ file (referenced by " + referencedBy + ")");
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
                m.texture = b.addTexture(atrous::readImage(tex), /*reflectance=*/true);
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

}  // namespace atrous::pt

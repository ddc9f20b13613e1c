// Findings of the libFuzzer targets (tests/fuzz/libfuzzer/, docs/reliability.md) in the files they
// found them in, one test each; each fails without its fix. The inputs that found them stay in the
// targets' seed corpora (tests/fuzz/libfuzzer/make_corpus.cpp writes them).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "atrous/error.h"
#include "atrous/render.h"

namespace {

namespace fs = std::filesystem;

struct ScratchDir {
    fs::path path;
    ScratchDir() {
        std::random_device rd;
        do path = fs::temp_directory_path() / ("atrous_fuzzreg_" + std::to_string(getpid()) + "_" + std::to_string(rd()));
        while (!fs::create_directories(path));
    }
    ~ScratchDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
    void write(const std::string& name, const std::string& text) const { std::ofstream(path / name, std::ios::binary) << text; }
};

// The InputError message of parsing a scene with one mesh m.obj (and m.mtl when given); "" when
// the scene loads.
std::string meshError(const ScratchDir& dir, const std::string& obj, const std::string& mtl) {
    dir.write("m.obj", obj);
    if (!mtl.empty()) dir.write("m.mtl", mtl);
    try {
        atrous::Scene::parse(R"({"camera": {"position": [0.5, 0.5, 3], "lookAt": [0.5, 0.5, 0]},
                                 "objects": [{"type": "mesh", "file": "m.obj"}]})",
                             dir.path.string(), "s.json");
    } catch (const atrous::InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

// obj_mtl: tinyobjloader reads a number's exponent into an int and overflows it at
// "1e-2147483648" (undefined behaviour, UBSan: "signed integer overflow: 2147483640 + 8"; with
// Debian's build "2e-21474836480" became 2 and "3e-2147483649" inf); strtod reads these as 0, so
// the prescan's finite-number check let them through, and tags (t) and texture options were not
// prescanned at all. An exponent of 10 or more significant digits is now refused in every
// statement of the OBJ and the MTL. Without the fix every case below loads without an error.
TEST(FuzzRegression, ObjAndMtlExponentsBeyondIntAreErrors) {
    ScratchDir dir;
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n";
    const std::string useMtl = "mtllib m.mtl\nusemtl a\n";
    struct Case {
        std::string obj, mtl, needle;
    };
    const std::vector<Case> cases = {
        {"v 0 0 0\nv 1e-2147483648 0 0\nv 1 1 0\nf 1 2 3\n", "", "m.obj: line 2: \"1e-2147483648\" has an exponent out of range"},
        {"v 0 0 0\nv 2e-21474836480 0 0\nv 1 1 0\nf 1 2 3\n", "", "m.obj: line 2: \"2e-21474836480\" has an exponent out of range"},
        {"t crease 0/1/0 1e-2147483649\n" + tri, "", "m.obj: line 1: \"1e-2147483649\" has an exponent out of range"},
        {"vt 0.5 -2.5E+000002147483648\n" + tri, "", "m.obj: line 1: \"-2.5E+000002147483648\" has an exponent out of range"},
        {useMtl + tri, "newmtl a\nKd 1e-21474836480 0.5 0.5\n", "m.mtl: line 2: \"1e-21474836480\" has an exponent out of range"},
        {useMtl + tri, "newmtl a\nmap_Kd -s 1e-2147483648 1 1 t.png\n", "m.mtl: line 2: \"1e-2147483648\" has an exponent out of range"},
    };
    for (const Case& c : cases) {
        const std::string msg = meshError(dir, c.obj, c.mtl);
        EXPECT_NE(msg.find(c.needle), std::string::npos) << c.needle << "\n" << msg;
    }
    // Ordinary exponents (leading zeros included), comments and skin weights still load.
    EXPECT_EQ(meshError(dir, "# 1e-2147483648 in a comment\nv 0 0 1e-5\nv 1.5E+0 0 0\nv 1 1e-000000000001 0\nf 1 2 3\n", ""), "");
    EXPECT_EQ(meshError(dir, useMtl + tri, "newmtl a\nKd 5e-1 0.5 0.5\n"), "");
}

// obj_mtl: tinyobjloader's skin weights ("vw vid joint weight ...", its own extension, ignored by
// atrous) cast each joint id from a float to int: undefined for 7.7e85, 3e9, or the NaN its parser
// makes of 7...7e-2000 (UBSan: "inf/-nan is outside the range of representable values of type
// 'int'"). A joint id is now an integer of at most 9 digits; without the fix every case loads.
TEST(FuzzRegression, ObjSkinWeightJointIdsBeyondIntAreErrors) {
    ScratchDir dir;
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n";
    for (const std::string& id : {std::string(90, '7'), std::string("3e9"), std::string(400, '7') + "e-2000", std::string("1234567890")}) {
        const std::string msg = meshError(dir, tri + "vw 1 0 0.5 " + id + " 0.5\n", "");
        EXPECT_NE(msg.find("m.obj: line 5: skin weight joint id \"" + id + "\" is not an integer of at most 9 digits"),
                  std::string::npos) << msg;
    }
    EXPECT_EQ(meshError(dir, tri + "vw 1 0 0.25 2 0.75 3.0 0\n", ""), "");
}

// obj_mtl: tinyobjloader ends a line at a lone "\r" as at "\n"; the prescans read lines with
// std::getline, so a statement after a "\r" was the tail of the line before (of a comment, not
// looked at, or of another statement, not recognised): "#\rvw 1 02147483648 1" reached
// tinyobjloader's float-to-int cast (UBSan: "2.14748e+09 is outside the range of representable
// values of type 'int'"), and a face past the last vertex or a bad value could hide the same way.
// The prescans now split lines as tinyobjloader does. Without the fix every case loads.
TEST(FuzzRegression, ObjStatementsAfterALoneCarriageReturnArePrescanned) {
    ScratchDir dir;
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n";
    struct Case {
        std::string obj, mtl, needle;
    };
    const std::vector<Case> cases = {
        {tri + "# skin\rvw 1 02147483648 1\n", "", "m.obj: line 6: skin weight joint id \"02147483648\""},
        {tri + "g a\rvw 1 3e9 1\n", "", "m.obj: line 6: skin weight joint id \"3e9\""},
        {tri + "# comment\rv 1 nan 0\n", "", "m.obj: line 6: \"nan\" is not a finite number"},
        {"mtllib m.mtl\rusemtl a\n" + tri, "newmtl a\r\nKd 0.5 0.5 0.5\r# c\rKe 1 x 1\n", "m.mtl: line 4: Ke value \"x\" is not a finite number"},
    };
    for (const Case& c : cases) {
        const std::string msg = meshError(dir, c.obj, c.mtl);
        EXPECT_NE(msg.find(c.needle), std::string::npos) << c.needle << "\n" << msg;
    }
    // "\r\n" and "\r" line ends alike still load.
    EXPECT_EQ(meshError(dir, "v 0 0 0\r\nv 1 0 0\rv 1 1 0\r\nf 1 2 3\r", ""), "");
}

// Bad values in mesh files (issue: robustness; docs/robustness.md, "Input validation"): every
// number the loaders take is finite and in range, else an InputError naming the file, the line
// and the material where there is one. assimp accepts all of these cases without a word.
#include <gtest/gtest.h>

#include <cstring>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "rtpg/errors.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"
#include "support/scene_files.h"

namespace rtpg {
namespace {

using test::expect_input_error;
using test::TempDir;
using test::write_file;

const char* kQuadVertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";
const char* kQuadFaces = "f 1 2 3\nf 2 4 3\n";
const char* kGoodMtl = "newmtl grey\nKd 0.5 0.5 0.5\nKs 0 0 0\n";

// A scene of one mesh file `mesh` (written next to it) lit by a sun.
std::string write_scene(const TempDir& dir, const std::string& mesh) {
  const std::string path = dir / "scene.json";
  write_file(path, R"({"camera": {"position": [0.5, 0.5, 3], "look_at": [0.5, 0.5, 0], "fov": 40},
    "sun": {"direction": [0, 0, 1], "irradiance": [1, 1, 1]},
    "meshes": [{"file": ")" +
                       mesh + R"("}]})");
  return path;
}

// An OBJ of the unit quad with `vertex_lines` (one statement or more) in place of its first
// vertex and the MTL `mtl`; expects the scene to be refused naming `parts`.
void expect_obj_refused(const std::string& vertex_lines, const std::string& mtl,
                        std::initializer_list<std::string> parts) {
  TempDir dir;
  write_file(dir / "m.obj", "mtllib m.mtl\n" + vertex_lines + "v 1 0 0\nv 0 1 0\nv 1 1 0\n" +
                                "usemtl grey\n" + kQuadFaces);
  write_file(dir / "m.mtl", mtl);
  const std::string scene = write_scene(dir, "m.obj");
  expect_input_error([&] { load_scene(scene); }, parts);
}

TEST(InputValidation, TheGoodQuadLoads) {
  TempDir dir;
  write_file(dir / "m.obj",
             std::string("mtllib m.mtl\n") + kQuadVertices + "usemtl grey\n" + kQuadFaces);
  write_file(dir / "m.mtl", kGoodMtl);
  const Scene scene = load_scene(write_scene(dir, "m.obj"));
  EXPECT_EQ(scene.triangle_count(), 2u);
  EXPECT_EQ(scene.degenerate_triangles, 0u);
  EXPECT_TRUE(scene.warnings.empty());
}

TEST(InputValidation, NonFiniteAndOverflowingVertexCoordinates) {
  for (const char* bad : {"nan", "inf", "-inf", "1e39", "-1e39", "NaN", "infinity", "1e400"}) {
    SCOPED_TRACE(bad);
    expect_obj_refused(std::string("v 0 ") + bad + " 0\n", kGoodMtl,
                       {"m.obj", "line 2", "v: '", bad});
  }
}

TEST(InputValidation, NonFiniteNormalsAndTextureCoordinates) {
  expect_obj_refused("v 0 0 0\nvn 0 nan 1\n", kGoodMtl, {"m.obj", "line 3", "vn", "nan"});
  expect_obj_refused("v 0 0 0\nvt inf 0\n", kGoodMtl, {"m.obj", "line 3", "vt", "inf"});
}

TEST(InputValidation, WrongNumberCountsAndWords) {
  expect_obj_refused("v 0 0\n", kGoodMtl, {"m.obj", "line 2", "v: 2 numbers"});
  expect_obj_refused("vn 0 0 1 1\nv 0 0 0\n", kGoodMtl, {"line 2", "vn: 4 numbers"});
  expect_obj_refused("v 0 zero 0\n", kGoodMtl, {"line 2", "'zero' is not a number"});
}

// assimp reads such a coordinate as 0; the check refuses it at once, by its length.
TEST(InputValidation, TenMillionDigitCoordinateOnTheFirstLine) {
  TempDir dir;
  std::string obj = "v " + std::string(10'000'000, '7') + " 0 0\n";
  obj += std::string(kQuadVertices) + "f 2 3 4\nf 3 5 4\n";
  write_file(dir / "long.obj", obj);
  const std::string scene = write_scene(dir, "long.obj");
  expect_input_error([&] { load_scene(scene); },
                     {"long.obj", "line 1", "a number of 10000000 characters"});
}

TEST(InputValidation, BadMtlValuesNameTheMaterialAndLine) {
  const std::string head = "newmtl grey\nKd 0.5 0.5 0.5\n";
  const struct {
    const char* statement;
    const char* expected;
  } cases[] = {
      {"Kd nan 0.5 0.5", "Kd: 'nan' is not a finite number"},
      {"Ke inf 1 1", "Ke: 'inf' is not a finite number"},
      {"Ns -1", "Ns: -1 must not be negative"},
      {"Pr nan", "Pr: 'nan' is not a finite number"},
      {"Pm inf", "Pm: 'inf' is not a finite number"},
      {"Kd 1.5 0.5 0.5", "Kd: 1.5 must lie in [0, 1]"},
      {"Ke -1 0 0", "Ke: -1 must not be negative"},
      {"Ni 0", "Ni: 0 must be above 0"},
      {"d 2", "d: 2 must lie in [0, 1]"},
      {"Ks 1e39 0 0", "Ks: '1e39' is outside the float range"},
      {"map_bump -bm nan bump.png", "map_bump -bm: 'nan' is not a finite number"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.statement);
    expect_obj_refused("v 0 0 0\n", head + c.statement + "\n",
                       {"m.mtl", "line 3", "material 'grey'", c.expected, "mtllib of"});
  }
}

// assimp 5.2.5 crashes (a write through a null material) on a texture statement before the
// first newmtl; found by fuzzing. The check refuses every statement there.
TEST(InputValidation, MtlStatementBeforeTheFirstNewmtl) {
  for (const char* mtl : {"map_Kd t.png\nnewmtl grey\n", "map_d9\n\n", "Kd 1 1 1\n"}) {
    SCOPED_TRACE(mtl);
    expect_obj_refused("v 0 0 0\n", mtl, {"m.mtl", "line 1", "before the first newmtl"});
  }
}

// OBJ and MTL are text: a NUL byte, even in a comment, makes assimp 5.2.5 read past the end of
// an MTL (a crash, found by fuzzing); every control byte but tab and CR is refused.
TEST(InputValidation, ControlBytesInObjAndMtl) {
  expect_obj_refused(std::string("v 0 0 0\n# a\0b\n", 14), "newmtl grey\nKd 0.5 0.5 0.5\n",
                     {"m.obj", "line 3", "a control byte (0x00)"});
  expect_obj_refused("v 0 0 0\n", "newmtl grey\nKd 0.5 0.5 0.5\x01\n",
                     {"m.mtl", "line 2", "a control byte (0x01)"});
}

// A PLY list whose length is typed double could claim more items than any integer holds
// (undefined behaviour in the check itself, found by fuzzing).
TEST(InputValidation, PlyListLengthOfAFloatType) {
  TempDir dir;
  write_file(dir / "d.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
             "property float z\nelement face 1\nproperty list double int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const std::string scene = write_scene(dir, "d.ply");
  expect_input_error([&] { load_scene(scene); }, {"d.ply", "has a length of type double"});
}

// A PLY header has exactly one format line, of version 1.0; with two, assimp 5.2.5 reads the
// body in one format and asserts while triangulating it (found by fuzzing).
TEST(InputValidation, PlyFormatLineOnceAndVersionOne) {
  TempDir dir;
  const std::string body =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  write_file(dir / "two.ply", "ply\nformat ascii 1.0\nformat binary_little_endian 1.0\n" + body);
  expect_input_error([&] { load_scene(write_scene(dir, "two.ply")); },
                     {"two.ply", "a second format line"});
  write_file(dir / "v2.ply", "ply\nformat ascii 2.0\n" + body);
  expect_input_error([&] { load_scene(write_scene(dir, "v2.ply")); },
                     {"v2.ply", "format version '2.0'"});
  write_file(dir / "good.ply", "ply\nformat ascii 1.0\n" + body);
  EXPECT_NO_THROW(load_scene(write_scene(dir, "good.ply")));
}

// An ASCII PLY body is text: assimp 5.2.5 stops reading a line at a NUL byte, shifts the rest
// of the element into the next and asserts while triangulating (found by fuzzing).
TEST(InputValidation, PlyAsciiBodyWithANulByte) {
  TempDir dir;
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0";
  ply += std::string("\0\x01 1\n3 0 1 2\n", 13);
  write_file(dir / "nul.ply", ply);
  expect_input_error([&] { load_scene(write_scene(dir, "nul.ply")); },
                     {"nul.ply", "a control or non-ASCII byte in element 'vertex' 2"});
}

// The canonical PLY layout only: assimp 5.2.5 matches element names without regard to case,
// reads repeated elements and writes out of bounds on such headers (found by fuzzing).
TEST(InputValidation, PlyElementsVertexThenFaceOnce) {
  const std::string vertex =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\n";
  const std::string body = "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string head = "ply\nformat ascii 1.0\n";
  const struct {
    std::string header, message;
  } cases[] = {
      {vertex + "element Face 1\nproperty list uchar int vertex_indices\n", "element 'Face'"},
      {vertex + face + "element edge 0\nproperty int vertex1\n", "element 'edge'"},
      {vertex + face + "element face 0\nproperty list uchar int vertex_indices\n",
       "a second element 'face'"},
      {face + vertex, "element 'vertex' after 'face'"},
      {"element vertex 3 extra\nproperty float x\nproperty float y\nproperty float z\n" + face,
       "bad element line"},
      {"element vertex 3\nproperty float x 1.0\nproperty float y\nproperty float z\n" + face,
       "property 'x' has extra words ('1.0')"},
      {"element vertex 3\nproperty float x\nproperty float x\nproperty float z\n" + face,
       "a second property 'x'"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.header);
    TempDir dir;
    write_file(dir / "e.ply", head + c.header + body);
    expect_input_error([&] { load_scene(write_scene(dir, "e.ply")); }, {"e.ply", c.message});
  }
}

TEST(InputValidation, TrailingCommentsAndOtherForms) {
  TempDir dir;
  write_file(dir / "m.obj", std::string("mtllib m.mtl\n") + "v 0 0 0 # origin\n" +
                                "v +1 0 0\nv 0 1 0 1\nv 1 1 0 0.5 0.5 0.5\n" + "usemtl grey\n" +
                                kQuadFaces);
  write_file(dir / "m.mtl", "newmtl grey\nKa 0.6 0.1 0.1 # red\nKd 0.5 0.5 0.5\nd 1\n");
  EXPECT_NO_THROW(load_scene(write_scene(dir, "m.obj")));
}

TEST(InputValidation, AllDegenerateMeshIsAnError) {
  TempDir dir;
  // Two triangles with a repeated vertex and one of three collinear vertices.
  write_file(dir / "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\nf 2 3 3\n");
  const std::string scene = write_scene(dir, "flat.obj");
  expect_input_error([&] { load_scene(scene); }, {"flat.obj", "triangles have zero area"});
}

TEST(InputValidation, DegenerateTrianglesAmongGoodOnesAreDroppedCountedAndReported) {
  TempDir dir;
  write_file(dir / "some.obj",
             std::string(kQuadVertices) + "v 2 0 0\n" + kQuadFaces + "f 1 2 5\nf 3 3 4\n");
  const Scene scene = load_scene(write_scene(dir, "some.obj"));
  EXPECT_EQ(scene.triangle_count(), 2u);
  EXPECT_EQ(scene.degenerate_triangles, 2u);
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_NE(scene.warnings[0].find("some.obj: dropped 2 triangles of zero area"), std::string::npos)
      << scene.warnings[0];
}

// assimp reads a binary PLY's NaN and then merges that vertex into another one (vertex
// joining), so the PLY check reads the values itself.
TEST(InputValidation, NanInABinaryPlyIsAnError) {
  TempDir dir;
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float vertices[9] = {0, 0, 0, 1, nan, 0, 0, 1, 0};
  ply.append(reinterpret_cast<const char*>(vertices), sizeof(vertices));
  ply.push_back(3);
  const int indices[3] = {0, 1, 2};
  ply.append(reinterpret_cast<const char*>(indices), sizeof(indices));
  write_file(dir / "nan.ply", ply);
  const std::string scene = write_scene(dir, "nan.ply");
  expect_input_error([&] { load_scene(scene); },
                     {"nan.ply", "element 'vertex' 1, property 'y'", "is not a finite float"});
}

TEST(InputValidation, TransformThatOverflowsTheCoordinates) {
  TempDir dir;
  write_file(dir / "m.obj", std::string("v 1e30 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n"));
  const std::string path = dir / "scene.json";
  write_file(path, R"({"camera": {"position": [0.5, 0.5, 3], "look_at": [0.5, 0.5, 0], "fov": 40},
    "sun": {"direction": [0, 0, 1], "irradiance": [1, 1, 1]},
    "meshes": [{"file": "m.obj", "transform": {"scale": [1e10, 1, 1]}}]})");
  expect_input_error([&] { load_scene(path); },
                     {"scene.json", "meshes[0].transform", "outside the float range"});
}

}  // namespace
}  // namespace rtpg

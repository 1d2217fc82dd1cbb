// Tessellation of the analytic shapes.
#include "scene/shapes.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <utility>

namespace rtpg {

namespace {

void append_quad(Mesh& mesh, const glm::vec3& corner, const glm::vec3& edge1,
                 const glm::vec3& edge2) {
  const glm::vec3 n = glm::normalize(glm::cross(edge1, edge2));
  // u runs along edge1 and v along edge2, and cross(edge1, edge2) = n, so the bitangent
  // cross(n, tangent) points along edge2: handedness +1.
  const glm::vec4 tangent(glm::normalize(edge1), 1.0f);
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  const std::array<glm::vec3, 4> p = {corner, corner + edge1, corner + edge1 + edge2,
                                      corner + edge2};
  const std::array<glm::vec2, 4> uv = {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1),
                                       glm::vec2(0, 1)};
  for (int i = 0; i < 4; ++i) {
    mesh.positions.push_back(p[i]);
    mesh.normals.push_back(n);
    mesh.uvs.push_back(uv[i]);
    mesh.tangents.push_back(tangent);
  }
  mesh.triangles.emplace_back(base, base + 1, base + 2);
  mesh.triangles.emplace_back(base, base + 2, base + 3);
}

}  // namespace

Mesh make_quad(const glm::vec3& corner, const glm::vec3& edge1, const glm::vec3& edge2) {
  Mesh mesh;
  mesh.name = "quad";
  append_quad(mesh, corner, edge1, edge2);
  return mesh;
}

Mesh make_box(const glm::vec3& lo, const glm::vec3& hi) {
  Mesh mesh;
  mesh.name = "box";
  const glm::vec3 d = hi - lo;
  const glm::vec3 dx(d.x, 0, 0), dy(0, d.y, 0), dz(0, 0, d.z);
  // Each face as corner + two edges whose cross product points out of the box.
  append_quad(mesh, lo, dz, dy);                            // -x
  append_quad(mesh, glm::vec3(hi.x, lo.y, hi.z), -dz, dy);  // +x
  append_quad(mesh, lo, dx, dz);                            // -y
  append_quad(mesh, glm::vec3(lo.x, hi.y, hi.z), dx, -dz);  // +y
  append_quad(mesh, glm::vec3(hi.x, lo.y, lo.z), -dx, dy);  // -z
  append_quad(mesh, glm::vec3(lo.x, lo.y, hi.z), dx, dy);   // +z
  return mesh;
}

Mesh make_sphere(const glm::vec3& center, float radius, int subdivisions, bool inward) {
  // The icosahedron, faces counter-clockwise seen from outside.
  const float t = (1.0f + glm::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> unit = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                 {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                 {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (glm::vec3& v : unit) v = glm::normalize(v);
  std::vector<glm::uvec3> faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                   {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                   {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                   {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    // Shared edge midpoints, so the subdivided sphere stays watertight.
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const std::pair<std::uint32_t, std::uint32_t> key = std::minmax(a, b);
      const auto found = midpoints.find(key);
      if (found != midpoints.end()) return found->second;
      unit.push_back(glm::normalize(unit[a] + unit[b]));
      const auto index = static_cast<std::uint32_t>(unit.size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<glm::uvec3> finer;
    finer.reserve(faces.size() * 4);
    for (const glm::uvec3& f : faces) {
      const std::uint32_t ab = midpoint(f.x, f.y), bc = midpoint(f.y, f.z), ca = midpoint(f.z, f.x);
      finer.emplace_back(f.x, ab, ca);
      finer.emplace_back(f.y, bc, ab);
      finer.emplace_back(f.z, ca, bc);
      finer.emplace_back(ab, bc, ca);
    }
    faces.swap(finer);
  }

  Mesh mesh;
  mesh.name = "sphere";
  const float sign = inward ? -1.0f : 1.0f;
  for (const glm::vec3& v : unit) {
    mesh.positions.push_back(center + radius * v);
    mesh.normals.push_back(sign * v);
  }
  for (const glm::uvec3& f : faces)
    mesh.triangles.push_back(inward ? glm::uvec3(f.x, f.z, f.y) : f);
  return mesh;
}

}  // namespace rtpg

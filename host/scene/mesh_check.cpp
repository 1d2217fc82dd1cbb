// Value checks of imported meshes and materials (mesh_check.h).
#include "scene/mesh_check.h"

#include <cmath>
#include <cstdio>

#include "rtpg/errors.h"

namespace rtpg {
namespace {

std::string vec_text(const glm::vec3& v) {
  char text[96];
  std::snprintf(text, sizeof(text), "(%g %g %g)", v.x, v.y, v.z);
  return text;
}

}  // namespace

bool all_finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::size_t drop_degenerate_triangles(Mesh& mesh) {
  std::size_t kept = 0;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::vec3 c = glm::cross(mesh.positions[t.y] - mesh.positions[t.x],
                                   mesh.positions[t.z] - mesh.positions[t.x]);
    if (all_finite(c) && glm::dot(c, c) > 0.0f) mesh.triangles[kept++] = t;
  }
  const std::size_t dropped = mesh.triangles.size() - kept;
  mesh.triangles.resize(kept);
  return dropped;
}

void check_mesh_values(const Mesh& mesh, const std::string& file, const std::string& context) {
  auto fail = [&](const std::string& problem) {
    throw InputError(file, "mesh '" + mesh.name + "': " + problem + " (" + context + ")");
  };
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    if (!all_finite(mesh.positions[i]))
      fail("vertex " + std::to_string(i) + " at " + vec_text(mesh.positions[i]) + " is not finite");
  for (std::size_t i = 0; i < mesh.uvs.size(); ++i)
    if (!std::isfinite(mesh.uvs[i].x) || !std::isfinite(mesh.uvs[i].y))
      fail("texture coordinate " + std::to_string(i) + " is not finite");
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (mesh.triangles[i][k] >= mesh.positions.size())
        fail("triangle " + std::to_string(i) + " names vertex " +
             std::to_string(mesh.triangles[i][k]) + " of " + std::to_string(mesh.positions.size()));
}

void check_material_values(const Material& m, const std::string& file, const std::string& context) {
  auto fail = [&](const std::string& problem) {
    throw InputError(file, "material '" + m.name + "': " + problem + " (" + context + ")");
  };
  auto unit = [&](float v, const char* what) {
    if (!(v >= 0.0f && v <= 1.0f))
      fail(std::string(what) + " " + std::to_string(v) + " is not in [0, 1]");
  };
  for (int i = 0; i < 3; ++i) {
    if (!(m.base_color[i] >= 0.0f && m.base_color[i] <= 1.0f))
      fail("base colour " + vec_text(m.base_color) + " is not in [0, 1]");
    if (!(m.emission[i] >= 0.0f) || !std::isfinite(m.emission[i]))
      fail("emission " + vec_text(m.emission) + " is not finite and non-negative");
  }
  unit(m.roughness, "roughness");
  unit(m.metallic, "metallic");
  unit(m.specular, "specular");
  unit(m.alpha_cutoff, "alpha cutoff");
  if (!std::isfinite(m.bump_scale)) fail("bump scale is not finite");
}

}  // namespace rtpg

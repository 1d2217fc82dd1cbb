// Affine transformation of meshes.
#include "scene/mesh_transform.h"

#include <utility>

namespace rtpg {

namespace {

glm::vec3 normalize_or(const glm::vec3& v, const glm::vec3& fallback) {
  const float len2 = glm::dot(v, v);
  return len2 > 0.0f ? v / glm::sqrt(len2) : fallback;
}

}  // namespace

void transform_mesh(Mesh& mesh, const glm::mat4& m) {
  const glm::mat3 linear(m);
  const glm::mat3 normal_matrix = glm::transpose(glm::inverse(linear));
  const bool mirrored = glm::determinant(linear) < 0.0f;

  for (glm::vec3& p : mesh.positions) p = glm::vec3(m * glm::vec4(p, 1.0f));
  // Tangents need the old normals (for the bitangent), so they go before the normals.
  for (std::size_t i = 0; i < mesh.tangents.size() && i < mesh.normals.size(); ++i) {
    const glm::vec3 n = mesh.normals[i];
    const glm::vec3 t(mesh.tangents[i]);
    const glm::vec3 b = mesh.tangents[i].w * glm::cross(n, t);
    const glm::vec3 n2 = normalize_or(normal_matrix * n, n);
    const glm::vec3 t2 = normalize_or(linear * t, t);
    const float w = glm::dot(glm::cross(n2, t2), linear * b) < 0.0f ? -1.0f : 1.0f;
    mesh.tangents[i] = glm::vec4(t2, w);
  }
  for (glm::vec3& n : mesh.normals) n = normalize_or(normal_matrix * n, n);
  if (mirrored)
    for (glm::uvec3& t : mesh.triangles) std::swap(t.y, t.z);
}

}  // namespace rtpg

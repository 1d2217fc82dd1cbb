// Edits of a loaded scene that tests make to reach a case the scene files do not have.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace rtpg::test {

// Every emitting mesh scaled by `size` about its own centre, and its emission multiplied by
// `emission` (a light shrunk or grown in place: the Cornell box's ceiling light as a tiny
// bright one, or one that fills the ceiling).
inline void resize_emitters(Scene& scene, float size, float emission) {
  for (Mesh& mesh : scene.meshes) {
    Material& material = scene.materials[mesh.material];
    if (!material.is_emissive()) continue;
    glm::vec3 centre(0.0f);
    for (const glm::vec3& v : mesh.positions) centre += v;
    centre /= static_cast<float>(mesh.positions.size());
    for (glm::vec3& v : mesh.positions) v = centre + (v - centre) * size;
    material.emission *= emission;
  }
}

// Every mesh turned by `rotation` about `centre` (positions, normals and tangents; the camera
// and the lights that are not meshes stay): a scene whose walls are no longer axis-aligned.
inline void rotate_meshes(Scene& scene, const glm::mat3& rotation, const glm::vec3& centre) {
  for (Mesh& mesh : scene.meshes) {
    for (glm::vec3& v : mesh.positions) v = centre + rotation * (v - centre);
    for (glm::vec3& n : mesh.normals) n = rotation * n;
    for (glm::vec4& t : mesh.tangents) t = glm::vec4(rotation * glm::vec3(t), t.w);
  }
}

// An alpha mask whose left half is transparent: 8x1 texels, alpha 0 in the left four and 1 in
// the right four (8-bit, or float texels), white. On make_quad's uv (u along its first edge) the
// quad is then open for u below about 1/2: bilinear alpha falls below 1/2 from a quarter texel
// short of the middle, and from the wrap's edge (u = 1/16 .. 7/16 certainly open).
inline Texture left_half_transparent_mask(bool eight_bit = true) {
  Texture mask;
  mask.width = 8;
  mask.height = 1;
  for (int x = 0; x < mask.width; ++x) {
    const std::uint8_t alpha = x < 4 ? 0 : 255;
    if (eight_bit) {
      mask.texels8.push_back({255, 255, 255, alpha});
    } else {
      mask.texels.push_back(glm::vec4(1.0f, 1.0f, 1.0f, alpha / 255.0f));
    }
  }
  return mask;
}

}  // namespace rtpg::test

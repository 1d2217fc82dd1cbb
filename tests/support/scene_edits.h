// Edits of a loaded scene that tests make to reach a case the scene files do not have.
#pragma once

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

}  // namespace rtpg::test

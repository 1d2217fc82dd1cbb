#include "scene/alpha_mask.h"

namespace rtpg {

bool has_alpha_mask(const Scene& scene, const Mesh& mesh) {
  return scene.materials.at(mesh.material).alpha_texture >= 0 && !mesh.uvs.empty();
}

}  // namespace rtpg

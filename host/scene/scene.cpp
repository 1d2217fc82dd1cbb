// Summaries of a loaded scene: size, extent and the features the renderer must compile in.
#include "scene/scene.h"

#include <limits>

namespace rtpg {

namespace {

// Materials that some mesh uses: an unused material must not switch on renderer features.
std::vector<bool> used_materials(const Scene& scene) {
  std::vector<bool> used(scene.materials.size(), false);
  for (const Mesh& mesh : scene.meshes)
    if (mesh.material < used.size() && !mesh.triangles.empty()) used[mesh.material] = true;
  return used;
}

bool has_positions(const Scene& scene) {
  for (const Mesh& mesh : scene.meshes)
    if (!mesh.positions.empty()) return true;
  return false;
}

}  // namespace

std::size_t Scene::triangle_count() const {
  std::size_t count = 0;
  for (const Mesh& mesh : meshes) count += mesh.triangles.size();
  return count;
}

// Bounds of all vertices; (0,0,0) for a scene without geometry, so callers never see inf.
glm::vec3 Scene::bounds_min() const {
  if (!has_positions(*this)) return glm::vec3(0.0f);
  glm::vec3 lo(std::numeric_limits<float>::max());
  for (const Mesh& mesh : meshes)
    for (const glm::vec3& p : mesh.positions) lo = glm::min(lo, p);
  return lo;
}

glm::vec3 Scene::bounds_max() const {
  if (!has_positions(*this)) return glm::vec3(0.0f);
  glm::vec3 hi(std::numeric_limits<float>::lowest());
  for (const Mesh& mesh : meshes)
    for (const glm::vec3& p : mesh.positions) hi = glm::max(hi, p);
  return hi;
}

SceneFeatures Scene::features() const {
  SceneFeatures f;
  const std::vector<bool> used = used_materials(*this);
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (!used[i]) continue;
    const Material& m = materials[i];
    f.textures = f.textures || m.base_color_texture >= 0 || m.roughness_texture >= 0 ||
                 m.metallic_texture >= 0 || m.normal_texture >= 0 || m.bump_texture >= 0 ||
                 m.alpha_texture >= 0;
    f.normal_maps = f.normal_maps || m.normal_texture >= 0;
    f.bump_maps = f.bump_maps || m.bump_texture >= 0;
    f.alpha_masks = f.alpha_masks || m.alpha_texture >= 0;
    f.area_lights = f.area_lights || m.is_emissive();
    // A metallic texture only scales the metallic factor, so the factor alone decides.
    f.glossy = f.glossy || m.specular > 0.0f || m.metallic > 0.0f;
    f.metallic = f.metallic || m.metallic > 0.0f;
    f.transmission = f.transmission || m.transmissive;
  }
  f.sun = sun.enabled;
  f.environment = environment.kind != Environment::Kind::None;
  f.environment_map = environment.kind == Environment::Kind::Map;
  f.camera_paths = !camera.paths.empty();
  return f;
}

}  // namespace rtpg

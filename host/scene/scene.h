// The in-memory scene: flattened world-space meshes, materials, textures, lights and camera.
// Built by SceneLoader (scene_loader.h) from a JSON description; read by the tracer (BVH),
// the lights (light sampling) and the renderer. Knows nothing of Embree or OpenCL.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/camera.h"
#include "scene/texture.h"

namespace rtpg {

// Lambert diffuse plus a GGX microfacet lobe, metallic/roughness parameterisation (as glTF).
// Texture indices refer to Scene::textures; -1 means "no texture".
struct Material {
  std::string name;
  glm::vec3 base_color{0.8f};
  int base_color_texture = -1;  // RGB(A), decoded to linear; multiplies base_color
  float roughness = 1.0f;       // perceptual roughness, alpha = roughness^2
  int roughness_texture = -1;   // channel roughness_channel multiplies roughness
  int roughness_channel = 1;    // glTF metallicRoughness: G = roughness, B = metallic
  float metallic = 0.0f;
  int metallic_texture = -1;  // channel metallic_channel multiplies metallic
  int metallic_channel = 2;
  float specular = 0.04f;   // dielectric F0 at normal incidence; 0 disables the GGX lobe
  int normal_texture = -1;  // tangent-space normal map (RGB in [0,1])
  int bump_texture = -1;    // height map (grey); perturbs the shading normal
  float bump_scale = 1.0f;
  int alpha_texture = -1;  // alpha mask, alpha-tested at alpha_cutoff
  float alpha_cutoff = 0.5f;
  glm::vec3 emission{0.0f};  // emitted radiance (one-sided, along the geometric normal)
  // Guiding skips it (no guided first bounce there: PG_GBUF_TRANSMISSIVE); it is shaded, lit by
  // next-event estimation and sampled as its BSDF allows, which has no transmission.
  bool transmissive = false;
  bool is_emissive() const { return emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f; }
  // Whether shading a hit reads a texture (the alpha mask is the ray queries' own).
  bool has_textures() const {
    return base_color_texture >= 0 || roughness_texture >= 0 || metallic_texture >= 0 ||
           normal_texture >= 0 || bump_texture >= 0;
  }
};

// The most path vertices after the primary hit a render takes (a scene's integrator.max_bounces,
// --max-bounces): paths record their depth in a byte (the world guide's), and Russian roulette
// ends real paths long before.
constexpr int kMaxPathBounces = 64;

// One triangle mesh in world space (instances and transforms are flattened at load time).
struct Mesh {
  std::string name;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;   // per vertex; empty = use the geometric normal
  std::vector<glm::vec2> uvs;       // per vertex; empty = no texture coordinates
  std::vector<glm::vec4> tangents;  // xyz tangent, w handedness; empty = derived when needed
  std::vector<glm::uvec3> triangles;
  std::uint32_t material = 0;  // index into Scene::materials
};

// A directional light of finite angular radius (a disc of uniform radiance on the sky).
struct SunLight {
  bool enabled = false;
  glm::vec3 direction{0.0f, 1.0f, 0.0f};  // unit vector from the scene towards the sun
  glm::vec3 irradiance{0.0f};             // W/m^2 on a surface facing the sun
  float angular_radius = 0.0f;            // radians; 0 = a delta light (NEE only)
};

struct Environment {
  enum class Kind { None, Constant, Map };
  Kind kind = Kind::None;
  glm::vec3 color{0.0f};  // Constant: radiance; Map: multiplier of the map
  int map_texture = -1;   // equirectangular, linear RGB, Scene::textures index
  float rotation = 0.0f;  // radians about +y
};

struct SceneFeatures {
  bool textures = false, normal_maps = false, bump_maps = false, alpha_masks = false;
  bool area_lights = false, sun = false, environment = false, environment_map = false;
  bool glossy = false, metallic = false, transmission = false, camera_paths = false;
};

struct Scene {
  std::string source_path;  // the JSON file it came from ("" for scenes built in code)
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  SunLight sun;
  Environment environment;
  CameraSetup camera;
  int max_bounces = 0;  // the scene's "integrator.max_bounces"; 0 = the renderer's default
  // The scene's "exposure": radiance is multiplied by it before the display transform of PNG
  // output and of the benchmarks' LDR-FLIP (kernels/shared/tonemap.h); EXR output stays linear.
  float exposure = 1.0f;
  std::size_t degenerate_triangles = 0;  // zero-area triangles the loader dropped
  std::vector<std::string> warnings;     // what the loader accepted but the user should know

  std::size_t triangle_count() const;
  glm::vec3 bounds_min() const;
  glm::vec3 bounds_max() const;
  SceneFeatures features() const;
};

}  // namespace rtpg

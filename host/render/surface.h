// What the integrator needs to know about a ray's hit point: geometry, shading frame and
// material parameters with textures applied.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "shared/bsdf.h"
#include "trace/ray.h"

namespace rtpg {

struct SurfacePoint {
  glm::vec3 position{0.0f};
  // How far along geometric_normal a ray origin must move to clear the rounding error of
  // `position` (offset_ray_origin); scales with the coordinates' magnitude.
  float offset_distance = 0.0f;
  glm::vec3 geometric_normal{0.0f, 0.0f, 1.0f};  // flipped to face the incoming ray
  glm::vec3 shading_normal{0.0f, 0.0f, 1.0f};    // same side as geometric_normal
  glm::vec3 emission{0.0f};  // radiance emitted back along the ray (0 from the back side)
  shared::pg_material material{};
  std::uint32_t material_id = 0;
  bool transmissive = false;
};

// Interpolates and textures the hit of `ray`; `hit` must be valid.
SurfacePoint make_surface_point(const Scene& scene, const Ray& ray, const Hit& hit);

// Origin for rays leaving p on the side of the unit normal n: p moved offset_distance along n
// (SurfacePoint::offset_distance, an error bound of p), then one float further from p in each
// moved coordinate, so rounding the sum cannot land it back inside the error box. No
// scene-dependent epsilon: the offset follows the hit's magnitude (docs/robustness.md).
glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n, float offset_distance);

}  // namespace rtpg

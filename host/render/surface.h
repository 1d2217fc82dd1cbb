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
  glm::vec3 geometric_normal{0.0f, 0.0f, 1.0f};  // flipped to face the incoming ray
  glm::vec3 shading_normal{0.0f, 0.0f, 1.0f};    // same side as geometric_normal
  glm::vec3 emission{0.0f};  // radiance emitted back along the ray (0 from the back side)
  shared::pg_material material{};
  std::uint32_t material_id = 0;
  bool transmissive = false;
};

// Interpolates and textures the hit of `ray`; `hit` must be valid.
SurfacePoint make_surface_point(const Scene& scene, const Ray& ray, const Hit& hit);

// Offset origin for rays leaving p on the side of n: avoids self-intersection without a
// scene-dependent epsilon (a scaled offset as in Wächter and Binder, Ray Tracing Gems ch. 6).
glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n);

}  // namespace rtpg

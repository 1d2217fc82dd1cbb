// Light sampling for next-event estimation and the densities MIS needs when a BSDF-sampled
// ray finds a light by itself: emissive triangles (chosen by power, uniform by area; two that
// make a parallelogram, as a quad light's do, sampled as one), the sun
// (a cone of finite angular radius, or a delta direction) and the environment (constant, or
// an equirectangular map sampled by luminance times sin(theta)).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "render/distribution.h"
#include "scene/scene.h"
#include "trace/ray.h"

namespace rtpg {

struct LightSample {
  glm::vec3 direction{0.0f};  // unit, from the shading point towards the light
  float distance = 0.0f;      // to the light point; infinity for the sun and the environment
  glm::vec3 radiance{0.0f};   // arriving along -direction (before visibility)
  float pdf = 0.0f;           // solid-angle density of this sample (selection included)
  bool delta = false;         // a delta light: BSDF sampling can never hit it (no MIS)
};

// Shadow ray from origin towards a light sample, stopping just short of the light (infinite
// for the sun and the environment).
Ray shadow_ray(const glm::vec3& origin, const LightSample& sample);
// The same written into r in place (set_ray, host/trace/ray.h).
void set_shadow_ray(Ray& r, const glm::vec3& origin, const LightSample& sample);

class Lights {
 public:
  explicit Lights(const Scene& scene);

  bool empty() const { return selection_.total() <= 0.0f; }
  // u: three uniform numbers (select, then two for the point or direction).
  bool sample(const glm::vec3& p, float u_select, float u1, float u2, LightSample& out) const;

  // Density with which sample() would produce the direction from p to the hit point y on
  // triangle `triangle` of mesh `mesh` (with its geometric normal ng, any side).
  float pdf_triangle(std::uint32_t mesh, std::uint32_t triangle, const glm::vec3& p,
                     const glm::vec3& y, const glm::vec3& ng) const;
  // Radiance arriving from infinity along -direction (environment plus the sun's disc), and
  // the density with which sample() produces that direction.
  glm::vec3 escaped_radiance(const glm::vec3& direction) const;
  float pdf_escaped(const glm::vec3& direction) const;

  // The emitters light sampling chooses from: each emissive triangle, or two of them as one
  // parallelogram (docs/host-path-tracer.md, "Quad lights sampled as parallelograms").
  std::size_t emitter_count() const { return triangles_.size(); }
  std::size_t parallelogram_count() const { return parallelograms_; }

 private:
  // An emissive triangle (p0, p0 + e1, p0 + e2), or the parallelogram p0 + s e1 + t e2 of two
  // triangles of one mesh that share its diagonal p0 + e1, p0 + e2.
  struct EmissiveTriangle {
    glm::vec3 p0, e1, e2;
    glm::vec3 normal;  // unit, front side
    float area;
    glm::vec3 radiance;
    bool parallelogram = false;
    // Where its mesh is alpha-tested (scene/alpha_mask.h): the mesh and the triangle, so that a
    // point drawn on a transparent texel is refused as a ray there passes through; -1 where
    // not. A masked triangle is never part of a parallelogram (its point needs its own
    // barycentrics).
    std::int32_t masked_mesh = -1;
    std::uint32_t triangle = 0;
  };
  enum Kind : std::size_t { kTriangles = 0, kSun = 1, kEnvironment = 2 };

  // Whether triangles a and b (of one mesh, a's unit normal `normal`) make a parallelogram;
  // if so, `out` becomes it (its corner, edges and area; out's other fields are left).
  static bool parallelogram_of(const glm::uvec3& a, const glm::uvec3& b,
                               const std::vector<glm::vec3>& positions, const glm::vec3& normal,
                               EmissiveTriangle& out);
  // Inline in both callers: where triangles are the only lights, sample is little more than it.
  [[gnu::always_inline]] inline bool sample_triangle(const glm::vec3& p, float u_triangle,
                                                     float p_kind, float u1, float u2,
                                                     LightSample& out) const;
  // Whether the point (1 - u - v) p0 + u p1 + v p2 of masked emitter e passes its mesh's alpha
  // test. Out of line: the one masked emitters' cost.
  bool masked_point_emits(const EmissiveTriangle& e, float u, float v) const;
  // Whether direction d (unit) lies in the sun's cone: by the sine of its angle to the axis.
  bool in_sun_cone(const glm::vec3& d) const;
  glm::vec3 environment_radiance(const glm::vec3& direction) const;
  float environment_pdf(const glm::vec3& direction) const;
  glm::vec2 direction_to_equirect(const glm::vec3& d) const;
  glm::vec3 equirect_to_direction(float u, float v) const;

  const Scene& scene_;
  std::vector<EmissiveTriangle> triangles_;
  std::size_t parallelograms_ = 0;
  std::vector<std::vector<std::int32_t>> triangle_index_;  // [mesh][triangle] -> light or -1
  Distribution1D triangle_selection_;
  Distribution1D selection_;  // over Kind
  // What a scene without them skips (docs/host-path-tracer.md, "What a scene does not use,
  // skipped"): the choice of a kind where emissive triangles are the only one, and the sky's
  // radiance and density where there is neither an environment nor a sun of finite size.
  bool triangles_only_ = false;
  bool has_sky_ = true;
  glm::vec3 sun_axis_{0, 1, 0};  // normalize(scene.sun.direction), once: every escaped ray asks
  glm::vec3 sun_frame_t_{1, 0, 0}, sun_frame_b_{0, 1, 0};
  // The sun's cone of angular radius r: 1 - cos r and sin^2 r from sines, not from cos r, whose
  // difference from 1 keeps only two or three digits in float at the sun's 0.27 degrees
  // (docs/robustness.md, "The sun's cone").
  float sun_one_minus_cos_max_ = 0.0f;
  float sun_sin2_max_ = 0.0f;
  float sun_solid_angle_ = 0.0f;
  glm::vec3 sun_radiance_{0.0f};
  const Texture* env_map_ = nullptr;
  Distribution2D env_distribution_;
};

}  // namespace rtpg

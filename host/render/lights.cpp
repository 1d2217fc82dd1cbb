#include "render/lights.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "scene/alpha_mask.h"
#include "shared/compat.h"

namespace rtpg {
namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

float luminance(const glm::vec3& c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

}  // namespace

bool Lights::parallelogram_of(const glm::uvec3& a, const glm::uvec3& b,
                              const std::vector<glm::vec3>& positions, const glm::vec3& normal,
                              EmissiveTriangle& out) {
  // Triangle b shares two corners (a diagonal) with triangle a; the corners off it, o_a and
  // o_b, then make a parallelogram with it where the diagonals bisect each other:
  // o_a + o_b = s1 + s2.
  const std::uint32_t ia[3] = {a.x, a.y, a.z}, ib[3] = {b.x, b.y, b.z};
  // The one corner of x that y lacks (-1: none, or more than one).
  const auto off = [](const std::uint32_t* x, const std::uint32_t* y) {
    int found = -1, count = 0;
    for (int i = 0; i < 3; ++i) {
      if (x[i] != y[0] && x[i] != y[1] && x[i] != y[2]) {
        found = i;
        ++count;
      }
    }
    return count == 1 ? found : -1;
  };
  const int off_a = off(ia, ib), off_b = off(ib, ia);
  if (off_a < 0 || off_b < 0) return false;
  const glm::vec3 o = positions[ia[off_a]], q = positions[ib[off_b]];
  const glm::vec3 s1 = positions[ia[(off_a + 1) % 3]], s2 = positions[ia[(off_a + 2) % 3]];
  const glm::vec3 e1 = s1 - o, e2 = s2 - o;
  const float size = glm::length(e1) + glm::length(e2);
  if (!(glm::length(o + q - s1 - s2) <= 1e-6f * size)) return false;
  // Triangle b must face the way a does (emitters are one-sided) and have its area.
  const glm::vec3 cb =
      glm::cross(positions[ib[1]] - positions[ib[0]], positions[ib[2]] - positions[ib[0]]);
  const float area_b = 0.5f * glm::length(cb);
  if (!(area_b > 0.0f) || !(glm::dot(cb / (2.0f * area_b), normal) > 0.99999f)) return false;
  // (o, s1, s2) is a's winding turned: cross(e1, e2) points along a's normal, the emitter's front.
  const glm::vec3 c = glm::cross(e1, e2);
  out.p0 = o;
  out.e1 = e1;
  out.e2 = e2;
  out.area = glm::length(c);
  out.parallelogram = true;
  return true;
}

void set_shadow_ray(Ray& r, const glm::vec3& origin, const LightSample& sample) {
  set_ray(r, origin, sample.direction, 0.0f,
          std::isinf(sample.distance) ? kInfinity : sample.distance * (1.0f - 1e-4f));
}

Ray shadow_ray(const glm::vec3& origin, const LightSample& sample) {
  Ray r;
  set_shadow_ray(r, origin, sample);
  return r;
}

Lights::Lights(const Scene& scene) : scene_(scene) {
  // Emissive triangles, weighted by their emitted power (area * luminance of Le). Two
  // consecutive triangles of a mesh that form a parallelogram (a quad light, scene/shapes.h, or
  // an OBJ quad) become one emitter, sampled without the triangle's square root and without a
  // choice between the two: the same density, half the light choices (docs/host-path-tracer.md,
  // "Quad lights sampled as parallelograms").
  std::vector<float> weights;
  triangle_index_.resize(scene.meshes.size());
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    const Material& mat = scene.materials[mesh.material];
    if (!mat.is_emissive()) continue;
    triangle_index_[m].assign(mesh.triangles.size(), -1);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const glm::uvec3 tri = mesh.triangles[t];
      EmissiveTriangle e;
      e.p0 = mesh.positions[tri.x];
      e.e1 = mesh.positions[tri.y] - e.p0;
      e.e2 = mesh.positions[tri.z] - e.p0;
      const glm::vec3 c = glm::cross(e.e1, e.e2);
      e.area = 0.5f * glm::length(c);
      if (!(e.area > 0.0f)) continue;
      e.normal = glm::normalize(c);
      e.radiance = mat.emission;
      if (has_alpha_mask(scene, mesh)) {
        e.masked_mesh = static_cast<std::int32_t>(m);
        e.triangle = static_cast<std::uint32_t>(t);
      }
      const bool pair =
          e.masked_mesh < 0 && t + 1 < mesh.triangles.size() &&
          parallelogram_of(mesh.triangles[t], mesh.triangles[t + 1], mesh.positions, e.normal, e);
      triangle_index_[m][t] = static_cast<std::int32_t>(triangles_.size());
      if (pair) {
        triangle_index_[m][t + 1] = static_cast<std::int32_t>(triangles_.size());
        ++parallelograms_;
        ++t;
      }
      triangles_.push_back(e);
      weights.push_back(e.area * luminance(e.radiance));
    }
  }
  triangle_selection_ = Distribution1D(weights);

  // Rough powers decide how often each kind is chosen; any positive split is unbiased.
  const glm::vec3 extent = scene.bounds_max() - scene.bounds_min();
  const float radius = 0.5f * glm::length(extent);
  const float disc = kPi * radius * radius;
  sun_axis_ = glm::normalize(scene.sun.direction);
  std::vector<float> kinds(3, 0.0f);
  kinds[kTriangles] = kPi * triangle_selection_.total();
  if (scene.sun.enabled && luminance(scene.sun.irradiance) > 0.0f) {
    kinds[kSun] = luminance(scene.sun.irradiance) * disc;
    const shared::pg_frame f = shared::pg_frame_from_normal(glm::normalize(scene.sun.direction));
    sun_frame_t_ = f.t;
    sun_frame_b_ = f.b;
    if (scene.sun.angular_radius > 0.0f) {
      // A cone of radius r holds the solid angle 2 pi (1 - cos r) = 4 pi sin^2(r / 2), and a
      // surface facing it receives L pi sin^2 r from radiance L over it: the radiance that
      // gives the scene's irradiance on such a surface (scenes/README.md, "sun").
      const float r = scene.sun.angular_radius, half_sine = std::sin(0.5f * r);
      sun_one_minus_cos_max_ = 2.0f * half_sine * half_sine;
      sun_sin2_max_ = std::sin(r) * std::sin(r);
      sun_solid_angle_ = 2.0f * kPi * sun_one_minus_cos_max_;
      sun_radiance_ = scene.sun.irradiance / (kPi * sun_sin2_max_);
    }
  }
  const Environment& env = scene.environment;
  if (env.kind == Environment::Kind::Constant) {
    kinds[kEnvironment] = kPi * luminance(env.color) * disc;
  } else if (env.kind == Environment::Kind::Map && env.map_texture >= 0) {
    env_map_ = &scene.textures[env.map_texture];
    const int w = env_map_->width, h = env_map_->height;
    std::vector<float> texel_weights(static_cast<std::size_t>(w) * h);
    double sum = 0.0;
    for (int y = 0; y < h; ++y) {
      const float sin_theta =
          std::sin(kPi * (static_cast<float>(y) + 0.5f) / static_cast<float>(h));
      for (int x = 0; x < w; ++x) {
        const float l = luminance(glm::vec3(env_map_->fetch(x, y)) * env.color);
        texel_weights[static_cast<std::size_t>(y) * w + x] = l * sin_theta;
        sum += l * sin_theta;
      }
    }
    env_distribution_ = Distribution2D(texel_weights, w, h);
    const float mean_radiance =
        static_cast<float>(sum / (static_cast<double>(w) * h)) * (kPi / 2.0f);
    kinds[kEnvironment] = kPi * mean_radiance * disc;
  }
  selection_ = Distribution1D(kinds);
  triangles_only_ =
      kinds[kTriangles] > 0.0f && !(kinds[kSun] > 0.0f) && !(kinds[kEnvironment] > 0.0f);
  // escaped_radiance and pdf_escaped are 0 without an environment (none, a map that did not
  // load, or a black constant, whose selection probability is 0 too) and without a sun of finite
  // size (a delta sun is only ever sampled, never found).
  has_sky_ = env_map_ != nullptr ||
             (env.kind == Environment::Kind::Constant && env.color != glm::vec3(0.0f)) ||
             sun_solid_angle_ > 0.0f;
}

bool Lights::in_sun_cone(const glm::vec3& d) const {
  // |d x axis| = sin of the angle, with the relative precision of its small components: the
  // cosine, a dot product near 1, resolves the sun's 0.27-degree rim only to about 1%.
  const glm::vec3 c = glm::cross(d, sun_axis_);
  return glm::dot(d, sun_axis_) > 0.0f && glm::dot(c, c) <= sun_sin2_max_;
}

glm::vec2 Lights::direction_to_equirect(const glm::vec3& d) const {
  // +y is up; u runs with the azimuth (rotated by the scene's rotation), v from the zenith.
  const float theta = std::acos(std::clamp(d.y, -1.0f, 1.0f));
  float phi = std::atan2(d.z, d.x) - scene_.environment.rotation;
  phi = phi - 2.0f * kPi * std::floor(phi / (2.0f * kPi));
  return {phi / (2.0f * kPi), theta / kPi};
}

glm::vec3 Lights::equirect_to_direction(float u, float v) const {
  const float theta = v * kPi, phi = u * 2.0f * kPi + scene_.environment.rotation;
  const float s = std::sin(theta);
  return {s * std::cos(phi), std::cos(theta), s * std::sin(phi)};
}

glm::vec3 Lights::environment_radiance(const glm::vec3& d) const {
  const Environment& env = scene_.environment;
  if (env.kind == Environment::Kind::Constant) return env.color;
  if (env_map_) {
    const glm::vec2 uv = direction_to_equirect(d);
    // Texture::sample has v = 0 at the bottom row; the map's v = 0 is the zenith (top row).
    return glm::vec3(env_map_->sample_lat_long({uv.x, 1.0f - uv.y})) * env.color;
  }
  return glm::vec3(0.0f);
}

float Lights::environment_pdf(const glm::vec3& d) const {
  const Environment& env = scene_.environment;
  if (env.kind == Environment::Kind::Constant) return 1.0f / (4.0f * kPi);
  if (env_map_ && !env_distribution_.empty()) {
    const glm::vec2 uv = direction_to_equirect(d);
    const float sin_theta = std::sin(uv.y * kPi);
    if (sin_theta <= 0.0f) return 0.0f;
    return env_distribution_.pdf(uv.x, uv.y) / (2.0f * kPi * kPi * sin_theta);
  }
  return 0.0f;
}

inline bool Lights::sample_triangle(const glm::vec3& p, float u_triangle, float p_kind, float u1,
                                    float u2, LightSample& out) const {
  float p_tri = 0.0f;
  const std::size_t i = triangle_selection_.sample_discrete(u_triangle, &p_tri);
  const EmissiveTriangle& e = triangles_[i];
  glm::vec3 y;
  if (e.parallelogram) {
    y = e.p0 + e.e1 * u1 + e.e2 * u2;
  } else {
    // Uniform point on the triangle (pbrt's square-root parameterisation).
    const float su = std::sqrt(u1);
    const float b1 = u2 * su;
    // On a transparent texel of a masked emitter there is nothing to see: a ray towards it
    // passes through (the ray queries' alpha filter), so the sample carries no light, and the
    // density stays that of the whole triangle, which pdf_triangle gives the hits that do find
    // it (docs/robustness.md, "Alpha-masked emitters").
    if (e.masked_mesh >= 0 && !masked_point_emits(e, 1.0f - su, b1)) return false;
    y = e.p0 + e.e1 * (1.0f - su) + e.e2 * b1;
  }
  const glm::vec3 to = y - p;
  const float d2 = glm::dot(to, to);
  if (!(d2 > 0.0f)) return false;
  const float d = std::sqrt(d2);
  out.direction = to / d;
  const float cos_light = -glm::dot(out.direction, e.normal);
  if (cos_light <= 0.0f) return false;  // one-sided emitters
  out.distance = d;
  out.radiance = e.radiance;
  out.pdf = p_kind * p_tri * d2 / (cos_light * e.area);
  out.delta = false;
  return true;
}

bool Lights::masked_point_emits(const EmissiveTriangle& e, float u, float v) const {
  const Mesh& mesh = scene_.meshes[static_cast<std::size_t>(e.masked_mesh)];
  const Material& mat = scene_.materials[mesh.material];
  return passes_alpha_test(mesh, scene_.textures[static_cast<std::size_t>(mat.alpha_texture)],
                           mat.alpha_cutoff, e.triangle, u, v);
}

bool Lights::sample(const glm::vec3& p, float u_select, float u1, float u2,
                    LightSample& out) const {
  // u_select's place inside the kind's cell chooses the triangle (only this kind needs it).
  // With triangles the only kind, what sample_discrete and remap give for it, without calling
  // them: its probability (1) and u.
  if (triangles_only_)
    return sample_triangle(p, Distribution1D::remap_in_only_cell(u_select),
                           selection_.probability(kTriangles), u1, u2, out);
  if (empty()) return false;
  float p_kind = 0.0f;
  const std::size_t kind = selection_.sample_discrete(u_select, &p_kind);
  if (kind == kTriangles)
    return sample_triangle(p, selection_.remap(u_select, kind), p_kind, u1, u2, out);
  if (kind == kSun) {
    const glm::vec3 axis = sun_axis_;
    out.distance = kInfinity;
    if (sun_solid_angle_ <= 0.0f) {
      out.direction = axis;
      out.radiance = scene_.sun.irradiance;  // delta: the estimator divides by pdf = p_kind
      out.pdf = p_kind;
      out.delta = true;
      return true;
    }
    // Uniform in solid angle: 1 - cos t uniform in [0, 1 - cos r]; sin t from it without
    // cancellation.
    const float one_minus_cos = u1 * sun_one_minus_cos_max_;
    const float cos_t = 1.0f - one_minus_cos;
    const float sin_t = std::sqrt(std::max(0.0f, one_minus_cos * (2.0f - one_minus_cos)));
    const float phi = 2.0f * kPi * u2;
    out.direction = glm::normalize(sun_frame_t_ * (sin_t * std::cos(phi)) +
                                   sun_frame_b_ * (sin_t * std::sin(phi)) + axis * cos_t);
    out.radiance = escaped_radiance(out.direction);
    out.pdf = pdf_escaped(out.direction);
    out.delta = false;
    // Rounding can put a direction drawn at the cone's rim (u1 within about 2e-5 of 1) just
    // outside the float test of pdf_escaped; with no sky behind the sun its density is then 0,
    // and the sample is refused instead of dividing 0 by 0 (docs/robustness.md, "The sun's
    // cone").
    return out.pdf > 0.0f;
  }
  // Environment.
  out.distance = kInfinity;
  out.delta = false;
  if (env_map_) {
    float u = 0.0f, v = 0.0f, pdf_uv = 0.0f;
    env_distribution_.sample(u1, u2, u, v, pdf_uv);
    out.direction = equirect_to_direction(u, v);
  } else {
    const float z = 1.0f - 2.0f * u1, r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * kPi * u2;
    out.direction = {r * std::cos(phi), z, r * std::sin(phi)};
  }
  out.radiance = escaped_radiance(out.direction);
  out.pdf = pdf_escaped(out.direction);
  return out.pdf > 0.0f;
}

float Lights::pdf_triangle(std::uint32_t mesh, std::uint32_t triangle, const glm::vec3& p,
                           const glm::vec3& y, const glm::vec3& ng) const {
  if (mesh >= triangle_index_.size() || triangle_index_[mesh].empty()) return 0.0f;
  const std::int32_t i = triangle_index_[mesh][triangle];
  if (i < 0) return 0.0f;
  const EmissiveTriangle& e = triangles_[i];
  const glm::vec3 to = y - p;
  const float d2 = glm::dot(to, to);
  const float cos_light = std::fabs(glm::dot(to, e.normal)) / std::sqrt(d2);
  if (!(cos_light > 0.0f)) return 0.0f;
  (void)ng;
  return selection_.probability(kTriangles) * triangle_selection_.probability(i) * d2 /
         (cos_light * e.area);
}

glm::vec3 Lights::escaped_radiance(const glm::vec3& d) const {
  if (!has_sky_) return glm::vec3(0.0f);
  glm::vec3 l = environment_radiance(d);
  if (sun_solid_angle_ > 0.0f && in_sun_cone(d)) l += sun_radiance_;
  return l;
}

float Lights::pdf_escaped(const glm::vec3& d) const {
  if (!has_sky_) return 0.0f;
  float pdf = selection_.probability(kEnvironment) * environment_pdf(d);
  if (sun_solid_angle_ > 0.0f && in_sun_cone(d))
    pdf += selection_.probability(kSun) / sun_solid_angle_;
  return pdf;
}

}  // namespace rtpg

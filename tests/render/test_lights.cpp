// Light sampling for next-event estimation against its own densities (host/render/lights.h):
// the directions Lights::sample produces are binned over the sphere and compared with the
// density MIS uses for them (chi-square, tests/support/chi_square.h), for emissive triangles,
// the sun's cone, a constant sky and an environment map. Each test also shows its power: the
// same samples against a density that is 5% off, or that lacks the environment map's sin(theta)
// Jacobian, are rejected.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "render/distribution.h"
#include "render/lights.h"
#include "scene/scene.h"
#include "scene/shapes.h"
#include "shared/rng.h"
#include "support/chi_square.h"
#include "support/scene_edits.h"

namespace rtpg {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::size_t kSamples = 1000000;

// Every chi-square test of this file at an overall level of 0.01.
const double kAlpha = test::sidak_alpha(0.01, 4);

// A grey floor, so that the scene has bounds (they size the sun's and sky's share).
Scene floor_scene() {
  Scene scene;
  scene.materials.push_back(Material{});
  scene.meshes.push_back(make_quad({-1, 0, -1}, {2, 0, 0}, {0, 0, 2}));
  return scene;
}

// floor_scene with two emissive materials after the floor's (materials 1 and 2).
Scene floor_scene_with_lamps(const glm::vec3& first, const glm::vec3& second) {
  Scene scene = floor_scene();
  for (const glm::vec3& emission : {first, second}) {
    Material lamp;
    lamp.emission = emission;
    scene.materials.push_back(lamp);
  }
  return scene;
}

// The directions Lights::sample produces from p, with the pdf each sample reports.
struct LightSampler {
  const Lights& lights;
  glm::vec3 p;
  bool operator()(std::size_t i, glm::vec3& d) const {
    shared::pg_rng rng = shared::pg_rng_make(7u, static_cast<shared::uint>(i), 0u, 0u, 3u);
    const float a = shared::pg_rng_next(&rng), b = shared::pg_rng_next(&rng),
                c = shared::pg_rng_next(&rng);
    LightSample s;
    if (!lights.sample(p, a, b, c, s) || !(s.pdf > 0.0f)) return false;
    d = s.direction;
    return true;
  }
};

// Sun (a cone of 0.25 rad) and a constant sky: the density of a direction is what pdf_escaped
// says, which MIS uses when a BSDF-sampled ray escapes.
TEST(Lights, SunConeAndConstantSkyMatchTheirDensity) {
  Scene scene = floor_scene();
  scene.sun.enabled = true;
  scene.sun.direction = glm::normalize(glm::vec3(0.3f, 0.8f, 0.2f));
  scene.sun.irradiance = glm::vec3(3.0f);
  scene.sun.angular_radius = 0.25f;
  scene.environment.kind = Environment::Kind::Constant;
  scene.environment.color = glm::vec3(0.5f, 0.6f, 0.7f);
  const Lights lights(scene);
  const LightSampler sampler{lights, glm::vec3(0.0f, 0.5f, 0.0f)};
  // Each sample reports the density of its direction.
  for (std::size_t i = 0; i < 10000; ++i) {
    std::mt19937 gen(static_cast<unsigned>(i));
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    LightSample s;
    ASSERT_TRUE(lights.sample(sampler.p, u(gen), u(gen), u(gen), s));
    ASSERT_FALSE(s.delta);
    ASSERT_EQ(s.pdf, lights.pdf_escaped(s.direction));
  }
  const auto pdf = [&](const glm::vec3& d) { return double(lights.pdf_escaped(d)); };
  const auto right = test::chi_square_test(sampler, pdf, kSamples, 40, 80, 24);
  EXPECT_GT(right.p_value, kAlpha) << right.describe();
  EXPECT_NEAR(right.pdf_integral, 1.0, 2e-3) << right.describe();
  EXPECT_EQ(right.sample_fraction, 1.0);
  // Power: 5% more density inside the sun's cone is rejected.
  const glm::vec3 axis = scene.sun.direction;
  const auto wrong = test::chi_square_test(
      sampler,
      [&](const glm::vec3& d) {
        return pdf(d) * (glm::dot(d, axis) >= std::cos(0.25f) ? 1.05 : 1.0);
      },
      kSamples, 40, 80, 24);
  EXPECT_LT(wrong.p_value, 1e-6) << wrong.describe();
}

// An equirectangular map of random texels with one bright spot, rotated about +y, and a sun:
// sampled by luminance times sin(theta) (pbrt's infinite area light).
TEST(Lights, EnvironmentMapMatchesItsDensity) {
  Scene scene = floor_scene();
  Texture map;
  map.path = "random";
  map.width = 32;
  map.height = 16;
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(0.05f, 1.0f);
  for (int i = 0; i < map.width * map.height; ++i)
    map.texels.push_back(glm::vec4(u(gen), u(gen), u(gen), 1.0f));
  map.texels[5 * map.width + 20] = glm::vec4(40.0f, 30.0f, 20.0f, 1.0f);
  scene.textures.push_back(map);
  scene.environment.kind = Environment::Kind::Map;
  scene.environment.map_texture = 0;
  scene.environment.color = glm::vec3(1.0f);
  scene.environment.rotation = 0.7f;
  scene.sun.enabled = true;
  scene.sun.direction = glm::normalize(glm::vec3(-0.5f, 0.6f, 0.3f));
  scene.sun.irradiance = glm::vec3(1.0f);
  scene.sun.angular_radius = 0.3f;
  const Lights lights(scene);
  const LightSampler sampler{lights, glm::vec3(0.0f, 0.5f, 0.0f)};
  const auto pdf = [&](const glm::vec3& d) { return double(lights.pdf_escaped(d)); };
  const auto right = test::chi_square_test(sampler, pdf, kSamples, 40, 80, 24);
  EXPECT_GT(right.p_value, kAlpha) << right.describe();
  EXPECT_NEAR(right.pdf_integral, 1.0, 2e-3) << right.describe();
  // Power: the density without the 1 / sin(theta) of the equirectangular map (theta from +y),
  // renormalised over the sphere, is rejected.
  double integral = 0.0;
  const int n = 512;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < 2 * n; ++b) {
      const double z = 1.0 - 2.0 * (a + 0.5) / n, phi = 2.0 * kPi * (b + 0.5) / (2 * n);
      const double r = std::sqrt(1.0 - z * z);
      const glm::vec3 d(r * std::cos(phi), r * std::sin(phi), z);
      integral += pdf(d) * std::sqrt(std::max(0.0, 1.0 - double(d.y) * d.y));
    }
  integral *= (2.0 / n) * (2.0 * kPi / (2 * n));
  const auto wrong = test::chi_square_test(
      sampler,
      [&](const glm::vec3& d) {
        return pdf(d) * std::sqrt(std::max(0.0, 1.0 - double(d.y) * d.y)) / integral;
      },
      kSamples, 40, 80, 24);
  EXPECT_LT(wrong.p_value, 1e-6) << wrong.describe();
}

// The emissive triangle a ray from p along d hits first, with its hit point and mesh indices.
struct TriangleHit {
  bool hit = false;
  std::uint32_t mesh = 0, triangle = 0;
  glm::vec3 point{0.0f};
};

// Moller-Trumbore over every triangle of the scene (the test's own intersector).
TriangleHit first_hit(const Scene& scene, const glm::vec3& p, const glm::vec3& d) {
  TriangleHit best;
  double best_t = 1e30;
  for (std::uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      const glm::dvec3 a = mesh.positions[mesh.triangles[t].x];
      const glm::dvec3 e1 = glm::dvec3(mesh.positions[mesh.triangles[t].y]) - a;
      const glm::dvec3 e2 = glm::dvec3(mesh.positions[mesh.triangles[t].z]) - a;
      const glm::dvec3 dd(d), pv = glm::cross(dd, e2);
      const double det = glm::dot(e1, pv);
      if (std::fabs(det) < 1e-12) continue;
      const glm::dvec3 tv = glm::dvec3(p) - a;
      const double u = glm::dot(tv, pv) / det;
      if (u < 0.0 || u > 1.0) continue;
      const glm::dvec3 qv = glm::cross(tv, e1);
      const double v = glm::dot(dd, qv) / det;
      if (v < 0.0 || u + v > 1.0) continue;
      const double dist = glm::dot(e2, qv) / det;
      if (dist <= 1e-6 || dist >= best_t) continue;
      best_t = dist;
      best = {true, m, t, glm::vec3(glm::dvec3(p) + dd * dist)};
    }
  }
  return best;
}

// Two emissive quads of different size, radiance and distance (chosen by power, then uniformly
// by area) and one facing away from p (one-sided: never sampled from p). The density of a
// direction is pdf_triangle of the emitter it reaches, if that emitter faces p.
TEST(Lights, EmissiveTrianglesMatchTheirDensity) {
  Scene scene = floor_scene_with_lamps(glm::vec3(4.0f, 3.0f, 2.0f), glm::vec3(1.0f));
  Mesh big = make_quad({-0.8f, 1.5f, -0.4f}, {0.9f, 0, 0}, {0, 0, 0.6f});  // faces down
  big.material = 1;
  Mesh small = make_quad({1.2f, 0.4f, 0.2f}, {0, 0, 0.2f}, {0, 0.3f, 0});  // faces -x, p
  small.material = 2;
  Mesh away = make_quad({-1.5f, 0.4f, 0.2f}, {0, 0, 0.4f}, {0, 0.3f, 0});  // faces -x, away
  away.material = 2;
  scene.meshes.push_back(big);
  scene.meshes.push_back(small);
  scene.meshes.push_back(away);
  const Lights lights(scene);
  ASSERT_EQ(lights.emitter_count(), 3u);  // three quads, each one parallelogram
  ASSERT_EQ(lights.parallelogram_count(), 3u);
  const glm::vec3 p(0.1f, 0.3f, 0.1f);
  // Which way each emitter faces, from the test's own geometry.
  auto facing_p = [&](const TriangleHit& h) {
    const Mesh& mesh = scene.meshes[h.mesh];
    const glm::uvec3 t = mesh.triangles[h.triangle];
    const glm::vec3 n = glm::cross(mesh.positions[t.y] - mesh.positions[t.x],
                                   mesh.positions[t.z] - mesh.positions[t.x]);
    return glm::dot(n, p - h.point) > 0.0f;
  };
  ASSERT_TRUE(facing_p(first_hit(scene, p, glm::normalize(glm::vec3(-0.3f, 1.5f, -0.1f)))));
  ASSERT_FALSE(facing_p(first_hit(scene, p, glm::normalize(glm::vec3(-1.6f, 0.25f, 0.3f)))));
  const auto pdf = [&](const glm::vec3& d) {
    const TriangleHit h = first_hit(scene, p, d);
    if (!h.hit || !scene.materials[scene.meshes[h.mesh].material].is_emissive() || !facing_p(h))
      return 0.0;
    return double(lights.pdf_triangle(h.mesh, h.triangle, p, h.point, glm::vec3(0.0f)));
  };
  const LightSampler sampler{lights, p};
  // Each sample's pdf is the density pdf_triangle gives its direction.
  for (std::size_t i = 0; i < 2000; ++i) {
    std::mt19937 gen(static_cast<unsigned>(i));
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    LightSample s;
    if (!lights.sample(p, u(gen), u(gen), u(gen), s)) continue;
    const TriangleHit h = first_hit(scene, p, s.direction);
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(s.distance, glm::length(h.point - p), 1e-4f * s.distance);
    EXPECT_NEAR(s.pdf, pdf(s.direction), 1e-3 * s.pdf);
  }
  const auto right = test::chi_square_test(sampler, pdf, kSamples / 4, 40, 80, 32);
  EXPECT_GT(right.p_value, kAlpha) << right.describe();
  // The one facing away takes its power's share of the attempts and never yields a sample.
  EXPECT_NEAR(right.pdf_integral, right.sample_fraction, 5e-3) << right.describe();
  EXPECT_LT(right.sample_fraction, 0.95) << right.describe();
  const auto wrong = test::chi_square_test(
      sampler, [&](const glm::vec3& d) { return pdf(d) * 1.05; }, kSamples / 4, 40, 80, 12);
  EXPECT_LT(wrong.p_value, 1e-6) << wrong.describe();
}

// Emissive triangles that are not halves of a parallelogram are sampled one by one, uniformly
// in area (the square root of the barycentric draw): a kite's two triangles and a lone one,
// against the density pdf_triangle gives. Without this scene no test sampled a lone triangle
// since quads became parallelograms (docs/mutation-testing.md, `triangle-sample-nonuniform`).
TEST(Lights, LoneEmissiveTrianglesMatchTheirDensity) {
  Scene scene = floor_scene_with_lamps(glm::vec3(3.0f, 2.0f, 1.0f), glm::vec3(1.5f));
  Mesh kite;  // above p, facing down: corners 0-1-2 and 0-2-3, 3 off the parallelogram
  kite.positions = {
      {-0.6f, 1.4f, -0.5f}, {0.4f, 1.4f, -0.5f}, {0.4f, 1.4f, 0.3f}, {-0.6f, 1.4f, 0.6f}};
  kite.triangles = {{0, 1, 2}, {0, 2, 3}};
  kite.material = 1;
  Mesh lone;  // beside p, facing -x towards it, a long thin triangle
  lone.positions = {{1.1f, 0.1f, -0.6f}, {1.1f, 0.9f, 0.4f}, {1.1f, 0.2f, 0.5f}};
  lone.triangles = {{0, 2, 1}};
  lone.material = 2;
  scene.meshes.push_back(kite);
  scene.meshes.push_back(lone);
  const Lights lights(scene);
  ASSERT_EQ(lights.emitter_count(), 3u);
  ASSERT_EQ(lights.parallelogram_count(), 0u);
  const glm::vec3 p(0.1f, 0.3f, 0.1f);
  const auto pdf = [&](const glm::vec3& d) {
    const TriangleHit h = first_hit(scene, p, d);
    if (!h.hit || !scene.materials[scene.meshes[h.mesh].material].is_emissive()) return 0.0;
    return double(lights.pdf_triangle(h.mesh, h.triangle, p, h.point, glm::vec3(0.0f)));
  };
  // Every sample lands on the triangle whose density it reports.
  for (std::size_t i = 0; i < 2000; ++i) {
    std::mt19937 gen(static_cast<unsigned>(i));
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    LightSample s;
    ASSERT_TRUE(lights.sample(p, u(gen), u(gen), u(gen), s));
    EXPECT_NEAR(s.pdf, pdf(s.direction), 1e-3 * s.pdf);
  }
  const LightSampler sampler{lights, p};
  const auto right = test::chi_square_test(sampler, pdf, kSamples / 4, 40, 80, 32);
  EXPECT_GT(right.p_value, kAlpha) << right.describe();
  EXPECT_NEAR(right.pdf_integral, 1.0, 5e-3) << right.describe();
  const auto wrong = test::chi_square_test(
      sampler, [&](const glm::vec3& d) { return pdf(d) * 1.05; }, kSamples / 4, 40, 80, 12);
  EXPECT_LT(wrong.p_value, 1e-6) << wrong.describe();
}

// Two triangles of a mesh that make a parallelogram are one emitter (Lights::parallelogram_of),
// whichever diagonal they share and in whichever order their corners come; a kite, a second
// triangle facing the other way, or two triangles apart stay two emitters. The parallelogram's
// samples land on the quad, in its two halves equally often, each with the density
// pdf_triangle gives the direction through either triangle.
TEST(Lights, QuadLightsAreSampledAsOneParallelogram) {
  Material lamp;
  lamp.emission = glm::vec3(2.0f);
  const glm::vec3 c(-0.5f, 1.0f, -0.5f), e1(1.0f, 0.0f, 0.0f), e2(0.0f, 0.0f, 1.0f);
  // Corners 0..3 of a quad facing down (cross(e1, e2) = -y), or 3 moved off it (a kite).
  const auto lamp_scene = [&](std::vector<glm::uvec3> triangles, bool kite) {
    Scene scene = floor_scene();
    scene.materials.push_back(lamp);
    Mesh mesh;
    mesh.positions = {c, c + e1, c + e1 + e2, kite ? c + 1.3f * e2 : c + e2};
    mesh.triangles = std::move(triangles);
    mesh.material = 1;
    scene.meshes.push_back(mesh);
    return scene;
  };
  struct Case {
    const char* name;
    std::vector<glm::uvec3> triangles;
    bool kite;
    std::size_t emitters, parallelograms;
  };
  const std::vector<Case> cases = {
      {"diagonal 0-2", {{0, 1, 2}, {0, 2, 3}}, false, 1, 1},
      {"diagonal 1-3", {{0, 1, 3}, {1, 2, 3}}, false, 1, 1},
      {"corners rotated", {{2, 0, 1}, {3, 0, 2}}, false, 1, 1},
      {"kite", {{0, 1, 2}, {0, 2, 3}}, true, 2, 0},
      {"second faces up", {{0, 1, 2}, {0, 3, 2}}, false, 2, 0},
      {"no shared diagonal", {{0, 1, 2}, {1, 2, 1}}, false, 1, 0},  // the second has no area
  };
  const glm::vec3 p(0.1f, 0.2f, -0.05f);
  for (const Case& k : cases) {
    const Scene scene = lamp_scene(k.triangles, k.kite);
    const Lights lights(scene);
    EXPECT_EQ(lights.emitter_count(), k.emitters) << k.name;
    EXPECT_EQ(lights.parallelogram_count(), k.parallelograms) << k.name;
    if (k.parallelograms == 0) continue;
    // Samples on the quad (y = 1, inside its square), half in the first triangle (below the
    // diagonal it shares: z < x, or x + z < 0 for the diagonal 1-3), each with the density
    // pdf_triangle gives through either triangle.
    std::size_t in_first = 0, samples = 0;
    for (std::size_t i = 0; i < 20000; ++i) {
      shared::pg_rng rng = shared::pg_rng_make(3u, static_cast<shared::uint>(i), 0u, 0u, 5u);
      const float a = shared::pg_rng_next(&rng), b = shared::pg_rng_next(&rng),
                  d = shared::pg_rng_next(&rng);
      LightSample s;
      ASSERT_TRUE(lights.sample(p, a, b, d, s)) << k.name;
      const glm::vec3 y = p + s.direction * s.distance;
      ASSERT_NEAR(y.y, 1.0f, 1e-5f) << k.name;
      ASSERT_GE(y.x, -0.5f - 1e-5f);
      ASSERT_LE(y.x, 0.5f + 1e-5f);
      ASSERT_GE(y.z, -0.5f - 1e-5f);
      ASSERT_LE(y.z, 0.5f + 1e-5f);
      for (std::uint32_t t = 0; t < 2; ++t)
        ASSERT_NEAR(lights.pdf_triangle(1, t, p, y, glm::vec3(0, -1, 0)), s.pdf, 1e-4f * s.pdf)
            << k.name << " triangle " << t;
      ++samples;
      const bool first = k.triangles[0] == glm::uvec3(0, 1, 3) ? y.x + y.z < 0.0f : y.z < y.x;
      in_first += first ? 1 : 0;
    }
    // Binomial(20000, 1/2): 5 standard deviations are 354.
    EXPECT_NEAR(static_cast<double>(in_first), samples / 2.0, 354.0) << k.name;
  }
}

// A lamp whose alpha mask makes its left half transparent (a quad over the square x, z in
// [-0.5, 0.5] at y = 1, facing down, texture u = x + 0.5; eight texels in u, alpha 0 in the left
// four) emits only where a ray would find it: Embree's alpha filter lets rays through the
// transparent texels, so a light sample drawn there would add light that no BSDF-sampled ray
// can find, a bias (docs/robustness.md, "Alpha-masked emitters"). Its samples land only on the
// opaque half, about half of them are refused, and each keeps the density of the whole lamp,
// which pdf_triangle gives the hits; its two triangles stay two emitters.
TEST(Lights, MaskedEmittersDrawNoLightFromTransparentTexels) {
  Scene scene = floor_scene();
  scene.textures.push_back(test::left_half_transparent_mask());
  Material lamp;
  lamp.emission = glm::vec3(2.0f);
  lamp.alpha_texture = 0;
  lamp.alpha_cutoff = 0.5f;
  scene.materials.push_back(lamp);
  // make_quad's corners take uv (0, 0), (1, 0), (1, 1), (0, 1): u runs along e1 (+x).
  Mesh mesh = make_quad({-0.5f, 1.0f, -0.5f}, {1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f});
  ASSERT_FALSE(mesh.uvs.empty());
  mesh.material = 1;
  scene.meshes.push_back(mesh);
  Scene opaque = scene;
  opaque.materials[1].alpha_texture = -1;
  const Lights lights(scene), unmasked(opaque);
  EXPECT_EQ(lights.emitter_count(), 2u);
  EXPECT_EQ(lights.parallelogram_count(), 0u);
  EXPECT_EQ(unmasked.parallelogram_count(), 1u);

  const glm::vec3 p(0.1f, 0.2f, -0.05f);
  const std::size_t n = 40000;
  std::size_t accepted = 0;
  for (std::size_t i = 0; i < n; ++i) {
    shared::pg_rng rng = shared::pg_rng_make(5u, static_cast<shared::uint>(i), 0u, 0u, 5u);
    const float a = shared::pg_rng_next(&rng), b = shared::pg_rng_next(&rng),
                c = shared::pg_rng_next(&rng);
    LightSample s;
    if (!lights.sample(p, a, b, c, s)) continue;
    ++accepted;
    const glm::vec3 y = p + s.direction * s.distance;
    const float u = y.x + 0.5f;
    // Bilinear alpha: below the cutoff from a quarter texel short of the middle down to a
    // quarter texel from the wrap's edge (u = 1/16 .. 7/16), so no sample lands there.
    EXPECT_FALSE(u > 1.5f / 16.0f && u < 6.5f / 16.0f) << "sample " << i << " at u = " << u;
    EXPECT_GT(s.pdf, 0.0f);
    const float whole = unmasked.pdf_triangle(1, 0, p, y, glm::vec3(0, -1, 0));
    EXPECT_NEAR(s.pdf, whole, 1e-4f * whole) << "sample " << i;
    for (std::uint32_t t = 0; t < 2; ++t) {
      const float hit = lights.pdf_triangle(1, t, p, y, glm::vec3(0, -1, 0));
      EXPECT_NEAR(hit, s.pdf, 1e-4f * s.pdf) << "sample " << i << " triangle " << t;
    }
  }
  // Opaque where alpha >= 1/2: u in [7/16, 1) and [0, 1/16), half the lamp. Binomial(40000,
  // 1/2): 5 standard deviations are 500.
  EXPECT_NEAR(static_cast<double>(accepted), n / 2.0, 500.0);
}

// The sun's cone drawn at its rim: directions from u1 within 2^-15 of 1 (where rounding puts a
// few of them just outside the cone's float test) are either refused or carry a positive, finite
// density and radiance, with no sky behind the sun to give them one; before the refusal a rim
// sample reported density 0 with radiance 0, and next-event estimation divided 0 by 0 (a NaN
// pixel sample). Some are refused, so the sweep reaches the case.
TEST(Lights, SunConeSamplesAtItsRimHaveADensity) {
  for (const float radius_deg : {0.27f, 2.0f}) {
    Scene scene = floor_scene();
    scene.sun.enabled = true;
    scene.sun.direction = glm::normalize(glm::vec3(0.3f, 0.8f, 0.2f));
    scene.sun.irradiance = glm::vec3(3.0f);
    scene.sun.angular_radius = radius_deg * static_cast<float>(kPi / 180.0);
    const Lights lights(scene);
    std::size_t refused = 0, drawn = 0;
    for (int k = 1; k <= 512; ++k) {
      const float u1 = 1.0f - static_cast<float>(k) * 0x1p-24f;
      for (int j = 0; j < 256; ++j) {
        const float u2 = (static_cast<float>(j) + 0.5f) / 256.0f;
        LightSample s;
        ++drawn;
        if (!lights.sample(glm::vec3(0.0f, 0.5f, 0.0f), 0.5f, u1, u2, s)) {
          ++refused;
          continue;
        }
        ASSERT_TRUE(s.pdf > 0.0f && std::isfinite(s.pdf))
            << radius_deg << " deg, u1 = 1 - " << k << " * 2^-24, u2 = " << u2 << ": pdf " << s.pdf;
        ASSERT_TRUE(std::isfinite(s.radiance.x) && s.radiance.x > 0.0f) << radius_deg << " deg";
      }
    }
    std::printf("sun of %.2f degrees: %zu of %zu rim samples refused\n", radius_deg, refused,
                drawn);
    EXPECT_GT(refused, 0u) << radius_deg << " deg: the sweep did not reach the rim's case";
  }
}

// Distribution1D::sample_discrete on a fine uniform grid of u: each cell takes its share of the
// grid (its probability, within two grid steps for the two edges), reports weight / total as
// its probability and a remapped number in [0, 1), and an empty cell is never picked, also
// for u at every cell edge; empty cells at the ends and inside, sizes 1 to 40.
TEST(Distribution1D, PicksCellsInProportionAndNeverAnEmptyOne) {
  std::mt19937 gen(17);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  const int steps = 4096;
  for (std::size_t size : {1u, 2u, 3u, 8u, 9u, 40u}) {
    std::vector<float> weights(size);
    for (float& x : weights) x = u01(gen) < 0.25f ? 0.0f : u01(gen);
    weights.front() = 0.0f;
    if (size > 1) weights.back() = 0.0f;
    weights[size / 2] = 1.0f;  // at least one cell to sample
    const Distribution1D dist(weights);
    std::vector<double> cdf(size + 1, 0.0);
    for (std::size_t i = 0; i < size; ++i) cdf[i + 1] = cdf[i] + weights[i];
    std::vector<int> hits(size, 0);
    const auto pick = [&](float u) {
      float probability = -1.0f, remapped = -1.0f;
      const std::size_t cell = dist.sample_discrete(u, &probability, &remapped);
      EXPECT_LT(cell, size);
      EXPECT_GT(weights[cell], 0.0f) << "size " << size << " u " << u;
      EXPECT_EQ(probability, weights[cell] / dist.total()) << "size " << size;
      EXPECT_GE(remapped, 0.0f);
      EXPECT_LT(remapped, 1.0f);
      return cell;
    };
    for (int k = 0; k < steps; ++k) ++hits[pick(static_cast<float>(k) / steps)];
    for (std::size_t i = 0; i <= size; ++i)
      pick(std::min(static_cast<float>(cdf[i] / cdf.back()), 0.99999994f));
    for (std::size_t i = 0; i < size; ++i)
      EXPECT_NEAR(static_cast<double>(hits[i]) / steps, weights[i] / cdf.back(), 2.0 / steps)
          << "size " << size << " cell " << i;
  }
}

// Small distributions count the cells below u instead of searching (sample_discrete); either
// way the cell is the one the cumulative search gives (the first whose upper end exceeds u's
// target, stepped back over empty cells), for every size on both sides of the switch, with
// empty cells, for u on a grid, at every cell edge and next to it; and the remapped number,
// from sample_discrete or from remap alone, is u's place inside that cell.
TEST(Distribution1D, CountingPicksTheCellTheSearchPicks) {
  std::mt19937 gen(23);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  for (std::size_t size = 1; size <= 40; ++size) {
    std::vector<float> weights(size);
    for (float& x : weights) x = u01(gen) < 0.3f ? 0.0f : u01(gen);
    weights[size / 3] = 0.5f;
    const Distribution1D dist(weights);
    std::vector<double> cdf(size + 1, 0.0);
    for (std::size_t i = 0; i < size; ++i) cdf[i + 1] = cdf[i] + weights[i];
    const auto searched = [&](float u) {
      const double target = static_cast<double>(u) * cdf.back();
      std::size_t i = std::min<std::size_t>(
          static_cast<std::size_t>(std::upper_bound(cdf.begin() + 1, cdf.end(), target) -
                                   cdf.begin()) -
              1,
          size - 1);
      while (i > 0 && weights[i] == 0.0f) --i;
      return i;
    };
    std::vector<float> us;
    for (int k = 0; k <= 1000; ++k) us.push_back(std::min(k / 1000.0f, 0.99999994f));
    for (std::size_t i = 0; i <= size; ++i) {
      const float edge = std::min(static_cast<float>(cdf[i] / cdf.back()), 0.99999994f);
      us.insert(us.end(), {edge, std::nextafter(edge, 0.0f), std::nextafter(edge, 1.0f)});
    }
    for (float u : us) {
      if (!(u >= 0.0f && u < 1.0f)) continue;
      float remapped = -1.0f;
      const std::size_t cell = dist.sample_discrete(u, nullptr, &remapped);
      EXPECT_EQ(cell, searched(u)) << "size " << size << " u " << u;
      // u's place in its cell, as the search's caller would compute it, and remap's the same.
      const double target = static_cast<double>(u) * cdf.back();
      const double width = cdf[cell + 1] - cdf[cell];
      const float place = static_cast<float>(
          std::clamp(width > 0.0 ? (target - cdf[cell]) / width : 0.5, 0.0, 1.0 - 1e-7));
      EXPECT_EQ(remapped, place) << "size " << size << " u " << u;
      EXPECT_EQ(dist.remap(u, cell), remapped) << "size " << size << " u " << u;
    }
  }
}

// One cell with weight among empty ones (a scene with one kind of light, which takes a path of
// its own in sample_discrete): that cell with probability 1, and the remapped number is u itself
// (below the clamp at 1 - 1e-7 that every cell's remapping has), as the cumulative search gives.
TEST(Distribution1D, OneCellWithWeightKeepsUAsItsRemappedNumber) {
  for (std::size_t size : {1u, 3u, 7u}) {
    for (std::size_t cell = 0; cell < size; ++cell) {
      std::vector<float> weights(size, 0.0f);
      weights[cell] = 0.37f;
      const Distribution1D dist(weights);
      for (float u : {0.0f, 1e-30f, 0.25f, 0.3333333f, 0.5f, 0.9999f, 0.9999999f, 0.99999994f}) {
        float probability = -1.0f, remapped = -1.0f;
        EXPECT_EQ(dist.sample_discrete(u, &probability, &remapped), cell);
        EXPECT_EQ(probability, 1.0f);
        EXPECT_EQ(remapped, static_cast<float>(std::min(static_cast<double>(u), 1.0 - 1e-7)))
            << "u " << u;
        // What Lights::sample uses instead of asking, where triangles are the only lights.
        EXPECT_EQ(Distribution1D::remap_in_only_cell(u), remapped) << "u " << u;
      }
      EXPECT_EQ(dist.probability(cell), 1.0f);
      EXPECT_EQ(dist.probability(size), 0.0f);  // outside the distribution
    }
  }
  EXPECT_EQ(Distribution1D().probability(0), 0.0f);
}

// The sky's radiance and density are 0 without an environment and a sun of finite size, and
// Lights says so without looking (its has_sky_): no environment, a black constant one (which
// light selection never picks), a delta sun; a dim constant sky and a sun's cone are seen.
TEST(Lights, NoSkyWithoutAnEnvironmentOrASunsDisc) {
  Scene scene = floor_scene();
  Material light;
  light.emission = glm::vec3(3.0f);
  scene.materials.push_back(light);
  Mesh lamp = make_quad({-0.2f, 1.0f, -0.2f}, {0.0f, 0.0f, 0.4f}, {0.4f, 0.0f, 0.0f});
  lamp.material = 1;
  scene.meshes.push_back(lamp);
  const glm::vec3 up(0.0f, 1.0f, 0.0f), side = glm::normalize(glm::vec3(1.0f, 0.2f, 0.0f));
  const auto dark = [&](const Scene& s) {
    const Lights lights(s);
    for (const glm::vec3& d : {up, side, -up}) {
      EXPECT_EQ(lights.escaped_radiance(d), glm::vec3(0.0f));
      EXPECT_EQ(lights.pdf_escaped(d), 0.0f);
    }
  };
  dark(scene);
  Scene black = scene;
  black.environment.kind = Environment::Kind::Constant;
  black.environment.color = glm::vec3(0.0f);
  dark(black);
  Scene delta_sun = scene;
  delta_sun.sun.enabled = true;
  delta_sun.sun.direction = up;
  delta_sun.sun.irradiance = glm::vec3(2.0f);
  delta_sun.sun.angular_radius = 0.0f;
  dark(delta_sun);

  Scene dim = scene;
  dim.environment.kind = Environment::Kind::Constant;
  dim.environment.color = glm::vec3(1e-3f);
  const Lights dim_lights(dim);
  EXPECT_EQ(dim_lights.escaped_radiance(side), glm::vec3(1e-3f));
  EXPECT_GT(dim_lights.pdf_escaped(side), 0.0f);
  Scene sun = scene;
  sun.sun = delta_sun.sun;
  sun.sun.angular_radius = 0.1f;
  const Lights sun_lights(sun);
  EXPECT_GT(sun_lights.escaped_radiance(up).x, 0.0f);
  EXPECT_GT(sun_lights.pdf_escaped(up), 0.0f);
  EXPECT_EQ(sun_lights.escaped_radiance(side), glm::vec3(0.0f));
}

// The floor under an 8x4 environment map whose every texel is its own value, x + 8 y + 1 (row 0,
// 1-8, at the zenith), times `color`, turned by `rotation` about +y.
Scene floor_under_a_numbered_map(const glm::vec3& color, float rotation) {
  Scene scene = floor_scene();
  Texture map;
  map.width = 8;
  map.height = 4;
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x)
      map.texels.push_back(glm::vec4(glm::vec3(static_cast<float>(x + map.width * y + 1)), 1.0f));
  scene.textures.push_back(map);
  scene.environment.kind = Environment::Kind::Map;
  scene.environment.map_texture = 0;
  scene.environment.color = color;
  scene.environment.rotation = rotation;
  return scene;
}

// The map's top and bottom rows are the two poles: within half a texel of a pole the bilinear
// lookup blends along the row only, never with the other pole's row (a lookup that wraps
// vertically gave the zenith half of the nadir's radiance; docs/robustness.md, "The environment
// map's poles").
TEST(Lights, SkyNearAPoleIsThatPolesRow) {
  const Scene scene = floor_under_a_numbered_map(glm::vec3(1.0f), 0.0f);
  const Lights lights(scene);
  const double half_texel = 0.5 * kPi / scene.textures[0].height;
  for (const double from_pole : {0.0, 0.1 * half_texel, 0.9 * half_texel})
    for (int a = 0; a < 16; ++a) {
      const double phi = 2.0 * kPi * (a + 0.25) / 16.0;
      for (const bool zenith : {true, false}) {
        const double theta = zenith ? from_pole : kPi - from_pole;
        const glm::vec3 d(static_cast<float>(std::sin(theta) * std::cos(phi)),
                          static_cast<float>(std::cos(theta)),
                          static_cast<float>(std::sin(theta) * std::sin(phi)));
        const float row_first = zenith ? 1.0f : 25.0f, row_last = row_first + 7.0f;
        const float got = lights.escaped_radiance(d).x;
        EXPECT_GE(got, row_first - 1e-4f) << (zenith ? "zenith" : "nadir") << ", " << from_pole;
        EXPECT_LE(got, row_last + 1e-4f) << (zenith ? "zenith" : "nadir") << ", " << from_pole;
      }
    }
}

// What the sky looks like, not only how it is sampled (the chi-square tests above compare samples
// with densities derived from the same lookups, so an upside-down map, a map turned the wrong way
// or a wrong scale passes them): the radiance of the direction through each texel centre of an
// environment map is that texel times the scene's colour, with the map's top row at the zenith
// (+y), u = 0 towards +x and u growing towards +z, turned by `rotation` about +y
// (scenes/README.md, "environment"); and a sun of finite size gives a surface facing it its
// irradiance (the radiance over its cone, weighed by the cosine, integrated by quadrature).
TEST(Lights, SkyRadianceHasTheMapsOrientationAndTheSunsIrradiance) {
  for (const float rotation : {0.0f, 0.7f}) {
    const Scene scene = floor_under_a_numbered_map(glm::vec3(2.0f, 3.0f, 0.5f), rotation);
    const Texture& map = scene.textures[0];
    const Lights lights(scene);
    for (int y = 0; y < map.height; ++y)
      for (int x = 0; x < map.width; ++x) {
        const double theta = kPi * (y + 0.5) / map.height;                // from the zenith
        const double phi = 2.0 * kPi * (x + 0.5) / map.width + rotation;  // from +x towards +z
        const glm::vec3 d(static_cast<float>(std::sin(theta) * std::cos(phi)),
                          static_cast<float>(std::cos(theta)),
                          static_cast<float>(std::sin(theta) * std::sin(phi)));
        const glm::vec3 want =
            glm::vec3(static_cast<float>(x + map.width * y + 1)) * scene.environment.color;
        const glm::vec3 got = lights.escaped_radiance(d);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(got[c], want[c], 1e-3f * want[c])
              << "texel " << x << "," << y << ", rotation " << rotation << ", channel " << c;
      }
  }

  for (const float radius : {0.01f, 0.05f, 0.3f}) {
    Scene scene = floor_scene();
    scene.sun.enabled = true;
    scene.sun.direction = glm::normalize(glm::vec3(-0.5f, 0.6f, 0.3f));
    scene.sun.irradiance = glm::vec3(3.0f, 2.0f, 1.0f);
    scene.sun.angular_radius = radius;
    const Lights lights(scene);
    const glm::vec3 axis = scene.sun.direction;
    const shared::pg_frame frame = shared::pg_frame_from_normal(axis);
    // Midpoint rule in (angle from the axis, azimuth), out to just past the cone's edge.
    const int rings = 400, sectors = 64;
    const double outer = 1.02 * radius;
    glm::dvec3 irradiance(0.0);
    for (int i = 0; i < rings; ++i) {
      const double a = outer * (i + 0.5) / rings;
      for (int j = 0; j < sectors; ++j) {
        const double b = 2.0 * kPi * (j + 0.5) / sectors;
        const glm::vec3 d = glm::normalize(static_cast<float>(std::cos(a)) * axis +
                                           static_cast<float>(std::sin(a) * std::cos(b)) * frame.t +
                                           static_cast<float>(std::sin(a) * std::sin(b)) * frame.b);
        const double weight = std::cos(a) * std::sin(a) * (outer / rings) * (2.0 * kPi / sectors);
        irradiance += glm::dvec3(lights.escaped_radiance(d)) * weight;
      }
    }
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(irradiance[c], scene.sun.irradiance[c], 0.01 * scene.sun.irradiance[c])
          << "angular radius " << radius << ", channel " << c;
  }
}

// Distribution2D: samples fall in cells in proportion to their weights, and the density it
// reports integrates to one and equals weight / mean weight.
TEST(Distribution2D, SamplesInProportionToTheWeights) {
  const int w = 7, h = 5;
  std::vector<float> weights(w * h);
  std::mt19937 gen(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double total = 0.0;
  for (float& x : weights) total += x = u(gen) < 0.2f ? 0.0f : u(gen);
  const Distribution2D dist(weights, w, h);
  std::vector<double> counts(w * h, 0.0);
  const int n = 1000000;
  for (int i = 0; i < n; ++i) {
    float x = 0, y = 0, pdf = 0;
    dist.sample(u(gen), u(gen), x, y, pdf);
    const int cx = std::min(w - 1, int(x * w)), cy = std::min(h - 1, int(y * h));
    ASSERT_GT(weights[cy * w + cx], 0.0f) << "sampled a cell of weight 0";
    ASSERT_NEAR(pdf, weights[cy * w + cx] / (total / (w * h)), 1e-4 * pdf);
    ASSERT_EQ(pdf, dist.pdf(x, y));
    counts[cy * w + cx] += 1.0;
  }
  double chi2 = 0.0;
  int cells = 0;
  for (int i = 0; i < w * h; ++i) {
    if (weights[i] == 0.0f) continue;
    const double expected = n * weights[i] / total;
    chi2 += (counts[i] - expected) * (counts[i] - expected) / expected;
    ++cells;
  }
  const double p_value = test::incomplete_gamma_q(0.5 * (cells - 1), 0.5 * chi2);
  EXPECT_GT(p_value, 0.01) << "chi2 " << chi2 << " over " << cells << " cells";
}

}  // namespace
}  // namespace rtpg

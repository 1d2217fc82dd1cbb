// Statistical checks of the material model's sampler against its density (pbrt-v4
// bsdfs_test.cpp style), energy bounds, and reciprocity.
#include <gtest/gtest.h>

#include <random>

#include "shared/bsdf.h"
#include "shared/rng.h"
#include "support/chi_square.h"

using namespace rtpg::shared;

namespace {

struct Case {
  const char* name;
  pg_material material;
  float theta_o;  // degrees
};

std::vector<Case> cases() {
  std::vector<Case> c;
  c.push_back({"lambert", {float3(0.8f, 0.5f, 0.3f), 1.0f, 0.0f, 0.0f}, 30.0f});
  c.push_back({"lambert_grazing", {float3(0.8f), 1.0f, 0.0f, 0.0f}, 85.0f});
  c.push_back({"ggx_metal_r0.3", {float3(0.9f, 0.6f, 0.3f), 0.3f, 1.0f, 0.04f}, 40.0f});
  c.push_back({"ggx_metal_r0.6_grazing", {float3(0.9f), 0.6f, 1.0f, 0.04f}, 80.0f});
  c.push_back({"plastic_r0.4", {float3(0.2f, 0.4f, 0.8f), 0.4f, 0.0f, 0.04f}, 20.0f});
  c.push_back({"plastic_r0.8", {float3(0.7f), 0.8f, 0.0f, 0.5f}, 60.0f});
  // Normal incidence. (Roughness much below 0.3 needs a finer integration of the expected
  // counts than this test's fixed midpoint rule near the pole, not a different sampler.)
  c.push_back({"metal_r0.35_normal", {float3(0.95f), 0.35f, 1.0f, 0.04f}, 0.0f});
  return c;
}

float3 direction(float theta_deg, float phi_deg) {
  const float t = theta_deg * PG_PI / 180.0f, p = phi_deg * PG_PI / 180.0f;
  return float3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
}

}  // namespace

TEST(Bsdf, SamplerMatchesPdfChiSquare) {
  const auto all = cases();
  const double alpha = rtpg::test::sidak_alpha(0.01, static_cast<int>(all.size()));
  for (const Case& c : all) {
    const float3 wo = direction(c.theta_o, 25.0f);
    const pg_lobes lobes = pg_make_lobes(c.material, wo);
    const auto result = rtpg::test::chi_square_test(
        [&](std::size_t i, glm::vec3& d) {
          pg_rng rng = pg_rng_make(1u, static_cast<uint>(i), 0u, 0u, 9u);
          const float a = pg_rng_next(&rng), b = pg_rng_next(&rng), e = pg_rng_next(&rng);
          const pg_bsdf_sample_t s = pg_bsdf_sample(lobes, wo, a, b, e);
          if (s.pdf <= 0.0f) return false;
          d = s.wi;
          return true;
        },
        [&](const glm::vec3& wi) { return static_cast<double>(pg_bsdf_pdf(lobes, wo, wi)); },
        1000000, 40, 80, 12);
    EXPECT_GT(result.p_value, alpha) << c.name << ": " << result.describe();
    EXPECT_LE(result.pdf_integral, 1.0 + 2e-3) << c.name << ": " << result.describe();
    // The pdf integrates to the fraction of attempts that produce a direction.
    EXPECT_NEAR(result.pdf_integral, result.sample_fraction, 5e-3)
        << c.name << ": " << result.describe();
  }
}

TEST(Bsdf, AlbedoNeverExceedsOneAndIsReciprocal) {
  std::mt19937 gen(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const Case& c : cases()) {
    for (float theta : {0.0f, 30.0f, 60.0f, 85.0f}) {
      const float3 wo = direction(theta, 10.0f);
      const pg_lobes lobes = pg_make_lobes(c.material, wo);
      double sum = 0.0;
      const int n = 200000;
      for (int i = 0; i < n; ++i) {
        const pg_bsdf_sample_t s = pg_bsdf_sample(lobes, wo, u(gen), u(gen), u(gen));
        if (s.pdf <= 0.0f) continue;
        sum += pg_max3(pg_bsdf_eval(lobes, wo, s.wi)) * s.wi.z / s.pdf;
      }
      EXPECT_LE(sum / n, 1.01) << c.name << " theta " << theta;
    }
    // Reciprocity f(wo, wi) = f(wi, wo) of the model with lobes fixed (p_specular only
    // changes sampling, not the value).
    const pg_lobes lobes = pg_make_lobes(c.material, direction(30.0f, 0.0f));
    for (int i = 0; i < 100; ++i) {
      const float3 a = direction(80.0f * u(gen), 360.0f * u(gen));
      const float3 b = direction(80.0f * u(gen), 360.0f * u(gen));
      const float3 fab = pg_bsdf_eval(lobes, a, b), fba = pg_bsdf_eval(lobes, b, a);
      EXPECT_NEAR(fab.x, fba.x, 1e-4f * std::max(1.0f, fab.x)) << c.name;
    }
  }
}

TEST(Rng, DeterministicAndUniform) {
  pg_rng a = pg_rng_make(1, 2, 3, 4, 0), b = pg_rng_make(1, 2, 3, 4, 0),
         c = pg_rng_make(1, 2, 3, 5, 0);
  EXPECT_EQ(pg_rng_next_uint(&a), pg_rng_next_uint(&b));
  EXPECT_NE(pg_rng_next_uint(&a), pg_rng_next_uint(&c));
  // Mean and variance of many draws across pixels.
  double sum = 0.0, sum2 = 0.0;
  const int n = 1 << 20;
  for (int i = 0; i < n; ++i) {
    pg_rng r = pg_rng_make(0, static_cast<uint>(i), 0, 0, 0);
    const double x = pg_rng_next(&r);
    ASSERT_GE(x, 0.0);
    ASSERT_LT(x, 1.0);
    sum += x;
    sum2 += x * x;
  }
  EXPECT_NEAR(sum / n, 0.5, 5 * std::sqrt(1.0 / 12.0 / n));
  EXPECT_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12.0, 1e-3);
}

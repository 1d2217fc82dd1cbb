// Statistical checks of the material model's sampler against its density (pbrt-v4
// bsdfs_test.cpp style), energy bounds, and reciprocity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>

#include <glm/glm.hpp>

#include "shared/bsdf.h"
#include "shared/rng.h"
#include "support/chi_square.h"

using namespace rtpg::shared;

namespace {
constexpr double kPiD = 3.14159265358979323846;
}  // namespace

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

// Attempt i of the BSDF sampler as the chi-square test wants it (false: no direction).
std::function<bool(std::size_t, glm::vec3&)> bsdf_attempts(const pg_lobes& lobes, float3 wo,
                                                           uint seed) {
  return [lobes, wo, seed](std::size_t i, glm::vec3& d) {
    pg_rng rng = pg_rng_make(seed, static_cast<uint>(i), 0u, 0u, 9u);
    const float a = pg_rng_next(&rng), b = pg_rng_next(&rng), e = pg_rng_next(&rng);
    const pg_bsdf_sample_t s = pg_bsdf_sample(lobes, wo, a, b, e);
    if (s.pdf <= 0.0f) return false;
    d = s.wi;
    return true;
  };
}

}  // namespace

TEST(Bsdf, SamplerMatchesPdfChiSquare) {
  const auto all = cases();
  const double alpha = rtpg::test::sidak_alpha(0.01, static_cast<int>(all.size()));
  for (const Case& c : all) {
    const float3 wo = direction(c.theta_o, 25.0f);
    const pg_lobes lobes = pg_make_lobes(c.material, wo);
    const auto result = rtpg::test::chi_square_test(
        bsdf_attempts(lobes, wo, 1u),
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
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(fab[k], fba[k], 1e-4f * std::max(1.0f, fab[k])) << c.name << " channel " << k;
    }
  }
}

namespace {

// The material model written again from its references (bsdf.h: Walter et al. 2007, Heitz
// 2014, Schlick, Ashikhmin and Shirley 2000 eq. 5), in double and without bsdf.h, so that the
// checks below do not compare the code with itself.
struct TextbookMaterial {
  glm::dvec3 diffuse, f0;
  double alpha;
  bool coated;
  explicit TextbookMaterial(const pg_material& m) {
    const double metallic = std::clamp(double(m.metallic), 0.0, 1.0);
    const double spec = std::clamp(double(m.specular), 0.0, 1.0);
    const glm::dvec3 base(m.base_color);
    f0 = glm::mix(glm::dvec3(spec), base, metallic);
    diffuse = base * ((1.0 - metallic) * (1.0 - spec));
    const double r = std::max(double(m.roughness), double(PG_MIN_ROUGHNESS));
    alpha = r * r;
    coated = std::max(f0.x, std::max(f0.y, f0.z)) > 0.0;
  }
  double lambda(const glm::dvec3& w) const {
    const double tan2 = (1.0 - w.z * w.z) / (w.z * w.z);
    return 0.5 * (-1.0 + std::sqrt(1.0 + alpha * alpha * tan2));
  }
  glm::dvec3 fresnel(double c) const { return f0 + (1.0 - f0) * std::pow(1.0 - c, 5.0); }
  double d(const glm::dvec3& h) const {
    const double a2 = alpha * alpha, c2 = h.z * h.z;
    const double t = a2 * c2 + (1.0 - c2);
    return a2 / (kPiD * t * t);
  }
  glm::dvec3 diffuse_f(const glm::dvec3& wo, const glm::dvec3& wi) const {
    if (!coated) return diffuse / kPiD;
    return diffuse * (28.0 / (23.0 * kPiD)) * (1.0 - std::pow(1.0 - 0.5 * wi.z, 5.0)) *
           (1.0 - std::pow(1.0 - 0.5 * wo.z, 5.0));
  }
  glm::dvec3 specular_f(const glm::dvec3& wo, const glm::dvec3& wi) const {
    if (!coated) return glm::dvec3(0.0);
    const glm::dvec3 h = glm::normalize(wo + wi);
    const double g2 = 1.0 / (1.0 + lambda(wo) + lambda(wi));
    return fresnel(glm::dot(wi, h)) * (d(h) * g2 / (4.0 * wo.z * wi.z));
  }
  glm::dvec3 f(const glm::dvec3& wo, const glm::dvec3& wi) const {
    if (wo.z <= 0.0 || wi.z <= 0.0) return glm::dvec3(0.0);
    return diffuse_f(wo, wi) + specular_f(wo, wi);
  }
  // Directional albedo: the integral of f cos over wi by two midpoint rules that need no
  // sampler: the diffuse part over cosine-distributed directions, the specular part over
  // half-vectors distributed as D(h) cos(theta_h) (tan^2 theta_h = alpha^2 s / (1 - s)),
  // where f cos |d wi / d h| / (D cos theta_h) = F G2 (wo.h) / (cos_o cos theta_h) is smooth.
  glm::dvec3 albedo(const glm::dvec3& wo, int n) const {
    glm::dvec3 sum(0.0);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const double s = (a + 0.5) / n, phi = 2.0 * kPiD * (b + 0.5) / n;
        const double z = std::sqrt(1.0 - s), r = std::sqrt(s);
        const glm::dvec3 wi(r * std::cos(phi), r * std::sin(phi), z);
        sum += kPiD * diffuse_f(wo, wi) / double(n * n);
        if (!coated) continue;
        const double tan_t = alpha * std::sqrt(s / (1.0 - s));
        const double ct = 1.0 / std::sqrt(1.0 + tan_t * tan_t), st = tan_t * ct;
        const glm::dvec3 h(st * std::cos(phi), st * std::sin(phi), ct);
        const double oh = glm::dot(wo, h);
        const glm::dvec3 wr = 2.0 * oh * h - wo;
        if (oh <= 0.0 || wr.z <= 0.0) continue;
        const double g2 = 1.0 / (1.0 + lambda(wo) + lambda(wr));
        sum += fresnel(glm::dot(wr, h)) * (g2 * oh / (wo.z * ct)) / double(n * n);
      }
    return sum;
  }
};

glm::dvec3 to_d(const float3& v) {
  return glm::dvec3(v.x, v.y, v.z);
}

}  // namespace

// pg_bsdf_eval equals the textbook model on every channel, for random materials and
// directions (roughness from 0.1: below it D's float evaluation near the lobe's peak loses
// digits to cancellation, which is the float code's precision, not its formula).
TEST(Bsdf, EvalEqualsTheTextbookModelOnEveryChannel) {
  std::mt19937 gen(21);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double worst = 0.0;
  for (int m = 0; m < 200; ++m) {
    const pg_material mat{float3(u(gen), u(gen), u(gen)), 0.1f + 0.9f * u(gen),
                          u(gen) < 0.3f ? 1.0f : u(gen), u(gen) < 0.2f ? 0.0f : u(gen)};
    const TextbookMaterial book(mat);
    for (int k = 0; k < 50; ++k) {
      const float3 wo = direction(89.0f * u(gen), 360.0f * u(gen));
      const float3 wi = direction(89.0f * u(gen), 360.0f * u(gen));
      const pg_lobes lobes = pg_make_lobes(mat, wo);
      const float3 got = pg_bsdf_eval(lobes, wo, wi);
      const glm::dvec3 want = book.f(to_d(wo), to_d(wi));
      for (int c = 0; c < 3; ++c) {
        const double err = std::fabs(got[c] - want[c]) / std::max(want[c], 1e-3);
        worst = std::max(worst, err);
        ASSERT_LE(err, 1e-3) << "material " << m << " channel " << c << ": " << got[c] << " vs "
                             << want[c];
      }
    }
  }
  std::printf("pg_bsdf_eval vs textbook: largest relative difference %.2e\n", worst);
}

// The sampler's estimate of the directional albedo, mean of f cos / pdf over its own samples,
// equals the textbook albedo integrated without it, on every channel: a lobe that loses energy,
// or a pdf that is off, moves the estimate. Power: each estimate's standard error is below 0.4%
// of the albedo, and the same estimate with the pdf 5% high is rejected every time.
TEST(Bsdf, SampledAlbedoEqualsAnIndependentIntegral) {
  const auto all = cases();
  const double z = 4.5;  // two-sided 7e-6 per check; 84 checks: 6e-4 overall
  for (const Case& c : all) {
    const TextbookMaterial book(c.material);
    for (float theta : {0.0f, 30.0f, 60.0f, 85.0f}) {
      const float3 wo = direction(theta, 10.0f);
      const pg_lobes lobes = pg_make_lobes(c.material, wo);
      const glm::dvec3 integral = book.albedo(to_d(wo), 1024);
      // The midpoint rules' own error, from a coarser grid (4x fewer points; the cut where the
      // reflected direction crosses the horizon makes it converge as 1 / n only).
      const glm::dvec3 coarse = book.albedo(to_d(wo), 512);
      const int n = 400000;
      glm::dvec3 sum(0.0), sum2(0.0);
      for (int i = 0; i < n; ++i) {
        pg_rng rng = pg_rng_make(4u, static_cast<uint>(i), static_cast<uint>(theta), 0u, 9u);
        const float a = pg_rng_next(&rng), b = pg_rng_next(&rng), e = pg_rng_next(&rng);
        const pg_bsdf_sample_t s = pg_bsdf_sample(lobes, wo, a, b, e);
        if (!(s.pdf > 0.0f)) continue;
        const glm::dvec3 x = to_d(pg_bsdf_eval(lobes, wo, s.wi)) * (double(s.wi.z) / s.pdf);
        sum += x;
        sum2 += x * x;
      }
      for (int k = 0; k < 3; ++k) {
        const double mean = sum[k] / n;
        const double se = std::sqrt(std::max(sum2[k] / n - mean * mean, 0.0) / (n - 1));
        const double quadrature = std::fabs(integral[k] - coarse[k]);
        // Plus float rounding: Lambert's f cos / pdf is the albedo in every sample (no variance).
        const double bound = z * se + quadrature + 1e-6 * integral[k];
        SCOPED_TRACE(std::string(c.name) + " theta_o " + std::to_string(theta) + " channel " +
                     std::to_string(k) + ": sampled " + std::to_string(mean) + " +- " +
                     std::to_string(se) + ", integral " + std::to_string(integral[k]));
        EXPECT_LE(integral[k], 1.0 + 1e-3);
        EXPECT_LE(quadrature, 3e-3 * integral[k]);  // 2.3e-3 at most (metal_r0.6 at 85 degrees)
        EXPECT_LE(se, 4e-3 * integral[k]);
        EXPECT_LE(std::fabs(mean - integral[k]), bound);
        EXPECT_GT(std::fabs(mean / 1.05 - integral[k]), bound) << "a 5% pdf error would pass";
      }
    }
  }
}

// A smooth white metal keeps nearly all its energy (single-scattering GGX loses little below
// alpha 0.1; Kulla and Conty 2017), and no material creates energy.
TEST(Bsdf, SmoothMetalKeepsItsEnergy) {
  const pg_material mirror_like{float3(1.0f), 0.3f, 1.0f, 0.04f};
  const TextbookMaterial book(mirror_like);
  for (float theta : {0.0f, 30.0f, 60.0f}) {
    const glm::dvec3 e = book.albedo(to_d(direction(theta, 0.0f)), 512);
    EXPECT_GE(e.x, 0.97) << theta;
    EXPECT_LE(e.x, 1.0 + 1e-6) << theta;
  }
}

// The chi-square test has power: the BSDF sampler against a density 5% too high in its
// glossy lobe, or of a 10% rougher lobe, is rejected far below any reasonable level.
TEST(Bsdf, ChiSquareRejectsAWrongDensity) {
  const pg_material plastic{float3(0.2f, 0.4f, 0.8f), 0.4f, 0.0f, 0.04f};
  const float3 wo = direction(35.0f, 25.0f);
  const pg_lobes lobes = pg_make_lobes(plastic, wo);
  pg_lobes rougher = lobes;
  rougher.alpha *= 1.1f;
  const auto sample = bsdf_attempts(lobes, wo, 2u);
  const float3 mirror(-wo.x, -wo.y, wo.z);
  const auto five_percent = rtpg::test::chi_square_test(
      sample,
      [&](const glm::vec3& wi) {
        const double p = pg_bsdf_pdf(lobes, wo, wi);
        return dot(float3(wi.x, wi.y, wi.z), mirror) > 0.9f ? 1.05 * p : p;
      },
      1000000, 40, 80, 12);
  EXPECT_LT(five_percent.p_value, 1e-6) << five_percent.describe();
  const auto wider = rtpg::test::chi_square_test(
      sample, [&](const glm::vec3& wi) { return double(pg_bsdf_pdf(rougher, wo, wi)); }, 1000000,
      40, 80, 12);
  EXPECT_LT(wider.p_value, 1e-6) << wider.describe();
}

// The sharpest lobe (roughness 0.02, alpha 4e-4) evaluated in float32 near its peak, where
// d = sin^2 + a2 cos^2 is of the order of a2 = 1.6e-7: the density of a float half vector (and
// the BSDF's sampling density of a reflection near the mirror direction) agrees with the same
// formula in double precision on the same float inputs. Computing d as 1 - cos^2 (1 - a2), the
// difference of two numbers near 1, made D wrong by a factor of up to 4 here (and an fma, which
// OpenCL compilers may contract, moved it again: docs/design.md, "Floating point on other
// devices").
TEST(Bsdf, SharpGgxIsAccurateNearItsPeak) {
  const float alpha = PG_MIN_ROUGHNESS * PG_MIN_ROUGHNESS;
  const double a2 = double(alpha) * alpha;
  const auto exact_d = [&](double hx, double hy, double hz) {
    const double n2 = hx * hx + hy * hy + hz * hz;
    const double d = (hx * hx + hy * hy) / n2 + a2 * hz * hz / n2;
    return a2 / (kPiD * d * d);
  };
  double worst_d = 0.0, worst_pdf = 0.0;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j < 8; ++j) {
      const double theta = alpha * 0.1 * i, phi = 0.785 * j + 0.1;
      const float3 h(static_cast<float>(std::sin(theta) * std::cos(phi)),
                     static_cast<float>(std::sin(theta) * std::sin(phi)),
                     static_cast<float>(std::cos(theta)));
      const double d_error = pg_ggx_d(h, alpha) / exact_d(h.x, h.y, h.z) - 1.0;
      worst_d = std::max(worst_d, std::fabs(d_error));
      // A reflection theta away from the mirror direction of a view 30 degrees off the normal.
      const pg_material mirror{float3(1.0f), PG_MIN_ROUGHNESS, 1.0f, 0.04f};
      const float3 wo = direction(30.0f, 0.0f);
      const float3 wi =
          normalize(float3(static_cast<float>(-wo.x + std::sin(theta) * std::cos(phi)),
                           static_cast<float>(-wo.y + std::sin(theta) * std::sin(phi)), wo.z));
      const pg_lobes lobes = pg_make_lobes(mirror, wo);
      const double sx = double(wo.x) + wi.x, sy = double(wo.y) + wi.y, sz = double(wo.z) + wi.z;
      const double c2 = double(wo.z) * wo.z, t2 = (1.0 - c2) / c2;
      const double g1 = 1.0 / (1.0 + 0.5 * (-1.0 + std::sqrt(1.0 + a2 * t2)));
      const double pdf = lobes.p_specular * g1 * exact_d(sx, sy, sz) / (4.0 * wo.z);
      worst_pdf = std::max(worst_pdf, std::fabs(pg_bsdf_pdf(lobes, wo, wi) / pdf - 1.0));
    }
  EXPECT_LT(worst_d, 1e-5);
  // The pdf's own conditioning: wo + wi cancels to a few ulp of 1 against alpha = 4e-4.
  EXPECT_LT(worst_pdf, 2e-3);
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

// The chi-square helper itself (tests/support/chi_square.h): uniform directions on the upper
// hemisphere pass against their density; the same sampler with 0.3% of its directions on the
// lower hemisphere, where the density is 0, fails, though no single cell there gets more than
// the 1e-5 of the samples a cell at a zero-density edge may hold (the bound is on all such cells
// together); and the pool of the cells expecting few samples grows until it expects 5.
TEST(ChiSquareHelper, SamplesWhereTheDensityIsZeroFailTogether) {
  const std::size_t n = 1000000;
  const auto uniform_upper = [](std::size_t i, glm::vec3& d, bool leak) {
    pg_rng rng = pg_rng_make(91u, static_cast<unsigned>(i), 0u, 0u, 0u);
    const float u1 = pg_rng_next(&rng), u2 = pg_rng_next(&rng), u3 = pg_rng_next(&rng);
    const float z = u1, r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 6.2831853f * u2;
    d = glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
    if (leak && u3 < 0.003f) d.z = -d.z;
    return true;
  };
  const auto pdf = [](const glm::vec3& d) { return d.z > 0.0f ? 1.0 / 6.283185307179586 : 0.0; };
  const auto clean = rtpg::test::chi_square_test(
      [&](std::size_t i, glm::vec3& d) { return uniform_upper(i, d, false); }, pdf, n);
  EXPECT_GT(clean.p_value, 1e-3) << clean.describe();
  const auto leaky = rtpg::test::chi_square_test(
      [&](std::size_t i, glm::vec3& d) { return uniform_upper(i, d, true); }, pdf, n);
  EXPECT_LT(leaky.p_value, 1e-6) << leaky.describe();
}

// The guiding mixture's shared math (kernels/shared/pmm.h) on the host: its sampler against
// its density (chi-square, pbrt-v4 bsdfs_test.cpp style), recovery of known targets by the
// online EM step, robustness of the step against junk input, and the change of hemisphere
// frame used by reprojection. Properties only: no test pins an internal number of the EM step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rtpg/guiding_settings.h"
#include "shared/bsdf.h"
#include "shared/guiding_pixel.h"
#include "shared/mapping.h"
#include "shared/pmm.h"
#include "shared/pmm_train.h"
#include "shared/rng.h"
#include "support/chi_square.h"
#include "support/pmm_checks.h"

using namespace rtpg::shared;

namespace {

pg_kernel_settings default_params() {
  return rtpg::to_kernel_settings(rtpg::GuidingSettings{});
}

// A state whose model has mean (mx, my), raw covariance (sxx, syy, sxy) (before the model's
// regularisation), mixing weight pi = S0 / W and epoch count k (pmm.h: Sigma = S2/S0 - mu mu^T).
pg_pmm_state make_state(float mx, float my, float sxx, float syy, float sxy, float pi, float k,
                        float s0 = 1.0f) {
  pg_pmm_state s;
  s.s0 = float4(s0 / pi, s0, s0 * mx, s0 * my);
  s.s1 = float4(s0 * (sxx + mx * mx), s0 * (syy + my * my), s0 * (sxy + mx * my), k);
  return s;
}

float3 direction(float theta_deg, float phi_deg) {
  const float t = theta_deg * PG_PI / 180.0f, p = phi_deg * PG_PI / 180.0f;
  return float3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
}

// Sigma = L L^T of a model.
struct Cov {
  double xx, yy, xy;
};
Cov model_covariance(const pg_pmm_model& m) {
  return {double(m.l11) * m.l11, double(m.l21) * m.l21 + double(m.l22) * m.l22,
          double(m.l11) * m.l21};
}

using rtpg::test::model_is_sane;

constexpr double kPiD = 3.14159265358979323846;

// ---- sampler against density -------------------------------------------------------------

struct SamplerCase {
  std::string name;
  pg_pmm_state state;
  pg_material material;
  float3 wo;
  pg_kernel_settings params;
};

std::vector<SamplerCase> sampler_cases() {
  const pg_kernel_settings p = default_params();
  const pg_material lambert{float3(0.8f), 1.0f, 0.0f, 0.0f};
  const pg_material plastic{float3(0.3f, 0.5f, 0.7f), 0.5f, 0.0f, 0.04f};
  const pg_material metal{float3(0.9f, 0.7f, 0.4f), 0.3f, 1.0f, 0.04f};
  std::vector<SamplerCase> c;
  c.push_back({"central_isotropic", make_state(0.5f, 0.5f, 0.01f, 0.01f, 0.0f, 0.5f, 8.0f), lambert,
               direction(0.0f, 0.0f), p});
  c.push_back({"correlated_plastic", make_state(0.3f, 0.6f, 0.01f, 0.02f, 0.008f, 0.3f, 4.0f),
               plastic, direction(40.0f, 30.0f), p});
  // Raw correlation 0.9999: the model clamps it to max_correlation (0.95).
  c.push_back({"near_singular_clamped",
               make_state(0.45f, 0.55f, 0.02f, 0.02f, 0.019998f, 0.6f, 32.0f), lambert,
               direction(20.0f, 100.0f), p});
  // A thin ridge: correlation bound raised to 0.999, no prior (minor std 0.006 in the square).
  pg_kernel_settings ridge = p;
  ridge.max_correlation = 0.999f;
  ridge.sigma_prior = 0.0f;
  c.push_back({"near_singular_ridge", make_state(0.4f, 0.5f, 0.02f, 0.02f, -0.019999f, 0.7f, 32.0f),
               lambert, direction(10.0f, 0.0f), ridge});
  c.push_back({"mean_on_edge", make_state(0.5f, 0.0f, 0.01f, 0.005f, 0.0f, 0.5f, 8.0f), plastic,
               direction(30.0f, 200.0f), p});
  c.push_back({"mean_on_corner", make_state(1.0f, 1.0f, 0.02f, 0.02f, 0.005f, 0.5f, 8.0f), lambert,
               direction(50.0f, 45.0f), p});
  c.push_back({"mean_on_opposite_corner", make_state(0.0f, 0.0f, 0.03f, 0.01f, -0.01f, 0.8f, 2.0f),
               metal, direction(35.0f, 225.0f), p});
  // Raw variance 5 (clamped to 1 by the model): most of the Gaussian falls outside the square.
  c.push_back({"large_sigma", make_state(0.5f, 0.5f, 5.0f, 5.0f, 0.0f, 0.5f, 8.0f), lambert,
               direction(60.0f, 10.0f), p});
  c.push_back({"pi_at_max_clamp", make_state(0.6f, 0.4f, 0.008f, 0.01f, 0.002f, 1.0f, 16.0f),
               plastic, direction(25.0f, 300.0f), p});
  c.push_back({"pi_at_min_clamp", make_state(0.6f, 0.4f, 0.008f, 0.01f, 0.002f, 0.001f, 16.0f),
               plastic, direction(25.0f, 300.0f), p});
  // Zero raw covariance: the lobe is as narrow as the regularisation allows.
  c.push_back({"regularised_only", make_state(0.35f, 0.7f, 0.0f, 0.0f, 0.0f, 0.5f, 32.0f), lambert,
               direction(15.0f, 80.0f), p});
  c.push_back({"glossy_metal_grazing", make_state(0.7f, 0.3f, 0.01f, 0.01f, 0.0f, 0.5f, 12.0f),
               metal, direction(75.0f, 120.0f), p});
  c.push_back({"no_model_k0", pg_pmm_initial_state(), plastic, direction(45.0f, 0.0f), p});
  // Random configurations from a fixed seed.
  std::mt19937 gen(20240611);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 8; ++i) {
    const float mx = -0.05f + 1.1f * u(gen), my = -0.05f + 1.1f * u(gen);  // model clamps
    const float sx = 0.03f + 0.25f * u(gen), sy = 0.03f + 0.25f * u(gen);
    const float rho = -0.98f + 1.96f * u(gen);
    const float pi = 0.02f + 0.96f * u(gen);
    const pg_material m{float3(u(gen), u(gen), u(gen)), 0.3f + 0.7f * u(gen), u(gen),
                        u(gen) < 0.5f ? 0.04f : 0.0f};
    c.push_back({"random_" + std::to_string(i),
                 make_state(std::clamp(mx, 0.0f, 1.0f), std::clamp(my, 0.0f, 1.0f), sx * sx,
                            sy * sy, rho * sx * sy, pi, 1.0f + std::floor(31.0f * u(gen))),
                 m, direction(80.0f * u(gen), 360.0f * u(gen)), p});
  }
  return c;
}

}  // namespace

// Every produced direction must be distributed as pg_pmm_pdf says (a defective density: a
// Gaussian sample that leaves the square produces nothing). 1e6 attempts per case, cells
// pooled below 5 expected samples, each case at the Sidak-corrected level of an overall 0.01.
TEST(PmmSampler, MatchesPdfChiSquare) {
  const auto all = sampler_cases();
  ASSERT_GE(all.size(), 12u);
  const double alpha = rtpg::test::sidak_alpha(0.01, static_cast<int>(all.size()));
  const std::size_t n = 1000000;
  for (const SamplerCase& c : all) {
    const pg_pmm_model model = pg_pmm_model_from_state(c.state, c.params);
    ASSERT_TRUE(model_is_sane(model, c.params)) << c.name;
    const pg_lobes lobes = pg_make_lobes(c.material, c.wo);
    const auto result = rtpg::test::chi_square_test(
        [&](std::size_t i, glm::vec3& d) {
          pg_rng rng = pg_rng_make(17u, static_cast<uint>(i), 0u, 0u, 5u);
          const float xi = pg_rng_next(&rng), u1 = pg_rng_next(&rng), u2 = pg_rng_next(&rng);
          const pg_pmm_sample_t s = pg_pmm_sample(model, lobes, c.wo, xi, u1, u2);
          if (!(s.pdf > 0.0f)) return false;
          d = s.wi;
          return true;
        },
        [&](const glm::vec3& wi) {
          return static_cast<double>(pg_pmm_pdf(model, lobes, c.wo, wi));
        },
        n, 40, 80, 16);
    EXPECT_GT(result.p_value, alpha) << c.name << ": " << result.describe();
    // The density integrates to the probability that an attempt produces a direction. The
    // measured fraction is binomial: 5 standard deviations (two-sided 6e-7 per case) plus
    // 1e-3 for the midpoint quadrature of the expected counts (16x16 points per cell; the
    // measured differences are all within 2 standard deviations, at most 9e-4).
    const double f = result.sample_fraction;
    const double sd = std::sqrt(std::max(f * (1.0 - f), 1e-12) / static_cast<double>(n));
    EXPECT_NEAR(result.pdf_integral, f, 5.0 * sd + 1e-3) << c.name << ": " << result.describe();
    EXPECT_LE(result.pdf_integral, 1.0 + 2e-3) << c.name << ": " << result.describe();
  }
}

// Every produced sample carries the pdf that pg_pmm_pdf gives for its direction, and a valid
// strategy; the BSDF strategy is used exactly when the model does not exist or xi >= pi.
TEST(PmmSampler, ReportsItsOwnPdfAndStrategy) {
  for (const SamplerCase& c : sampler_cases()) {
    const pg_pmm_model model = pg_pmm_model_from_state(c.state, c.params);
    const pg_lobes lobes = pg_make_lobes(c.material, c.wo);
    for (uint i = 0; i < 20000; ++i) {
      pg_rng rng = pg_rng_make(3u, i, 0u, 0u, 5u);
      const float xi = pg_rng_next(&rng), u1 = pg_rng_next(&rng), u2 = pg_rng_next(&rng);
      const pg_pmm_sample_t s = pg_pmm_sample(model, lobes, c.wo, xi, u1, u2);
      const uint expected = model.valid && xi < model.pi ? PG_STRATEGY_GUIDE : PG_STRATEGY_BSDF;
      ASSERT_EQ(s.strategy, expected) << c.name;
      ASSERT_GE(s.pdf, 0.0f) << c.name;
      if (s.pdf > 0.0f) {
        ASSERT_NEAR(length(s.wi), 1.0f, 1e-5f) << c.name;
        ASSERT_GT(s.wi.z, 0.0f) << c.name;
        // The density next-event MIS uses for the same direction.
        ASSERT_EQ(s.pdf, pg_pmm_pdf(model, lobes, c.wo, s.wi)) << c.name;
        // And the mixture of eq. 2 computed here from Sigma = L L^T (its inverse and
        // determinant, not pmm.h's triangular solve), in double: pi N(u; mu, Sigma) / (2 pi)
        // (the equal-area map's Jacobian, Mapping.JacobianIsTwoPiEverywhere) + (1 - pi) f_pdf.
        double mixture =
            (1.0 - (model.valid ? model.pi : 0.0)) * double(pg_bsdf_pdf(lobes, c.wo, s.wi));
        if (model.valid) {
          const Cov cov = model_covariance(model);
          const double det = cov.xx * cov.yy - cov.xy * cov.xy;
          const float2 u = pg_hemisphere_to_square(s.wi);
          const double dx = u.x - double(model.mx), dy = u.y - double(model.my);
          const double q = (cov.yy * dx * dx - 2.0 * cov.xy * dx * dy + cov.xx * dy * dy) / det;
          const double gaussian = std::exp(-0.5 * q) / (2.0 * kPiD * std::sqrt(det));
          mixture += model.pi * gaussian / (2.0 * kPiD);
        }
        ASSERT_NEAR(s.pdf, mixture, 1e-4 * mixture) << c.name;
      }
    }
  }
}

// The chi-square test has power: the same sampler against the density of a model whose mean is
// off by 0.02 in the square (a sixth of its standard deviation), or whose correlation has the
// wrong sign, is rejected far below any reasonable level.
TEST(PmmSampler, ChiSquareRejectsAWrongDensity) {
  const pg_kernel_settings p = default_params();
  const pg_material plastic{float3(0.3f, 0.5f, 0.7f), 0.5f, 0.0f, 0.04f};
  const float3 wo = direction(40.0f, 30.0f);
  const pg_lobes lobes = pg_make_lobes(plastic, wo);
  const pg_pmm_model model =
      pg_pmm_model_from_state(make_state(0.3f, 0.6f, 0.01f, 0.02f, 0.008f, 0.5f, 4.0f), p);
  pg_pmm_model shifted = model, flipped = model;
  shifted.mx += 0.02f;
  flipped.l21 = -flipped.l21;
  for (const pg_pmm_model& wrong : {shifted, flipped}) {
    const auto result = rtpg::test::chi_square_test(
        [&](std::size_t i, glm::vec3& d) {
          pg_rng rng = pg_rng_make(18u, static_cast<uint>(i), 0u, 0u, 5u);
          const float xi = pg_rng_next(&rng), u1 = pg_rng_next(&rng), u2 = pg_rng_next(&rng);
          const pg_pmm_sample_t s = pg_pmm_sample(model, lobes, wo, xi, u1, u2);
          if (!(s.pdf > 0.0f)) return false;
          d = s.wi;
          return true;
        },
        [&](const glm::vec3& wi) { return static_cast<double>(pg_pmm_pdf(wrong, lobes, wo, wi)); },
        1000000, 40, 80, 16);
    EXPECT_LT(result.p_value, 1e-6) << result.describe();
  }
}

// ---- EM recovery ---------------------------------------------------------------------------

namespace {

// A Gaussian density over the plane of the square.
struct Gauss2 {
  double mx, my, sxx, syy, sxy;
  double operator()(double x, double y) const {
    const double det = sxx * syy - sxy * sxy;
    const double dx = x - mx, dy = y - my;
    const double q = (syy * dx * dx - 2.0 * sxy * dx * dy + sxx * dy * dy) / det;
    return std::exp(-0.5 * q) / (2.0 * 3.14159265358979323846 * std::sqrt(det));
  }
};

// Runs `epochs` training steps (pg_pmm_train: the E-step passes and M-step that train.cl runs)
// of `per_epoch` samples each from the uniform density on the square (solid-angle density
// 1/(2 pi)), weighted by a = target / proposal with `target` a density over solid angle, as
// train.cl does for VPLs.
template <typename Target>
pg_pmm_state run_em(const pg_kernel_settings& p, const pg_lobes& lobes, float3 wo,
                    const Target& target, int epochs, int per_epoch, uint seed) {
  pg_pmm_state s = pg_pmm_initial_state();
  std::vector<float4> samples;
  // The proposal's density over solid angle: uniform on the square, Jacobian 2 pi.
  const std::vector<float> densities(static_cast<std::size_t>(per_epoch),
                                     static_cast<float>(0.5 / 3.14159265358979323846));
  for (int e = 0; e < epochs; ++e) {
    samples.clear();
    for (int j = 0; j < per_epoch; ++j) {
      pg_rng rng = pg_rng_make(seed, static_cast<uint>(j), static_cast<uint>(e), 0u, 7u);
      const float2 u(pg_rng_next(&rng), pg_rng_next(&rng));
      const float3 wi = pg_square_to_hemisphere(u);
      if (!(wi.z > 0.0f)) continue;
      const float a = static_cast<float>(target(u, wi) * 2.0 * 3.14159265358979323846);
      samples.push_back(float4(a, u.x, u.y, pg_bsdf_pdf(lobes, wo, wi)));
    }
    int updated = 0;
    s = pg_pmm_train(s, samples.data(), densities.data(), static_cast<int>(samples.size()), p,
                     static_cast<float>(per_epoch), p.em_passes, &updated);
  }
  return s;
}

}  // namespace

// Target: one Gaussian in the square (6 standard deviations from every edge, so its mass
// inside the square is 1 - 1e-9). Without the prior, the model must find its mean and
// covariance. Tolerances: the state averages about k_max = 32 epochs of 2000 uniform samples,
// of which about 2% land within 2 sigma of the lobe: ~1300 effective samples give a standard
// error of the mean of sigma/36 = 0.002 and of each covariance entry about 4%; the lobe's far
// tails (beyond ~2.5 sigma) are partly explained by the BSDF lobe at pi = pi_max, which
// shrinks Sigma by a few percent. Hence 0.008 on the mean and 15% on Sigma (plus sigma_eps).
TEST(PmmEm, RecoversAGaussianTarget) {
  rtpg::GuidingSettings settings;
  settings.sigma_prior = 0.0f;
  settings.pi_max = 0.95f;  // the EM's own fit: the Gaussian may explain almost everything
  const pg_kernel_settings p = rtpg::to_kernel_settings(settings);
  const pg_material lambert{float3(0.8f), 1.0f, 0.0f, 0.0f};
  const float3 wo = direction(30.0f, 0.0f);
  const pg_lobes lobes = pg_make_lobes(lambert, wo);
  const Gauss2 truth[] = {{0.4, 0.6, 0.004, 0.003, 0.0015},
                          {0.62, 0.35, 0.002, 0.005, -0.002},
                          {0.3, 0.3, 0.0025, 0.0025, 0.0}};
  uint seed = 100;
  for (const Gauss2& g : truth) {
    const auto target = [&](float2 u, float3) {
      return g(u.x, u.y) / (2.0 * 3.14159265358979323846);
    };
    const pg_pmm_state s = run_em(p, lobes, wo, target, 300, 2000, seed++);
    ASSERT_TRUE(pg_pmm_state_finite(s));
    const pg_pmm_model m = pg_pmm_model_from_state(s, p);
    ASSERT_TRUE(m.valid);
    EXPECT_NEAR(m.mx, g.mx, 0.008) << "mu.x";
    EXPECT_NEAR(m.my, g.my, 0.008) << "mu.y";
    const Cov c = model_covariance(m);
    const double scale = std::sqrt(g.sxx * g.syy);
    EXPECT_NEAR(c.xx, g.sxx + p.sigma_eps, 0.15 * g.sxx) << "Sigma_xx";
    EXPECT_NEAR(c.yy, g.syy + p.sigma_eps, 0.15 * g.syy) << "Sigma_yy";
    EXPECT_NEAR(c.xy, g.sxy, 0.15 * scale) << "Sigma_xy";
    // A pure Gaussian target: the Gaussian explains (almost) everything, pi at its upper clamp.
    EXPECT_NEAR(m.pi, p.pi_max, 0.03);
  }
}

namespace {

// The first bounce's second moment M(pi) = integral of E[F^2] / D over the hemisphere for the
// model m at mixing weight pi (midpoint rule on a 300x300 grid of the square, whose map to the
// hemisphere has the constant Jacobian 2 pi), and the pi in [pi_min, pi_max] that minimises it
// (a grid of 0.0025).
template <typename SecondMoment>
double best_mixing_weight(const pg_pmm_model& m, const pg_kernel_settings& p, const pg_lobes& lobes,
                          float3 wo, const SecondMoment& f2_of) {
  constexpr int kCells = 300;
  std::vector<double> f2, gauss, bsdf;
  for (int iy = 0; iy < kCells; ++iy)
    for (int ix = 0; ix < kCells; ++ix) {
      const float2 u((ix + 0.5f) / kCells, (iy + 0.5f) / kCells);
      const float3 wi = pg_square_to_hemisphere(u);
      if (!(wi.z > 0.0f)) continue;
      f2.push_back(f2_of(u, wi));
      gauss.push_back(pg_pmm_gaussian_pdf(m, u) / (2.0 * 3.14159265358979323846));
      bsdf.push_back(pg_bsdf_pdf(lobes, wo, wi));
    }
  double best = p.pi_min, best_moment = std::numeric_limits<double>::infinity();
  for (double pi = p.pi_min; pi <= p.pi_max + 1e-9; pi += 0.0025) {
    double moment = 0.0;
    for (std::size_t j = 0; j < f2.size(); ++j)
      moment += f2[j] / (pi * gauss[j] + (1.0 - pi) * bsdf[j]);
    if (moment < best_moment) {
      best_moment = moment;
      best = pi;
    }
  }
  return best;
}

// A noise factor of mean 1 that is a function of the sample's point: 20 with probability 1/20,
// else 0 (a hash of the point's bits), so that run_em's targets can be one-path estimates with
// fireflies. Its second moment is 20.
double firefly(float2 u) {
  std::uint32_t x = 0, y = 0;
  std::memcpy(&x, &u.x, 4);
  std::memcpy(&y, &u.y, 4);
  std::uint32_t h = x * 2654435761u ^ (y + 0x9e3779b9u) * 2246822519u;
  h ^= h >> 15;
  h *= 2246822519u;
  h ^= h >> 13;
  return h % 20u == 0u ? 20.0 : 0.0;
}

}  // namespace

// The variance-aware mixing weight (pi_learning; pmm.h, pg_pmm_update): trained on samples of a
// target, the running pi settles where the first bounce's second moment is smallest for the
// lobe that EM fitted, found here by quadrature. Without noise it agrees with EM's pi: at the
// lower clamp where the BSDF alone follows the target (guiding gets out of the way), at the
// upper clamp for a narrow lobe that the BSDF misses. With fireflies (one-path estimates whose
// second moment is 20x their squared mean) the best weight is far above EM's: fireflies in the
// lobe raise it where EM sees only the mean (pi ~ the lobe's 10% share), and fireflies outside
// the lobe keep re-seeding EM's model (pi back to pi_init) while the lobe still deserves 0.3.
// Tolerance 0.05: the running pi averages Newton steps of about k_max = 32 epochs of 2000
// samples, each clamped to [pi_min, pi_max], so next to a clamp the noisy steps average a
// little inside it; measured: 0.000, 0.000, 0.012, 0.039 (the last at the upper clamp).
TEST(PmmEm, LearnedMixingWeightMinimisesTheSecondMoment) {
  rtpg::GuidingSettings settings;
  settings.pi_learning = 1;
  const pg_kernel_settings learned = rtpg::to_kernel_settings(settings);
  settings.pi_learning = 0;
  const pg_kernel_settings em = rtpg::to_kernel_settings(settings);
  const pg_material lambert{float3(0.8f), 1.0f, 0.0f, 0.0f};
  const float3 wo = direction(30.0f, 0.0f);
  const pg_lobes lobes = pg_make_lobes(lambert, wo);
  const double two_pi = 2.0 * 3.14159265358979323846;
  const Gauss2 narrow{0.7, 0.35, 0.002, 0.002, 0.0};
  const auto lobe = [&](float2 u) { return narrow(u.x, u.y) / two_pi; };
  const auto bsdf = [&](float3 wi) { return double(pg_bsdf_pdf(lobes, wo, wi)); };
  struct Case {
    const char* name;
    bool em_at_best;                               // EM's own pi is the best one too
    std::function<double(float2, float3)> target;  // one sample's F
    std::function<double(float2, float3)> f2;      // E[F^2]
  };
  const Case cases[] = {
      {"Lambertian", true, [&](float2, float3 wi) { return bsdf(wi); },
       [&](float2, float3 wi) { return bsdf(wi) * bsdf(wi); }},
      {"one narrow lobe", true, [&](float2 u, float3) { return lobe(u); },
       [&](float2 u, float3) { return lobe(u) * lobe(u); }},
      {"fireflies outside the lobe", false,
       [&](float2 u, float3 wi) { return 0.5 * lobe(u) + 0.5 * bsdf(wi) * firefly(u); },
       [&](float2 u, float3 wi) {
         const double g = 0.5 * lobe(u), b = 0.5 * bsdf(wi);
         return g * g + 2.0 * g * b + 20.0 * b * b;
       }},
      {"fireflies in the lobe", false,
       [&](float2 u, float3 wi) { return 0.1 * lobe(u) * firefly(u) + 0.9 * bsdf(wi); },
       [&](float2 u, float3 wi) {
         const double g = 0.1 * lobe(u), b = 0.9 * bsdf(wi);
         return 20.0 * g * g + 2.0 * g * b + b * b;
       }},
  };
  uint seed = 300;
  for (const Case& c : cases) {
    const pg_pmm_state s_learned = run_em(learned, lobes, wo, c.target, 300, 2000, seed);
    const pg_pmm_state s_em = run_em(em, lobes, wo, c.target, 300, 2000, seed++);
    const pg_pmm_model m = pg_pmm_model_from_state(s_learned, learned);
    const pg_pmm_model m_em = pg_pmm_model_from_state(s_em, em);
    ASSERT_TRUE(m.valid && m_em.valid) << c.name;
    const double best = best_mixing_weight(m, learned, lobes, wo, c.f2);
    EXPECT_NEAR(m.pi, best, 0.05) << c.name << " (EM's pi " << m_em.pi << ")";
    if (c.em_at_best) {
      EXPECT_NEAR(m_em.pi, best, 0.03) << c.name;
    } else {
      EXPECT_GT(best - m_em.pi, 0.2) << c.name << " (EM's pi " << m_em.pi << ")";
    }
  }
}

// Target: w * Gaussian / (2 pi) + (1 - w) * p_bsdf, a member of the model's family. EM's fixed
// point is then the truth, and pi = E[a gamma] / E[a] estimates w, the Gaussian's share of the
// target. This needs a BSDF density that integrates to 1 over the hemisphere (Lambert, and a
// rough plastic whose GGX part loses ~1% below the horizon): with a lobe that loses mass there
// (a glossy metal at 50%), pi estimates the share w / (w + (1 - w) P_valid) instead. The prior
// variance is off (sigma_prior = 0): it widens the lobe so that it claims some of the BSDF's
// mass (+0.01 to +0.03 on pi measured at the default). 1000 epochs: the step size's floor
// 1/(k_max + 1) makes each epoch a 1/33 step towards the EM update (several E-step passes do
// not change that), which converges slowly when the Gaussian's share is small (at w = 0.1,
// 300 epochs still left pi = 0.123-0.127 and Sigma 2.3x too wide with 1 or 3 passes; 1000
// epochs give pi = 0.105-0.108). Tolerance 0.03: measured deviations are 0.0-0.013
// (the state averages ~k_max = 32 epochs of 2000 samples; the Monte Carlo standard deviation
// of pi is about 0.003).
TEST(PmmEm, MixingWeightConvergesToTheTargetsShare) {
  rtpg::GuidingSettings settings;
  settings.sigma_prior = 0.0f;
  settings.pi_max = 0.95f;  // the EM's own estimate of the share, not the renderer's clamp
  const pg_kernel_settings p = rtpg::to_kernel_settings(settings);
  struct Case {
    float w;
    pg_material material;
    float3 wo;
  };
  const Case cases[] = {{0.3f, {float3(0.8f), 1.0f, 0.0f, 0.0f}, direction(30.0f, 0.0f)},
                        {0.7f, {float3(0.8f), 1.0f, 0.0f, 0.0f}, direction(0.0f, 0.0f)},
                        {0.1f, {float3(0.8f), 1.0f, 0.0f, 0.0f}, direction(60.0f, 90.0f)},
                        {0.5f, {float3(0.5f), 0.5f, 0.0f, 0.04f}, direction(40.0f, 180.0f)}};
  const Gauss2 g{0.65, 0.4, 0.003, 0.003, 0.001};
  uint seed = 200;
  for (const Case& c : cases) {
    const pg_lobes lobes = pg_make_lobes(c.material, c.wo);
    const auto target = [&](float2 u, float3 wi) {
      return c.w * g(u.x, u.y) / (2.0 * 3.14159265358979323846) +
             (1.0 - c.w) * static_cast<double>(pg_bsdf_pdf(lobes, c.wo, wi));
    };
    const pg_pmm_state s = run_em(p, lobes, c.wo, target, 1000, 2000, seed++);
    const pg_pmm_model m = pg_pmm_model_from_state(s, p);
    ASSERT_TRUE(m.valid) << c.w;
    EXPECT_NEAR(m.pi, c.w, 0.03) << "w=" << c.w;
    EXPECT_NEAR(m.mx, g.mx, 0.008) << "w=" << c.w;
    EXPECT_NEAR(m.my, g.my, 0.008) << "w=" << c.w;
  }
}

// ---- adversarial input ---------------------------------------------------------------------

namespace {

pg_pmm_state update_with(const pg_pmm_state& s, const pg_kernel_settings& p,
                         const std::vector<std::pair<float, float2>>& samples, int* updated) {
  const pg_pmm_model m = pg_pmm_model_from_state(s, p);
  const pg_lobes lobes = pg_make_lobes({float3(0.8f), 1.0f, 0.0f, 0.0f}, float3(0, 0, 1));
  pg_pmm_batch b = pg_pmm_batch_empty();
  for (const auto& [a, u] : samples)
    b = pg_pmm_batch_add_terms(b, m, pg_pmm_e_terms_of(m), p, a, u,
                               pg_bsdf_pdf(lobes, float3(0, 0, 1), pg_square_to_hemisphere(u)),
                               0.0f, s.s0.x);
  return pg_pmm_update(s, b, p, static_cast<float>(samples.size()), updated);
}

bool same_state(const pg_pmm_state& a, const pg_pmm_state& b) {
  return a.s0 == b.s0 && a.s1 == b.s1;
}

}  // namespace

// A batch made only of unusable weights (zero, NaN, +-Inf, negative, above max_weight) must
// leave the state as it was, whether or not a model exists.
TEST(PmmEm, UnusableWeightsLeaveTheStateUnchanged) {
  const pg_kernel_settings p = default_params();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const float bad[] = {0.0f, nan, inf, -inf, -1.0f, p.max_weight * 2.0f, 3e38f};
  for (const pg_pmm_state& s0 :
       {pg_pmm_initial_state(), make_state(0.4f, 0.5f, 0.01f, 0.02f, 0.0f, 0.5f, 7.0f)}) {
    for (float a : bad) {
      std::vector<std::pair<float, float2>> batch;
      for (int i = 0; i < 20; ++i) batch.push_back({a, float2(0.05f * i, 1.0f - 0.05f * i)});
      int updated = 1;
      const pg_pmm_state s = update_with(s0, p, batch, &updated);
      EXPECT_EQ(updated, 0) << "a=" << a;
      EXPECT_TRUE(same_state(s, s0)) << "a=" << a;
    }
    // An empty batch too.
    int updated = 1;
    EXPECT_TRUE(same_state(update_with(s0, p, {}, &updated), s0));
    EXPECT_EQ(updated, 0);
  }
}

// A batch whose lit samples all lie far from a mature, narrow lobe gives the Gaussian nothing (its
// density underflows to 0 there). Stepwise EM still takes the step: S0 and the Gaussian's moments
// shrink together, so the lobe's mean and covariance stay while pi falls, and a lobe that no
// longer sees light fades. Skipping such batches froze the model, pi included, for good (a
// reprojected lobe pointing where the light was, a light that moved).
TEST(PmmEm, ABatchThatGivesTheGaussianNothingLowersPiAndKeepsTheLobe) {
  for (const int pi_learning : {0, 1}) {
    SCOPED_TRACE("pi_learning " + std::to_string(pi_learning));
    rtpg::GuidingSettings settings;
    settings.pi_learning = pi_learning;
    const pg_kernel_settings p = rtpg::to_kernel_settings(settings);
    const pg_pmm_state start = make_state(0.8f, 0.5f, 2e-4f, 2e-4f, 0.0f, 0.5f, 32.0f);
    // One lit sample 0.7 of the square away (about 17 standard deviations), four dark ones.
    const std::vector<std::pair<float, float2>> batch = {{10.0f, float2(0.1f, 0.5f)},
                                                         {0.0f, float2(0.2f, 0.2f)},
                                                         {0.0f, float2(0.3f, 0.7f)},
                                                         {0.0f, float2(0.6f, 0.1f)},
                                                         {0.0f, float2(0.9f, 0.9f)}};
    pg_pmm_state s = start;
    int updated = 0;
    s = update_with(s, p, batch, &updated);
    EXPECT_EQ(updated, 1);
    const pg_pmm_model after = pg_pmm_model_from_state(s, p);
    ASSERT_TRUE(after.valid);
    // The model of the start's statistics at the step's new age (the covariance prior follows
    // the age): the same mean and covariance.
    pg_pmm_state aged = start;
    aged.s1.w = s.s1.w;
    const pg_pmm_model before = pg_pmm_model_from_state(aged, p);
    ASSERT_TRUE(before.valid);
    EXPECT_GT(s.s1.w, start.s1.w - 0.5f);  // an update, not a re-seed (k 0 or 1)
    EXPECT_NEAR(after.mx, before.mx, 1e-6f);
    EXPECT_NEAR(after.my, before.my, 1e-6f);
    EXPECT_NEAR(after.l11, before.l11, 1e-5f * before.l11);
    EXPECT_NEAR(after.l21, before.l21, 1e-5f);
    EXPECT_NEAR(after.l22, before.l22, 1e-5f * before.l22);
    EXPECT_LT(after.pi, pg_pmm_model_from_state(start, p).pi);
    for (int step = 1; step < 100; ++step) s = update_with(s, p, batch, &updated);
    EXPECT_LT(pg_pmm_model_from_state(s, p).pi, 0.25f) << "the lobe kept its weight";
  }
}

// pg_pmm_batch_add_terms documents that NaN, negative and absurd weights are dropped: mixed into a
// good batch they change nothing (compared to the good batch alone, up to float rounding).
TEST(PmmEm, UnusableWeightsMixedIntoAGoodBatchAreDropped) {
  const pg_kernel_settings p = default_params();
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float junk[] = {std::numeric_limits<float>::quiet_NaN(), -2.0f,
                        -std::numeric_limits<float>::infinity(),
                        std::numeric_limits<float>::infinity(), p.max_weight * 10.0f};
  for (const pg_pmm_state& s0 :
       {pg_pmm_initial_state(), make_state(0.5f, 0.5f, 0.02f, 0.02f, 0.0f, 0.5f, 3.0f)}) {
    std::vector<std::pair<float, float2>> good, mixed;
    for (int i = 0; i < 12; ++i) {
      good.push_back({0.5f + u(gen), float2(0.3f + 0.4f * u(gen), 0.3f + 0.4f * u(gen))});
      mixed.push_back(good.back());
      mixed.push_back({junk[i % 5], float2(u(gen), u(gen))});
    }
    int ug = 0, um = 0;
    // Same target count, so that only the junk differs.
    const pg_pmm_model m = pg_pmm_model_from_state(s0, p);
    const pg_lobes lobes = pg_make_lobes({float3(0.8f), 1.0f, 0.0f, 0.0f}, float3(0, 0, 1));
    pg_pmm_batch bg = pg_pmm_batch_empty(), bm = pg_pmm_batch_empty();
    for (const auto& [a, v] : good)
      bg = pg_pmm_batch_add_terms(bg, m, pg_pmm_e_terms_of(m), p, a, v,
                                  pg_bsdf_pdf(lobes, float3(0, 0, 1), pg_square_to_hemisphere(v)),
                                  0.0f, s0.s0.x);
    for (const auto& [a, v] : mixed)
      bm = pg_pmm_batch_add_terms(bm, m, pg_pmm_e_terms_of(m), p, a, v,
                                  pg_bsdf_pdf(lobes, float3(0, 0, 1), pg_square_to_hemisphere(v)),
                                  0.0f, s0.s0.x);
    const pg_pmm_state sg = pg_pmm_update(s0, bg, p, 12.0f, &ug);
    const pg_pmm_state sm = pg_pmm_update(s0, bm, p, 12.0f, &um);
    EXPECT_EQ(ug, 1);
    EXPECT_EQ(um, 1);
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(sm.s0[c], sg.s0[c], 1e-6f * std::fabs(sg.s0[c])) << c;
      EXPECT_NEAR(sm.s1[c], sg.s1[c], 1e-6f * std::fabs(sg.s1[c])) << c;
    }
  }
}

// A frame that found fewer samples than the neighbourhood promises (target_count) takes a
// proportionally smaller step (pmm.h, pg_pmm_update): with 3 of 12 samples the state moves a
// quarter as far towards the batch as with a target of 3, so a starved frame cannot overwrite
// the history.
TEST(PmmEm, AStarvedBatchTakesAProportionallySmallerStep) {
  const pg_kernel_settings p = default_params();
  const pg_pmm_state s0 = make_state(0.5f, 0.5f, 0.02f, 0.02f, 0.0f, 0.5f, 3.0f);
  const pg_pmm_model m = pg_pmm_model_from_state(s0, p);
  const pg_lobes lobes = pg_make_lobes({float3(0.8f), 1.0f, 0.0f, 0.0f}, float3(0, 0, 1));
  pg_pmm_batch b = pg_pmm_batch_empty();
  for (const float2 v : {float2(0.55f, 0.45f), float2(0.6f, 0.5f), float2(0.52f, 0.58f)})
    b = pg_pmm_batch_add_terms(b, m, pg_pmm_e_terms_of(m), p, 1.0f, v,
                               pg_bsdf_pdf(lobes, float3(0, 0, 1), pg_square_to_hemisphere(v)),
                               0.0f, s0.s0.x);
  int full_updated = 0, starved_updated = 0;
  const pg_pmm_state full = pg_pmm_update(s0, b, p, 3.0f, &full_updated);
  const pg_pmm_state starved = pg_pmm_update(s0, b, p, 12.0f, &starved_updated);
  ASSERT_EQ(full_updated, 1);
  ASSERT_EQ(starved_updated, 1);
  for (int c = 0; c < 4; ++c) {
    const double step_full = double(full.s0[c]) - s0.s0[c];
    EXPECT_NEAR(double(starved.s0[c]) - s0.s0[c], 0.25 * step_full, 1e-5 * std::fabs(s0.s0[c]))
        << c;
    if (c == 3) continue;  // s1.w is the epoch count k, which advances by one either way
    const double step1 = double(full.s1[c]) - s0.s1[c];
    EXPECT_NEAR(double(starved.s1[c]) - s0.s1[c], 0.25 * step1, 1e-5 * std::fabs(s0.s1[c])) << c;
  }
  EXPECT_EQ(full.s1.w, starved.s1.w);
  EXPECT_GT(std::fabs(double(full.s0.z) - s0.s0.z), 1e-3) << "the batch must move the mean";
}

// Re-seeding (pmm.h, pg_pmm_batch_add_terms): a narrow lobe whose batch has samples far outside it
// (beyond 5 standard deviations) and brighter than reseed_ratio times its history restarts
// (k back to 1) once reseed_samples of them are in one batch, and otherwise trains on (k + 1).
TEST(PmmEm, ReseedsOnlyWhenEnoughSamplesOfOneBatchCallForIt) {
  const pg_pmm_state s = make_state(0.3f, 0.3f, 0.001f, 0.001f, 0.0f, 0.5f, 10.0f);  // W = 2
  const float4 near_lobe(1.0f, 0.31f, 0.29f, 0.3f), far_bright(100.0f, 0.8f, 0.8f, 0.3f);
  const float4 far_bright2(100.0f, 0.85f, 0.75f, 0.3f);
  const auto k_after = [&](int reseed_samples, std::vector<float4> batch) {
    rtpg::GuidingSettings settings;
    settings.reseed_samples = reseed_samples;
    const pg_kernel_settings p = rtpg::to_kernel_settings(settings);
    int updated = 0;
    const std::vector<float> densities(batch.size(), 1.0f);
    const pg_pmm_state out =
        pg_pmm_train(s, batch.data(), densities.data(), static_cast<int>(batch.size()), p,
                     static_cast<float>(batch.size()), 1, &updated);
    EXPECT_EQ(updated, 1);
    return out.s1.w;
  };
  EXPECT_EQ(k_after(1, {near_lobe, near_lobe, far_bright}), 1.0f);
  EXPECT_EQ(k_after(2, {near_lobe, near_lobe, far_bright}), 11.0f);
  EXPECT_EQ(k_after(2, {near_lobe, far_bright, far_bright2}), 1.0f);
  EXPECT_EQ(k_after(3, {near_lobe, far_bright, far_bright2}), 11.0f);
  // Far but not brighter than 10 W = 20: no re-seed at any setting.
  EXPECT_EQ(k_after(1, {near_lobe, float4(15.0f, 0.8f, 0.8f, 0.3f)}), 11.0f);
}

// The weight clamp (weight_clamp, pmm.h) against the running mean weight W of the state each
// E-step pass takes its model from. A new model (k = 0) trains in one pass, unclamped: its
// later passes were once clamped against its W of 0, which zeroed every weight and threw the
// frame's training away, so that no pixel ever trained with the clamp on. A young model (k = 1)
// trains in three passes, each clamping against the W the previous pass's M-step gave, which
// this test follows by hand: all samples sit in the lobe (no re-seed), so each pass's M-step
// is W0 + (mean of the clamped weights - W0) / 2 from the frame's first state.
TEST(PmmEm, WeightClampFollowsEachPassesHistory) {
  rtpg::GuidingSettings settings;
  settings.weight_clamp = 5.0f;
  const pg_kernel_settings p = rtpg::to_kernel_settings(settings);
  std::vector<float4> batch;
  std::vector<float> weights;
  for (int i = 0; i < 9; ++i) {
    const float a = 10.0f + static_cast<float>(i);
    batch.push_back(float4(a, 0.3f + 0.01f * static_cast<float>(i % 3),
                           0.3f + 0.01f * static_cast<float>(i / 3), 0.3f));
    weights.push_back(a);
  }
  batch.push_back(float4(100.0f, 0.31f, 0.31f, 0.3f));
  weights.push_back(100.0f);
  const std::vector<float> densities(batch.size(), 1.0f);
  const int n = static_cast<int>(batch.size());

  int updated = 0;
  const pg_pmm_state fresh = pg_pmm_train(pg_pmm_initial_state(), batch.data(), densities.data(), n,
                                          p, static_cast<float>(n), 3, &updated);
  EXPECT_EQ(updated, 1);
  EXPECT_TRUE(pg_pmm_model_from_state(fresh, p).valid);
  double mean = 0.0;
  for (float a : weights) mean += a;
  EXPECT_NEAR(fresh.s0.x, mean / n, 1e-4 * mean / n) << "a new model's weights are not clamped";

  const pg_pmm_state young = make_state(0.31f, 0.31f, 0.01f, 0.01f, 0.0f, 0.5f, 1.0f, 0.5f);
  ASSERT_NEAR(young.s0.x, 1.0f, 1e-6f);  // W0 = 1
  updated = 0;
  const pg_pmm_state out =
      pg_pmm_train(young, batch.data(), densities.data(), n, p, static_cast<float>(n), 3, &updated);
  EXPECT_EQ(updated, 1);
  double history = young.s0.x, w = 0.0;
  for (int pass = 0; pass < 3; ++pass) {
    double clamped = 0.0;
    for (float a : weights) clamped += std::min(double(a), double(p.weight_clamp) * history);
    w = young.s0.x + (clamped / n - young.s0.x) * 0.5;  // eta = 1/(k+1) at k = 1
    history = w;
  }
  EXPECT_NEAR(out.s0.x, w, 1e-4 * w);
  EXPECT_EQ(out.s1.w, 2.0f);
}

// One sample repeated (and the square's corners and edge midpoints, where the map M has its
// kinks and the mean sits on the clamp): the empirical covariance is exactly zero, yet the
// model keeps a positive definite Sigma and its mean at the sample.
TEST(PmmEm, RepeatedSamplesAndCornersKeepSigmaPositiveDefinite) {
  const pg_kernel_settings p = default_params();
  const float2 points[] = {float2(0.37f, 0.81f), float2(0, 0),      float2(1, 0),
                           float2(0, 1),         float2(1, 1),      float2(0.5f, 0),
                           float2(1, 0.5f),      float2(0.5f, 0.5f)};
  for (const float2 u0 : points) {
    pg_pmm_state s = pg_pmm_initial_state();
    for (int e = 0; e < 100; ++e) {
      std::vector<std::pair<float, float2>> batch(15, {1.0f, u0});
      int updated = 0;
      s = update_with(s, p, batch, &updated);
      ASSERT_TRUE(pg_pmm_state_finite(s)) << u0.x << "," << u0.y << " epoch " << e;
      const pg_pmm_model m = pg_pmm_model_from_state(s, p);
      ASSERT_TRUE(m.valid) << u0.x << "," << u0.y << " epoch " << e;
      ASSERT_TRUE(model_is_sane(m, p)) << u0.x << "," << u0.y << " epoch " << e;
    }
    const pg_pmm_model m = pg_pmm_model_from_state(s, p);
    EXPECT_NEAR(m.mx, u0.x, 1e-4f);
    EXPECT_NEAR(m.my, u0.y, 1e-4f);
    // The density at the sample is finite and positive: the sampler can use this model.
    const pg_lobes lobes = pg_make_lobes({float3(0.8f), 1.0f, 0.0f, 0.0f}, float3(0, 0, 1));
    const float3 w = pg_square_to_hemisphere(
        float2(std::clamp(u0.x, 0.01f, 0.99f), std::clamp(u0.y, 0.01f, 0.99f)));
    const float d = pg_pmm_pdf(m, lobes, float3(0, 0, 1), w);
    EXPECT_TRUE(std::isfinite(d) && d > 0.0f) << d;
  }
}

// 1e5 consecutive updates from junk: weights log-uniform over 60 decades and every special
// value, points on corners, edges and repeated, BSDF densities from 0 to 1e30, target counts
// below and above the batch size. After every step the state is finite, k stays in [0, k_max],
// a state with k > 0 gives a valid model with a positive definite Sigma, and the model's
// sampler and density produce finite values.
TEST(PmmEm, SurvivesAHundredThousandJunkUpdates) {
  pg_kernel_settings p = default_params();
  std::mt19937 gen(77);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  auto junk_weight = [&]() -> float {
    const float r = u(gen);
    if (r < 0.55f) return std::pow(10.0f, -30.0f + 60.0f * u(gen));
    if (r < 0.62f) return 0.0f;
    if (r < 0.66f) return nan;
    if (r < 0.70f) return inf;
    if (r < 0.72f) return -inf;
    if (r < 0.76f) return -u(gen);
    if (r < 0.80f) return 1e-40f * u(gen);  // denormal
    if (r < 0.84f) return p.max_weight;
    if (r < 0.88f) return std::nextafter(p.max_weight, inf);
    return 1.0f + u(gen);
  };
  float2 repeated(u(gen), u(gen));
  auto junk_point = [&]() -> float2 {
    const float r = u(gen);
    if (r < 0.4f) return float2(u(gen), u(gen));
    if (r < 0.6f) return float2(std::round(u(gen)), std::round(u(gen)));  // corners
    if (r < 0.7f) return float2(std::round(u(gen)), u(gen));              // edges
    if (r < 0.9f) return repeated;
    return float2(1.0f - 1e-7f * u(gen), 1e-7f * u(gen));
  };
  auto junk_pdf = [&]() -> float {
    const float r = u(gen);
    if (r < 0.6f) return std::pow(10.0f, -3.0f + 5.0f * u(gen));
    if (r < 0.7f) return 0.0f;
    if (r < 0.8f) return 1e30f * u(gen);
    if (r < 0.9f) return 1e-38f * u(gen);
    return u(gen);
  };
  pg_pmm_state s = pg_pmm_initial_state();
  int valid_steps = 0;
  std::vector<float4> samples;
  std::vector<float> densities;
  for (int step = 0; step < 100000; ++step) {
    // The second half with the variance-aware mixing weight, whose sums take the densities.
    p.pi_learning = step >= 50000 ? 1 : 0;
    if (u(gen) < 0.01f) repeated = float2(u(gen), u(gen));
    samples.clear();
    densities.clear();
    const int count = static_cast<int>(26.0f * u(gen));
    for (int j = 0; j < count; ++j) {
      const float a = junk_weight();
      const float2 v = junk_point();
      samples.push_back(float4(a, v.x, v.y, junk_pdf()));
      densities.push_back(junk_pdf());
    }
    // Alternately the building blocks (one E-step) and the kernels' step with 1-3 passes.
    int updated = 0;
    const float target = std::floor(1.0f + 30.0f * u(gen));
    if (step % 2 == 0) {
      const pg_pmm_model m = pg_pmm_model_from_state(s, p);
      pg_pmm_batch b = pg_pmm_batch_empty();
      for (int j = 0; j < count; ++j) {
        const float4& x = samples[static_cast<std::size_t>(j)];
        b = pg_pmm_batch_add_terms(b, m, pg_pmm_e_terms_of(m), p, x.x, float2(x.y, x.z), x.w,
                                   densities[static_cast<std::size_t>(j)], s.s0.x);
      }
      s = pg_pmm_update(s, b, p, target, &updated);
    } else {
      s = pg_pmm_train(s, samples.data(), densities.data(), count, p, target, 1 + (step / 2) % 3,
                       &updated);
    }
    ASSERT_TRUE(pg_pmm_state_finite(s)) << "step " << step;
    ASSERT_GE(s.s1.w, 0.0f) << "step " << step;
    ASSERT_LE(s.s1.w, p.k_max) << "step " << step;
    const pg_pmm_model n = pg_pmm_model_from_state(s, p);
    if (s.s1.w > 0.0f) {
      ASSERT_TRUE(n.valid) << "step " << step;
      ++valid_steps;
    }
    ASSERT_TRUE(model_is_sane(n, p)) << "step " << step;
    if (step % 64 == 0 && n.valid) {
      const pg_lobes lobes = pg_make_lobes({float3(0.8f), 1.0f, 0.0f, 0.0f}, float3(0, 0, 1));
      const pg_pmm_sample_t smp = pg_pmm_sample(n, lobes, float3(0, 0, 1), 0.0f, u(gen), u(gen));
      ASSERT_TRUE(std::isfinite(smp.pdf) && smp.pdf >= 0.0f) << "step " << step;
      ASSERT_TRUE(std::isfinite(pg_pmm_pdf(n, lobes, float3(0, 0, 1), smp.wi))) << "step " << step;
    }
  }
  // The junk must not simply have been rejected throughout: most steps held a model.
  EXPECT_GT(valid_steps, 50000);
}

// ---- change of frame -----------------------------------------------------------------------

namespace {

float3 random_unit(std::mt19937& gen) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  return normalize(float3(n(gen), n(gen), n(gen)));
}

// The world direction of a state's mean in frame f.
float3 mean_direction(const pg_pmm_state& s, pg_frame f) {
  const float2 mu(std::clamp(s.s0.z / s.s0.y, 0.0f, 1.0f), std::clamp(s.s0.w / s.s0.y, 0.0f, 1.0f));
  return pg_to_world(f, pg_square_to_hemisphere(mu));
}

// The covariance the statistics hold (pmm.h: S2/S0 - mu mu^T), before the model regularises it.
Cov raw_covariance(const pg_pmm_state& s) {
  const double s0 = s.s0.y, mx = s.s0.z / s0, my = s.s0.w / s0;
  return {s.s1.x / s0 - mx * mx, s.s1.y / s0 - my * my, s.s1.z / s0 - mx * my};
}

// Two frames: a random normal, and one tilted from it by up to max_tilt_deg degrees.
std::pair<pg_frame, pg_frame> tilted_frames(std::mt19937& gen, float max_tilt_deg) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float3 n1 = random_unit(gen);
  const float3 t = normalize(cross(n1, random_unit(gen)));
  const float tilt = max_tilt_deg * PG_PI / 180.0f * u(gen);
  const float3 n2 = normalize(n1 * std::cos(tilt) + t * std::sin(tilt));
  return {pg_frame_from_normal(n1), pg_frame_from_normal(n2)};
}

double angle(float3 a, float3 b) {
  return std::atan2(static_cast<double>(length(cross(a, b))), static_cast<double>(dot(a, b)));
}

}  // namespace

// The same frame on both sides: the state comes back. W, S0 and k are untouched; the mean
// survives the M^-1(M(u)) round trip within 1e-4 (float error ~ sqrt(ulp) = 2.4e-4 only at the
// pole itself, excluded here; 4e-6 measured); the covariance goes through a Jacobian by central
// differences of step 1e-3, whose float error is ~1e-7 / 1e-3 = 1e-4 relative per entry, growing
// where the probe crosses a kink of M (the square's diagonals, excluded within 2e-3): 2% of
// sqrt(Sxx Syy) per entry (0.6% measured).
// A carried model ages with its view only where the BSDF has a glossy lobe: by 1/e per
// view_memory * alpha radians of turn (alpha = roughness^2), not at all for a Lambert surface, a
// still view, or with the option off (pmm.h, pg_pmm_view_aged_k).
TEST(PmmViewAge, GlossyModelsForgetAsTheViewTurns) {
  pg_material metal;
  metal.base_color = float3(0.9f, 0.6f, 0.3f);
  metal.roughness = 0.3f;
  metal.metallic = 1.0f;
  metal.specular = 0.5f;
  pg_material lambert = metal;
  lambert.metallic = 0.0f;
  lambert.specular = 0.0f;
  const float memory = 2.0f, alpha = 0.3f * 0.3f, k = 20.0f;
  const float3 view(0.0f, 0.0f, 1.0f);
  for (const float turned : {0.05f, 0.18f, 0.5f, 1.5f}) {
    const float3 prev(std::sin(turned), 0.0f, std::cos(turned));
    const float expected = k * std::exp(-turned / (memory * alpha));
    EXPECT_NEAR(pg_pmm_view_aged_k(k, view, prev, metal, memory), expected, 1e-4f * k) << turned;
    EXPECT_EQ(pg_pmm_view_aged_k(k, view, prev, lambert, memory), k) << turned;
    EXPECT_EQ(pg_pmm_view_aged_k(k, view, prev, metal, 0.0f), k) << turned;
  }
  // One memory's worth of turn takes k to k / e; no turn keeps it; a fresh model stays fresh.
  const float one = memory * alpha;
  EXPECT_NEAR(
      pg_pmm_view_aged_k(k, view, float3(std::sin(one), 0.0f, std::cos(one)), metal, memory),
      k / std::exp(1.0f), 1e-4f * k);
  EXPECT_EQ(pg_pmm_view_aged_k(k, view, view, metal, memory), k);
  EXPECT_EQ(pg_pmm_view_aged_k(0.0f, view, float3(1.0f, 0.0f, 0.0f), metal, memory), 0.0f);
  // A dielectric coating (specular > 0, metallic 0) is glossy too.
  pg_material coated = lambert;
  coated.specular = 0.04f;
  EXPECT_LT(pg_pmm_view_aged_k(k, view, float3(1.0f, 0.0f, 0.0f), coated, memory), k);
}

// The sharpest lobe (roughness 0.02, M alpha = 8e-4 rad) under a slow camera: turns of 1e-5 to
// 1e-3 rad age k as exp(-turn / (M alpha)) says, within 1e-4 of k. acos of the views' dot
// product could not tell a turn below 3.5e-4 rad from none (cos rounds to 1) and aged those by a
// factor of up to 1.5 or not at all (docs/design.md, "Floating point on other devices").
TEST(PmmViewAge, SmallTurnsOfASharpLobeAgeByTheirAngle) {
  pg_material mirror;
  mirror.base_color = float3(0.9f);
  mirror.roughness = 0.0f;  // clamped to PG_MIN_ROUGHNESS
  mirror.metallic = 1.0f;
  mirror.specular = 0.5f;
  const float memory = 2.0f, alpha = PG_MIN_ROUGHNESS * PG_MIN_ROUGHNESS, k = 20.0f;
  const float3 view(0.0f, 0.0f, 1.0f);
  for (const double turned : {1e-5, 5e-5, 1e-4, 3e-4, 1e-3}) {
    const float3 prev(static_cast<float>(std::sin(turned)), 0.0f,
                      static_cast<float>(std::cos(turned)));
    // The exact angle between the two float vectors, in double.
    const double exact = std::atan2(double(prev.x), double(prev.z));
    const double expected = k * std::exp(-exact / (double(memory) * alpha));
    EXPECT_NEAR(pg_pmm_view_aged_k(k, view, prev, mirror, memory), expected, 1e-4 * k) << turned;
  }
}

TEST(PmmReframe, IdentityFrameKeepsTheState) {
  const pg_kernel_settings p = default_params();
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const float mx = 0.02f + 0.96f * u(gen), my = 0.02f + 0.96f * u(gen);
    // Away from the diagonals of the square (kinks of M): see above.
    if (std::fabs(std::fabs(mx - 0.5f) - std::fabs(my - 0.5f)) < 2e-3f) continue;
    if (std::fabs(mx - 0.5f) < 2e-3f && std::fabs(my - 0.5f) < 2e-3f) continue;
    const float sx = 0.02f + 0.1f * u(gen), sy = 0.02f + 0.1f * u(gen), rho = -0.9f + 1.8f * u(gen);
    const float s0 = std::pow(10.0f, -2.0f + 4.0f * u(gen));
    const pg_pmm_state s = make_state(mx, my, sx * sx, sy * sy, rho * sx * sy, 0.2f + 0.6f * u(gen),
                                      1.0f + std::floor(31.0f * u(gen)), s0);
    const pg_frame f = pg_frame_from_normal(random_unit(gen));
    const pg_pmm_state r = pg_pmm_reframe(s, f, f);
    ASSERT_EQ(r.s0.x, s.s0.x);
    ASSERT_EQ(r.s0.y, s.s0.y);
    ASSERT_EQ(r.s1.w, s.s1.w);
    ASSERT_NEAR(r.s0.z / r.s0.y, mx, 1e-4f);
    ASSERT_NEAR(r.s0.w / r.s0.y, my, 1e-4f);
    ASSERT_TRUE(pg_pmm_model_from_state(r, p).valid);
    const Cov ca = raw_covariance(s), cb = raw_covariance(r);
    const double scale = std::sqrt(ca.xx * ca.yy);
    EXPECT_NEAR(cb.xx, ca.xx, 2e-2 * scale) << i;
    EXPECT_NEAR(cb.yy, ca.yy, 2e-2 * scale) << i;
    EXPECT_NEAR(cb.xy, ca.xy, 2e-2 * scale) << i;
    ++checked;
  }
  EXPECT_GT(checked, 1900);
  // No model: nothing to carry.
  const pg_frame f = pg_frame_from_normal(float3(0, 0, 1));
  EXPECT_TRUE(same_state(pg_pmm_reframe(pg_pmm_initial_state(), f, f), pg_pmm_initial_state()));
}

// A change of frame keeps the lobe's mean pointing at the same world direction (up to float
// rounding through M, M^-1 and two frames: 1e-4 rad; 3e-6 measured), and a mean that falls
// below the new horizon gives the initial state. The reframed covariance stays a covariance
// (positive definite model), and its determinant is kept (M and rotations preserve area, so
// det J = 1): the median relative change must be below 1% (0.12% measured; single cases are
// off where the central differences straddle a kink of M, up to 2x).
TEST(PmmReframe, RotationKeepsTheMeansWorldDirection) {
  const pg_kernel_settings p = default_params();
  std::mt19937 gen(12);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int carried = 0, dropped = 0;
  std::vector<double> det_change;
  for (int i = 0; i < 5000; ++i) {
    // The new normal: tilted from the old by up to 60 degrees.
    const auto [f1, f2] = tilted_frames(gen, 60.0f);
    const float3 n2 = f2.n;
    const float mx = 0.05f + 0.9f * u(gen), my = 0.05f + 0.9f * u(gen);
    const float sx = 0.01f + 0.05f * u(gen), sy = 0.01f + 0.05f * u(gen),
                rho = -0.8f + 1.6f * u(gen);
    const pg_pmm_state s = make_state(mx, my, sx * sx, sy * sy, rho * sx * sy, 0.5f, 5.0f);
    const float3 d = mean_direction(s, f1);
    const float z2 = dot(d, n2);
    const pg_pmm_state r = pg_pmm_reframe(s, f1, f2);
    ASSERT_TRUE(pg_pmm_state_finite(r));
    if (z2 < -1e-3f) {
      EXPECT_TRUE(same_state(r, pg_pmm_initial_state())) << i << " z=" << z2;
      ++dropped;
      continue;
    }
    if (z2 < 1e-2f) continue;  // at the horizon either outcome is right
    ++carried;
    ASSERT_EQ(r.s1.w, s.s1.w);
    EXPECT_LT(angle(mean_direction(r, f2), d), 1e-4) << i;
    const pg_pmm_model mb = pg_pmm_model_from_state(r, p);
    ASSERT_TRUE(model_is_sane(mb, p));
    ASSERT_TRUE(mb.valid);
    const Cov ca = raw_covariance(s), cb = raw_covariance(r);
    const double deta = ca.xx * ca.yy - ca.xy * ca.xy, detb = cb.xx * cb.yy - cb.xy * cb.xy;
    det_change.push_back(std::fabs(detb / deta - 1.0));
  }
  EXPECT_GT(carried, 2500);
  EXPECT_GT(dropped, 100);
  std::nth_element(det_change.begin(), det_change.begin() + det_change.size() / 2,
                   det_change.end());
  EXPECT_LT(det_change[det_change.size() / 2], 0.01);
}

// The reframe's Jacobian in closed form (pg_square_to_hemisphere_d, the rotation, then
// pg_hemisphere_to_square_d) against central differences of the change of frame in double
// precision around the float maps (step 1e-3), at random points away from the maps' kinks (the
// wedges' diagonals, on both sides) and from the pole, under tilts up to 60 degrees; and its
// determinant is 1 (M and rotations preserve area; docs/guiding.md, "The reframe's Jacobian in
// closed form"). Measured: worst entry 1.9e-4 off (the differences' own error), worst
// determinant 9.3e-7 off.
TEST(PmmReframe, ClosedFormJacobianMatchesDifferences) {
  std::mt19937 gen(31);
  std::uniform_real_distribution<float> u(0.02f, 0.98f);
  const auto away_from_kinks = [](float a, float b) {
    return std::fabs(std::fabs(a) - std::fabs(b)) > 0.02f && std::fabs(a) + std::fabs(b) > 0.05f;
  };
  int checked = 0;
  double worst = 0.0, worst_det = 0.0;
  for (int i = 0; i < 4000; ++i) {
    const auto [f1, f2] = tilted_frames(gen, 60.0f);
    const float2 m(u(gen), u(gen));
    if (!away_from_kinks(2.0f * m.x - 1.0f, 2.0f * m.y - 1.0f)) continue;
    float3 w, w_dx, w_dy;
    ASSERT_TRUE(pg_square_to_hemisphere_d(m, &w, &w_dx, &w_dy));
    const float3 w2 = pg_to_local(f2, pg_to_world(f1, w));
    if (w2.z < 0.05f || !away_from_kinks(w2.x, w2.y)) continue;
    float2 m2;
    float3 gx, gy;
    if (!pg_hemisphere_to_square_d(w2, 0.1f, &m2, &gx, &gy)) continue;
    const float2 expected_m2 = pg_hemisphere_to_square(w2);
    ASSERT_EQ(m2.x, expected_m2.x);  // the same operations as the map itself
    ASSERT_EQ(m2.y, expected_m2.y);
    ASSERT_EQ(w.x, pg_square_to_hemisphere(m).x);
    ASSERT_EQ(w.z, pg_square_to_hemisphere(m).z);
    const float3 t_dx = pg_to_local(f2, pg_to_world(f1, w_dx));
    const float3 t_dy = pg_to_local(f2, pg_to_world(f1, w_dy));
    const double j[2][2] = {{dot(gx, t_dx), dot(gx, t_dy)}, {dot(gy, t_dx), dot(gy, t_dy)}};
    const float h = 1e-3f;
    const auto carried = [&](float x, float y) {
      int ok = 1;
      return pg_pmm_reframe_point(float2(x, y), f1, f2, &ok);
    };
    const float2 px1 = carried(m.x + h, m.y), px0 = carried(m.x - h, m.y);
    const float2 py1 = carried(m.x, m.y + h), py0 = carried(m.x, m.y - h);
    const double fd[2][2] = {
        {(double(px1.x) - px0.x) / (2.0 * h), (double(py1.x) - py0.x) / (2.0 * h)},
        {(double(px1.y) - px0.y) / (2.0 * h), (double(py1.y) - py0.y) / (2.0 * h)}};
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c) {
        const double off = std::fabs(j[r][c] - fd[r][c]);
        worst = std::max(worst, off);
        EXPECT_LT(off, 5e-3 * (1.0 + std::fabs(fd[r][c])))
            << i << ": J[" << r << "][" << c << "] " << j[r][c] << " by differences " << fd[r][c];
      }
    const double det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    worst_det = std::max(worst_det, std::fabs(det - 1.0));
    EXPECT_NEAR(det, 1.0, 1e-3) << i;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
  std::printf("[ info     ] %d points, worst entry %.2g off, worst determinant %.2g off\n", checked,
              worst, worst_det);
}

// ---- training samples from VPLs, by hand ----------------------------------------------------

// One VPL seen from a Lambertian pixel (albedo 0.5, normal +z, at the origin, viewed head-on):
// the VPL at y = (0, 3, 4), 5 away along w = (0, 0.6, 0.8), facing straight down (cos at y
// 0.8), with area density 0.2 and radiance 2. Computed here by hand: its solid-angle density
// from the pixel is 0.2 * 25 / 0.8 = 6.25, f cos = (0.5 / pi) * 0.8, so the weight
// lum(L f cos) / density = 0.8 / (6.25 pi) and the BSDF density 0.8 / pi (pmm_train.h).
TEST(PmmTrainSample, VplWeightByHand) {
  pg_kernel_settings p = default_params();
  p.train_all_samples = 0;
  const pg_material grey{float3(0.5f), 1.0f, 0.0f, 0.0f};
  pg_train_pixel px;
  px.x = float3(0.0f);
  px.frame = pg_frame_from_normal(float3(0.0f, 0.0f, 1.0f));
  px.wo = float3(0.0f, 0.0f, 1.0f);
  px.lobes = pg_make_lobes(grey, px.wo);
  const uint bsdf_info = PG_VPL_VALID | (PG_STRATEGY_BSDF << PG_VPL_STRATEGY_SHIFT);
  const uint guide_info = PG_VPL_VALID | (PG_STRATEGY_GUIDE << PG_VPL_STRATEGY_SHIFT);
  const float4 position_pdf(0.0f, 3.0f, 4.0f, 0.2f);
  // The packed channel: facing straight down, the whole mixture's area density 0.3, radiance 2
  // (both exact after packing: the octahedral map keeps the poles, bfloat16 keeps 2).
  auto packed = [](float3 normal, uint info) {
    return pg_pack_vpl_normal_radiance(normal, 0.3f, float3(2.0f), info);
  };
  const float3 down(0.0f, 0.0f, -1.0f), up(0.0f, 0.0f, 1.0f);
  float4 sample;
  float density = 0.0f;
  ASSERT_EQ(
      pg_train_sample_from_vpl(px, position_pdf, packed(down, bsdf_info), p, &sample, &density), 1);
  EXPECT_NEAR(sample.x, 0.8 / (6.25 * kPiD), 1e-6);
  EXPECT_NEAR(sample.w, 0.8 / kPiD, 1e-6);
  const float3 w = pg_square_to_hemisphere(float2(sample.y, sample.z));
  EXPECT_NEAR(w.x, 0.0f, 1e-5f);
  EXPECT_NEAR(w.y, 0.6f, 1e-5f);
  EXPECT_NEAR(w.z, 0.8f, 1e-5f);
  // A guide-strategy VPL trains only with train_all_samples (paper 3.2), and then every VPL
  // counts at the whole mixture's density: 0.3 * 25 / 0.8 = 9.375.
  EXPECT_EQ(
      pg_train_sample_from_vpl(px, position_pdf, packed(down, guide_info), p, &sample, &density),
      0);
  p.train_all_samples = 1;
  ASSERT_EQ(
      pg_train_sample_from_vpl(px, position_pdf, packed(down, guide_info), p, &sample, &density),
      1);
  EXPECT_NEAR(sample.x, 0.8 / (9.375 * kPiD), 1e-6);
  p.train_all_samples = 0;
  // A distant VPL (an escaped ray) holds its direction and a solid-angle density already.
  const uint distant_info = bsdf_info | PG_VPL_DISTANT;
  ASSERT_EQ(pg_train_sample_from_vpl(px, float4(0.0f, 0.6f, 0.8f, 0.2f), packed(down, distant_info),
                                     p, &sample, &density),
            1);
  EXPECT_NEAR(sample.x, 0.8 / (0.2 * kPiD), 1e-5);
  // A VPL whose surface faces away from the pixel, or one below the pixel's horizon, says
  // nothing about its hemisphere.
  EXPECT_EQ(pg_train_sample_from_vpl(px, position_pdf, packed(up, bsdf_info), p, &sample, &density),
            0);
  EXPECT_EQ(pg_train_sample_from_vpl(px, float4(0, 3, -4, 0.2f), packed(up, bsdf_info), p, &sample,
                                     &density),
            0);
}

// ---- reframe against carried samples --------------------------------------------------------

// Sigma' = J Sigma J^T, checked without any Jacobian: points drawn from the state's Gaussian in
// the old frame are carried one by one through the change of frame (pg_pmm_reframe_point), and
// their sample covariance must equal the reframed state's within its sampling error (5 standard
// errors) plus 3% of the scale for the map's curvature over the Gaussian (sigma <= 0.012).
// Power: the same criterion rejects J^T Sigma J or a flipped Sigma_xy in most cases.
TEST(PmmReframe, CovarianceMatchesCarriedSamples) {
  std::mt19937 gen(14);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int n = 20000;
  int checked = 0, transposed_rejected = 0, flipped_rejected = 0;
  auto within = [&](const Cov& sample, const Cov& model) {
    const double scale = std::sqrt(model.xx * model.yy);
    const double se_xx = std::sqrt(2.0 / n) * model.xx, se_yy = std::sqrt(2.0 / n) * model.yy;
    const double se_xy = std::sqrt((model.xx * model.yy + model.xy * model.xy) / n);
    return std::fabs(sample.xx - model.xx) <= 5.0 * se_xx + 0.03 * scale &&
           std::fabs(sample.yy - model.yy) <= 5.0 * se_yy + 0.03 * scale &&
           std::fabs(sample.xy - model.xy) <= 5.0 * se_xy + 0.03 * scale;
  };
  for (int i = 0; i < 300; ++i) {
    const auto [f1, f2] = tilted_frames(gen, 45.0f);
    const double sx = 0.004 + 0.008 * u(gen), sy = 0.004 + 0.008 * u(gen);
    const double rho = -0.8 + 1.6 * u(gen);
    const float mx = 0.15f + 0.7f * u(gen), my = 0.15f + 0.7f * u(gen);
    // The equal-area map has kinks on the square's diagonals: keep the Gaussian off them.
    const double margin = 6.0 * std::max(sx, sy);
    if (std::fabs(std::fabs(mx - 0.5) - std::fabs(my - 0.5)) < margin) continue;
    const pg_pmm_state s =
        make_state(mx, my, float(sx * sx), float(sy * sy), float(rho * sx * sy), 0.5f, 5.0f);
    const pg_pmm_state r = pg_pmm_reframe(s, f1, f2);
    if (same_state(r, pg_pmm_initial_state())) continue;  // the mean fell below the horizon
    // The carried points' mean and covariance.
    double sum_x = 0, sum_y = 0, sum_xx = 0, sum_yy = 0, sum_xy = 0;
    int carried = 0;
    for (int k = 0; k < n; ++k) {
      const double z1 = normal(gen), z2 = normal(gen);
      const float2 a(float(mx + sx * z1),
                     float(my + sy * (rho * z1 + std::sqrt(1.0 - rho * rho) * z2)));
      int ok = 1;
      const float2 b = pg_pmm_reframe_point(a, f1, f2, &ok);
      if (!ok) continue;
      sum_x += b.x;
      sum_y += b.y;
      sum_xx += double(b.x) * b.x;
      sum_yy += double(b.y) * b.y;
      sum_xy += double(b.x) * b.y;
      ++carried;
    }
    if (carried < n) continue;  // part of the Gaussian crosses the new horizon
    const double ex = sum_x / n, ey = sum_y / n;
    const Cov sample{sum_xx / n - ex * ex, sum_yy / n - ey * ey, sum_xy / n - ex * ey};
    const Cov reframed = raw_covariance(r);
    // And off the new square's diagonals (where the carried Gaussian lands).
    const double mx2 = r.s0.z / r.s0.y, my2 = r.s0.w / r.s0.y;
    const double margin2 = 6.0 * std::sqrt(std::max(reframed.xx, reframed.yy));
    if (std::fabs(std::fabs(mx2 - 0.5) - std::fabs(my2 - 0.5)) < margin2) continue;
    ++checked;
    EXPECT_TRUE(within(sample, reframed))
        << i << ": carried (" << sample.xx << ", " << sample.yy << ", " << sample.xy
        << "), reframed (" << reframed.xx << ", " << reframed.yy << ", " << reframed.xy << ")";
    // The wrong variants, built from the reframed covariance and the Jacobian's action on the
    // original: J^T Sigma J differs from J Sigma J^T unless J is symmetric.
    const Cov orig = raw_covariance(s);
    const float h = 1e-3f;
    int okx = 1, oky = 1, ok0 = 1;
    const float2 m0 = pg_pmm_reframe_point(float2(mx, my), f1, f2, &ok0);
    const float2 px = pg_pmm_reframe_point(float2(mx + h, my), f1, f2, &okx);
    const float2 py = pg_pmm_reframe_point(float2(mx, my + h), f1, f2, &oky);
    const double j11 = (px.x - m0.x) / h, j21 = (px.y - m0.y) / h;
    const double j12 = (py.x - m0.x) / h, j22 = (py.y - m0.y) / h;
    // J^T Sigma J: the transpose has j12 and j21 exchanged.
    const double a11 = j11, a12 = j21, a21 = j12, a22 = j22;
    const Cov transposed{
        a11 * (a11 * orig.xx + a12 * orig.xy) + a12 * (a11 * orig.xy + a12 * orig.yy),
        a21 * (a21 * orig.xx + a22 * orig.xy) + a22 * (a21 * orig.xy + a22 * orig.yy),
        a21 * (a11 * orig.xx + a12 * orig.xy) + a22 * (a11 * orig.xy + a12 * orig.yy)};
    if (!within(sample, transposed)) ++transposed_rejected;
    const Cov flipped_input{orig.xx, orig.yy, -orig.xy};
    const Cov flipped{j11 * (j11 * flipped_input.xx + j12 * flipped_input.xy) +
                          j12 * (j11 * flipped_input.xy + j12 * flipped_input.yy),
                      j21 * (j21 * flipped_input.xx + j22 * flipped_input.xy) +
                          j22 * (j21 * flipped_input.xy + j22 * flipped_input.yy),
                      j21 * (j11 * flipped_input.xx + j12 * flipped_input.xy) +
                          j22 * (j11 * flipped_input.xy + j12 * flipped_input.yy)};
    if (!within(sample, flipped)) ++flipped_rejected;
  }
  EXPECT_GT(checked, 150);
  EXPECT_GT(transposed_rejected, checked / 2) << "J^T Sigma J passes too often";
  EXPECT_GT(flipped_rejected, checked / 2) << "a flipped Sigma_xy passes too often";
  std::printf("reframe: %d cases; J^T rejected in %d, flipped Sigma_xy in %d\n", checked,
              transposed_rejected, flipped_rejected);
}

// The walk through a training window visits each of its (2 apron + 1)^2 VPLs once in as many
// steps, from any start, for every apron the settings allow: the stride the settings give must
// be coprime with the window's size. At aprons 1, 4 and 7 the first candidate stride (a third
// of the size) is not, and the search must move on (a stride of 3 at apron 1 visits 3 of 9).
TEST(TrainWindow, TheWalkVisitsEveryVplOnceForEveryApron) {
  for (int apron = 0; apron <= 8; ++apron) {
    rtpg::GuidingSettings s;
    s.apron = apron;
    const rtpg::pg_kernel_settings p = rtpg::to_kernel_settings(s);
    const int size = (2 * apron + 1) * (2 * apron + 1);
    // pg_train_walk_start draws the start in [0, size).
    for (const unsigned drawn : {0u, 1u, 5u, 77u, 288u}) {
      const unsigned start = drawn % static_cast<unsigned>(size);
      std::vector<int> seen(static_cast<std::size_t>(size), 0);
      for (int k = 0; k < size; ++k) {
        const int c = pg_train_window_index(start, k, p);
        ASSERT_GE(c, 0);
        ASSERT_LT(c, size);
        ++seen[static_cast<std::size_t>(c)];
      }
      EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), size)
          << "apron " << apron << ", stride " << p.stride << ", start " << start;
    }
  }
}

// A pixel that shares its row's model (kernels/shared/guiding_pixel.h, pg_shares_model) uses
// that model in its own frame as it is, so the frames must agree: any square point must give
// nearly the same world direction through both. Normals near the z = 0 plane (walls facing x or
// y) are drawn on purpose: there pg_frame_from_normal's tangent turns half a turn about the normal
// as n.z changes sign, and 0.5-degree-apart normals on both sides once gave lobes 100 degrees
// apart.
TEST(SharedModels, EveryAcceptedPairPointsALobeTheSameWayInBothFrames) {
  rtpg::GuidingSettings settings;
  settings.rows_per_model = 2;
  const rtpg::pg_kernel_settings p = rtpg::to_kernel_settings(settings);
  std::mt19937 gen(41);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  pg_sharing_pixel a{}, m{};
  a.material = m.material = 1;
  a.base_color_roughness = m.base_color_roughness = float4(0.5f, 0.5f, 0.5f, 1.0f);
  a.position_depth = float4(1.0f, 2.0f, 3.0f, 4.0f);
  m.position_depth = float4(1.0f, 2.0f, 3.001f, 4.0f);
  int accepted = 0, across_z0 = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 20000; ++trial) {
    const float phi = 6.2831853f * uniform(gen);
    // Half the pairs within 0.01 of z = 0, the others anywhere on the sphere.
    const bool near_z0 = trial % 2 == 0;
    const float z = near_z0 ? 0.01f * (2.0f * uniform(gen) - 1.0f) : 2.0f * uniform(gen) - 1.0f;
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    m.normal = float3(r * std::cos(phi), r * std::sin(phi), z);
    // A second normal up to 1.5 degrees away (some outside the 1.1-degree rule).
    const float3 across = normalize(
        cross(m.normal, float3(uniform(gen) - 0.5f, uniform(gen) - 0.5f, uniform(gen) - 0.5f)));
    a.normal = normalize(m.normal + 0.026f * uniform(gen) * across);
    if (!pg_shares_model(a, m, p)) continue;
    ++accepted;
    across_z0 += (a.normal.z >= 0.0f) != (m.normal.z >= 0.0f);
    const pg_frame fa = pg_frame_from_normal(a.normal), fm = pg_frame_from_normal(m.normal);
    for (float u : {0.1f, 0.5f, 0.8f})
      for (float v : {0.2f, 0.5f, 0.9f}) {
        const float3 h = pg_square_to_hemisphere(float2(u, v));
        const double c = dot(pg_to_world(fa, h), pg_to_world(fm, h));
        worst = std::max(worst, std::acos(std::min(1.0, c)) * 57.29578);
      }
  }
  EXPECT_GT(accepted, 5000);  // the rule is not vacuous
  EXPECT_EQ(across_z0, 0) << "pairs on both sides of z = 0 share a model";
  // On one side of z = 0 the frame turns smoothly with the normal (the tangent's derivative is
  // bounded there), so 1.1 degrees between normals is a few degrees between lobes at most; a
  // half turn would be 180.
  EXPECT_LT(worst, 5.0) << "a shared lobe points elsewhere in the sharing pixel's frame";
}

// Numerical stress of the guiding state (issue: robustness; docs/robustness.md, "Numerical
// stress"). Each configuration feeds 10^6 adversarial EM updates (pg_pmm_train, the kernels'
// step, with 16 samples each) to one state; after every update the state must be finite with
// k in [0, k_max] and a model with a positive definite Sigma, and after the run the model's
// density must still integrate to the fraction of sampling attempts that produce a direction.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "rtpg/guiding_settings.h"
#include "shared/bsdf.h"
#include "shared/mapping.h"
#include "shared/pmm.h"
#include "shared/rng.h"
#include "support/pmm_checks.h"

using namespace rtpg::shared;

namespace {

constexpr int kSamplesPerUpdate = 16;

pg_kernel_settings default_params() {
  return rtpg::to_kernel_settings(rtpg::GuidingSettings{});
}

const pg_lobes& lambert() {
  static const pg_lobes lobes = pg_make_lobes({float3(0.8f), 1.0f, 0.0f, 0.0f}, float3(0, 0, 1));
  return lobes;
}

float bsdf_pdf_at(float2 u) {
  return pg_bsdf_pdf(lambert(), float3(0, 0, 1), pg_square_to_hemisphere(u));
}

// One configuration: fills the samples of update `step` (x = weight, y/z = square point,
// w = BSDF density).
using SampleSource = std::function<void(int step, std::mt19937& gen, std::vector<float4>& out)>;

struct StressResult {
  int updates = 0, updates_with_model = 0;
  pg_pmm_state state = pg_pmm_initial_state();
};

// Runs `updates` updates from `start`; asserts the invariants after each.
StressResult stress(const char* name, const SampleSource& source, int updates,
                    pg_pmm_state start = pg_pmm_initial_state()) {
  const pg_kernel_settings p = default_params();
  std::mt19937 gen(20261123u);
  std::vector<float4> samples(kSamplesPerUpdate);
  // The density each sample was drawn with: uniform on the square (solid angle, Jacobian 2 pi).
  const std::vector<float> densities(kSamplesPerUpdate, PG_INV_TWO_PI);
  StressResult r;
  r.state = start;
  for (int step = 0; step < updates; ++step) {
    source(step, gen, samples);
    int updated = 0;
    r.state = pg_pmm_train(r.state, samples.data(), densities.data(), kSamplesPerUpdate, p,
                           static_cast<float>(kSamplesPerUpdate), 2, &updated);
    const pg_pmm_state& s = r.state;
    if (!pg_pmm_state_finite(s) || !(s.s1.w >= 0.0f && s.s1.w <= p.k_max) || !(s.s0.x >= 0.0f) ||
        !(s.s0.y >= 0.0f)) {
      ADD_FAILURE() << name << ", update " << step << ": state (" << s.s0.x << " " << s.s0.y << " "
                    << s.s0.z << " " << s.s0.w << " | " << s.s1.x << " " << s.s1.y << " " << s.s1.z
                    << " " << s.s1.w << ")";
      return r;
    }
    const pg_pmm_model m = pg_pmm_model_from_state(s, p);
    if (s.s1.w > 0.0f && !m.valid) {
      ADD_FAILURE() << name << ", update " << step << ": k = " << s.s1.w << " but no model";
      return r;
    }
    const ::testing::AssertionResult sane = rtpg::test::model_is_sane(m, p);
    if (!sane) {
      ADD_FAILURE() << name << ", update " << step << ": " << sane.message();
      return r;
    }
    r.updates_with_model += m.valid;
    ++r.updates;
  }
  return r;
}

// The integral of the model's density D over the hemisphere, through the equal-area square
// map (dw = 2 pi du), by the midpoint rule on a 1024^2 grid (spacing 1e-3, a third of the
// narrowest standard deviation Sigma can have: sigma_eps = 1e-4 and |rho| <= 0.95), against
// the fraction of 10^6 sampling attempts that produce a direction (a Gaussian draw outside
// the square produces none). Equal within 5 binomial standard deviations plus 1e-3.
void expect_density_integrates_to_valid_fraction(const char* name, const pg_pmm_state& s) {
  const pg_kernel_settings p = default_params();
  const pg_pmm_model m = pg_pmm_model_from_state(s, p);
  const float3 wo(0, 0, 1);
  const int grid = 1024;
  double integral = 0.0;
  for (int y = 0; y < grid; ++y)
    for (int x = 0; x < grid; ++x) {
      const float2 u((x + 0.5f) / grid, (y + 0.5f) / grid);
      integral += pg_pmm_pdf(m, lambert(), wo, pg_square_to_hemisphere(u));
    }
  integral *= 2.0 * PG_PI / (static_cast<double>(grid) * grid);
  const int attempts = 1000000;
  int produced = 0;
  for (int i = 0; i < attempts; ++i) {
    pg_rng rng = pg_rng_make(99u, static_cast<uint>(i), 0u, 0u, 5u);
    const float xi = pg_rng_next(&rng), u1 = pg_rng_next(&rng), u2 = pg_rng_next(&rng);
    produced += pg_pmm_sample(m, lambert(), wo, xi, u1, u2).pdf > 0.0f;
  }
  const double f = static_cast<double>(produced) / attempts;
  const double sd = std::sqrt(std::max(f * (1.0 - f), 1e-12) / attempts);
  std::printf("%s: density integral %.5f, valid fraction %.5f (sd %.1e), pi %.3f\n", name, integral,
              f, sd, m.pi);
  EXPECT_NEAR(integral, f, 5.0 * sd + 1e-3)
      << name << ": model pi " << m.pi << " mean (" << m.mx << ", " << m.my << ") L (" << m.l11
      << ", " << m.l21 << ", " << m.l22 << ")";
}

void run_configuration(const char* name, const SampleSource& source, int updates = 1000000,
                       pg_pmm_state start = pg_pmm_initial_state(), int min_with_model = 1) {
  const StressResult r = stress(name, source, updates, start);
  ASSERT_EQ(r.updates, updates) << name;
  EXPECT_GE(r.updates_with_model, min_with_model) << name << ": the model never existed";
  expect_density_integrates_to_valid_fraction(name, r.state);
}

float2 uniform_point(std::mt19937& gen) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  return float2(u(gen), u(gen));
}

float4 sample_at(float a, float2 u) {
  return float4(a, u.x, u.y, bsdf_pdf_at(u));
}

// A point drawn around c by `spread`, clamped into the square (x drawn before y: the order of
// a call's arguments is unspecified).
float2 clamped_around(float2 c, std::normal_distribution<float>& spread, std::mt19937& gen) {
  const float dx = spread(gen), dy = spread(gen);
  return float2(std::clamp(c.x + dx, 0.0f, 1.0f), std::clamp(c.y + dy, 0.0f, 1.0f));
}

}  // namespace

TEST(PmmStress, WeightsOverSixtyDecades) {
  run_configuration(
      "weights 1e-30 .. 1e30",
      [](int, std::mt19937& gen, std::vector<float4>& out) {
        std::uniform_real_distribution<float> e(-30.0f, 30.0f);
        for (float4& x : out) x = sample_at(std::pow(10.0f, e(gen)), uniform_point(gen));
      },
      1000000, pg_pmm_initial_state(), 900000);
}

TEST(PmmStress, EverySampleInOnePoint) {
  run_configuration(
      "one point",
      [](int, std::mt19937&, std::vector<float4>& out) {
        for (float4& x : out) x = sample_at(1.0f, float2(0.318f, 0.709f));
      },
      1000000, pg_pmm_initial_state(), 999000);
}

TEST(PmmStress, SamplesOnTheSquaresEdgesAndCorners) {
  run_configuration(
      "edges and corners",
      [](int, std::mt19937& gen, std::vector<float4>& out) {
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        std::uniform_int_distribution<int> side(0, 5);
        for (float4& x : out) {
          const int k = side(gen);
          const float t = u(gen);
          const float2 v = k == 0   ? float2(t, 0.0f)
                           : k == 1 ? float2(1.0f, t)
                           : k == 2 ? float2(t, 1.0f)
                           : k == 3 ? float2(0.0f, t)
                                    : float2(std::round(u(gen)), std::round(u(gen)));
          x = sample_at(0.1f + u(gen), v);
        }
      },
      1000000, pg_pmm_initial_state(), 999000);
}

// Two bright sources at opposite corners, one per frame: the lobe must never degenerate
// while EM is pulled back and forth (and re-seeds).
TEST(PmmStress, AlternatingFarApartSources) {
  run_configuration(
      "alternating sources",
      [](int step, std::mt19937& gen, std::vector<float4>& out) {
        std::normal_distribution<float> n(0.0f, 0.01f);
        const float2 c = step % 2 ? float2(0.05f, 0.05f) : float2(0.95f, 0.95f);
        const float a = step % 2 ? 1e4f : 1e-2f;
        for (float4& x : out) {
          x = sample_at(a, clamped_around(c, n, gen));
        }
      },
      1000000, pg_pmm_initial_state(), 999000);
}

TEST(PmmStress, NanAndInfiniteWeightsAmongGoodOnes) {
  run_configuration(
      "NaN and Inf weights",
      [](int, std::mt19937& gen, std::vector<float4>& out) {
        std::uniform_int_distribution<int> kind(0, 5);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (float4& x : out) {
          const int k = kind(gen);
          const float a = k == 0   ? std::numeric_limits<float>::quiet_NaN()
                          : k == 1 ? std::numeric_limits<float>::infinity()
                          : k == 2 ? -std::numeric_limits<float>::infinity()
                                   : 0.5f + u(gen);
          float2 v = uniform_point(gen);
          if (u(gen) < 0.1f) v.x = std::numeric_limits<float>::quiet_NaN();  // a NaN point too
          x = float4(a, v.x, v.y, std::isfinite(v.x) ? bsdf_pdf_at(v) : 0.3f);
        }
      },
      1000000, pg_pmm_initial_state(), 900000);
}

// A mature pixel (k = k_max, the smallest step) for 10^5 frames of a moving target.
TEST(PmmStress, AtKMaxForAHundredThousandFrames) {
  const pg_kernel_settings p = default_params();
  pg_pmm_state mature;
  mature.s0 = float4(2.0f, 1.0f, 0.5f, 0.5f);
  mature.s1 = float4(0.26f, 0.26f, 0.25f, p.k_max);
  run_configuration(
      "k at k_max",
      [](int step, std::mt19937& gen, std::vector<float4>& out) {
        const float angle = 2.0f * PG_PI * static_cast<float>(step) / 5000.0f;
        std::normal_distribution<float> n(0.0f, 0.03f);
        const float2 c(0.5f + 0.35f * std::cos(angle), 0.5f + 0.35f * std::sin(angle));
        for (float4& x : out) x = sample_at(1.0f, clamped_around(c, n, gen));
      },
      100000, mature, 100000);
}

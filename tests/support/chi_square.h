// Chi-square goodness-of-fit test of a direction sampler against its density, in the style
// of pbrt-v4's bsdfs_test.cpp: directions are binned over (cos theta, phi) of the sphere, the
// expected count per cell integrates the pdf numerically, cells expecting fewer than 5
// samples are pooled, and the p-value comes from the chi-square distribution.
#pragma once

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rtpg::test {

// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes 6.2: series for x < a + 1,
// continued fraction otherwise).
inline double incomplete_gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double gln = std::lgamma(a);
  if (x < a + 1.0) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 10000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::fabs(del) < std::fabs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::fabs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

struct ChiSquareResult {
  double statistic = 0.0;
  int degrees_of_freedom = 0;
  double p_value = 1.0;
  double pdf_integral = 0.0;     // integral of the pdf over the sphere (numerical)
  double sample_fraction = 0.0;  // fraction of attempts that produced a direction
  std::string describe() const {
    return "chi2=" + std::to_string(statistic) + " dof=" + std::to_string(degrees_of_freedom) +
           " p=" + std::to_string(p_value) + " integral=" + std::to_string(pdf_integral) +
           " valid=" + std::to_string(sample_fraction);
  }
};

// sample(i, dir) draws attempt i and returns false when it produced no direction; pdf(dir)
// is the solid-angle density of the produced directions (defective densities integrate to
// the probability of producing a direction).
inline ChiSquareResult chi_square_test(const std::function<bool(std::size_t, glm::vec3&)>& sample,
                                       const std::function<double(const glm::vec3&)>& pdf,
                                       std::size_t samples = 1000000, int theta_bins = 40,
                                       int phi_bins = 80, int integration_steps = 8) {
  const double kPi = 3.14159265358979323846;
  const int cells = theta_bins * phi_bins;
  std::vector<double> observed(cells, 0.0), expected(cells, 0.0);
  std::size_t valid = 0;
  for (std::size_t i = 0; i < samples; ++i) {
    glm::vec3 d;
    if (!sample(i, d)) continue;
    const double len = glm::length(d);
    if (!(len > 0.0)) continue;
    ++valid;
    const double z = std::clamp(static_cast<double>(d.z) / len, -1.0, 1.0);
    double phi = std::atan2(static_cast<double>(d.y), static_cast<double>(d.x));
    if (phi < 0.0) phi += 2.0 * kPi;
    const int ti = std::min(theta_bins - 1, static_cast<int>((1.0 - z) * 0.5 * theta_bins));
    const int pi = std::min(phi_bins - 1, static_cast<int>(phi / (2.0 * kPi) * phi_bins));
    observed[ti * phi_bins + pi] += 1.0;
  }
  // Expected counts: midpoint rule in (z, phi), which is uniform in solid angle.
  double integral = 0.0;
  const double dz = 2.0 / theta_bins, dphi = 2.0 * kPi / phi_bins;
  for (int ti = 0; ti < theta_bins; ++ti)
    for (int pi = 0; pi < phi_bins; ++pi) {
      double sum = 0.0;
      for (int a = 0; a < integration_steps; ++a)
        for (int b = 0; b < integration_steps; ++b) {
          const double z = 1.0 - (ti + (a + 0.5) / integration_steps) * dz;
          const double phi = (pi + (b + 0.5) / integration_steps) * dphi;
          const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
          sum += pdf(glm::vec3(r * std::cos(phi), r * std::sin(phi), z));
        }
      const double cell = sum * dz * dphi / (integration_steps * integration_steps);
      integral += cell;
      expected[ti * phi_bins + pi] = cell * static_cast<double>(samples);
    }
  // Pool cells with small expectations (pbrt-v4 style), sorted by expectation: every cell
  // expecting fewer than 5 samples, and then more cells until the pool expects 5 (a pool
  // expecting 0.05 with one sample in it would add about 19 to the statistic).
  std::vector<int> order(cells);
  for (int i = 0; i < cells; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return expected[a] < expected[b]; });
  double pooled_obs = 0.0, pooled_exp = 0.0, chi2 = 0.0, where_zero = 0.0;
  int dof = 0;
  for (int idx : order) {
    if (expected[idx] == 0.0) {
      where_zero += observed[idx];
      continue;
    }
    if (expected[idx] < 5.0 || (pooled_exp > 0.0 && pooled_exp < 5.0)) {
      pooled_obs += observed[idx];
      pooled_exp += expected[idx];
      continue;
    }
    const double diff = observed[idx] - expected[idx];
    chi2 += diff * diff / expected[idx];
    ++dof;
  }
  if (pooled_exp > 0.0) {
    const double diff = pooled_obs - pooled_exp;
    chi2 += diff * diff / pooled_exp;
    ++dof;
  }
  // Samples where the pdf is zero are a hard failure, counted over all such cells together (at
  // most 1e-5 of the samples, for cells the midpoint rule saw as empty at their edge): made
  // visible as a huge statistic.
  if (where_zero > static_cast<double>(samples) * 1e-5) chi2 += where_zero * 1e6;
  ChiSquareResult result;
  result.statistic = chi2;
  result.degrees_of_freedom = dof - 1;
  result.p_value = incomplete_gamma_q(0.5 * (dof - 1), 0.5 * chi2);
  result.pdf_integral = integral;
  result.sample_fraction = static_cast<double>(valid) / static_cast<double>(samples);
  return result;
}

// Significance per test after the Sidak correction for `tests` tests at overall level alpha.
inline double sidak_alpha(double alpha, int tests) {
  return 1.0 - std::pow(1.0 - alpha, 1.0 / static_cast<double>(tests));
}

}  // namespace rtpg::test

// Quantiles for the statistical image tests: the standard normal and Student's t (two-sided
// bounds for means whose standard error is itself estimated from the data).
#pragma once

#include <cmath>

namespace rtpg::test {

// Regularised incomplete beta I_x(a, b) (Numerical Recipes 6.4: Lentz's continued fraction,
// with the symmetry I_x(a, b) = 1 - I_{1-x}(b, a) where the fraction converges slowly).
inline double incomplete_beta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  if (x > (a + 1.0) / (a + b + 2.0)) return 1.0 - incomplete_beta(b, a, 1.0 - x);
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x)) /
                       a;
  const double tiny = 1e-300;
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::fabs(d) < tiny) d = tiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m < 10000; ++m) {
    const double m2 = 2.0 * m;
    double num = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
    d = 1.0 + num * d;
    c = 1.0 + num / c;
    if (std::fabs(d) < tiny) d = tiny;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    h *= d * c;
    num = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
    d = 1.0 + num * d;
    c = 1.0 + num / c;
    if (std::fabs(d) < tiny) d = tiny;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < 1e-15) break;
  }
  return front * h;
}

// P(|T| > t) for Student's t with `dof` degrees of freedom (real-valued dof allowed, as
// Welch's approximation gives).
inline double student_t_two_sided_p(double t, double dof) {
  return incomplete_beta(0.5 * dof, 0.5, dof / (dof + t * t));
}

// P(|Z| > z) for the standard normal.
inline double normal_two_sided_p(double z) {
  return std::erfc(std::fabs(z) / std::sqrt(2.0));
}

// The t with P(|T| > t) = p (bisection: the tail probability falls monotonically in t).
inline double student_t_two_sided_quantile(double p, double dof) {
  double lo = 0.0, hi = 1.0;
  while (student_t_two_sided_p(hi, dof) > p) hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (student_t_two_sided_p(mid, dof) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The z with P(|Z| > z) = p.
inline double normal_two_sided_quantile(double p) {
  double lo = 0.0, hi = 1.0;
  while (normal_two_sided_p(hi) > p) hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (normal_two_sided_p(mid) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Mean and unbiased variance of a series, accumulated one value at a time (Welford).
struct RunningMoments {
  long long count = 0;
  double mean = 0.0, m2 = 0.0;
  void add(double x) {
    ++count;
    const double delta = x - mean;
    mean += delta / static_cast<double>(count);
    m2 += delta * (x - mean);
  }
  double variance() const { return count > 1 ? m2 / static_cast<double>(count - 1) : 0.0; }
  // Standard error of the mean.
  double standard_error() const { return std::sqrt(variance() / static_cast<double>(count)); }
};

}  // namespace rtpg::test

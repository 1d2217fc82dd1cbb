// Checks of a guiding model shared by the mixture tests (kernels/shared/pmm.h).
#pragma once

#include <gtest/gtest.h>

#include <cmath>

#include "shared/pmm.h"

namespace rtpg::test {

// A valid model has a positive definite Sigma (a real Cholesky factor with positive diagonal),
// pi inside its clamp and its mean inside the square; an invalid model is always sane.
inline ::testing::AssertionResult model_is_sane(const shared::pg_pmm_model& m,
                                                const shared::pg_kernel_settings& p) {
  if (!m.valid) return ::testing::AssertionSuccess();
  if (!(m.l11 > 0.0f) || !(m.l22 > 0.0f) || !std::isfinite(m.l11) || !std::isfinite(m.l22) ||
      !std::isfinite(m.l21))
    return ::testing::AssertionFailure()
           << "Cholesky factor l11=" << m.l11 << " l21=" << m.l21 << " l22=" << m.l22;
  if (!(m.pi >= p.pi_min && m.pi <= p.pi_max))
    return ::testing::AssertionFailure() << "pi=" << m.pi;
  if (!(m.mx >= 0.0f && m.mx <= 1.0f && m.my >= 0.0f && m.my <= 1.0f))
    return ::testing::AssertionFailure() << "mean " << m.mx << "," << m.my;
  return ::testing::AssertionSuccess();
}

}  // namespace rtpg::test

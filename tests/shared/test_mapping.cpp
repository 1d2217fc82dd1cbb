// Closed-form checks of the square <-> hemisphere mapping M (paper eq. 2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "shared/mapping.h"
#include "shared/sincos.h"

using namespace rtpg::shared;

TEST(Mapping, SquareToHemisphereRoundTrips) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 100000; ++i) {
    const float2 p(u(gen), u(gen));
    const float3 w = pg_square_to_hemisphere(p);
    EXPECT_NEAR(length(w), 1.0f, 1e-5f);
    EXPECT_GE(w.z, 0.0f);
    const float2 q = pg_hemisphere_to_square(w);
    ASSERT_NEAR(q.x, p.x, 2e-4f) << p.x << "," << p.y;
    ASSERT_NEAR(q.y, p.y, 2e-4f) << p.x << "," << p.y;
  }
}

TEST(Mapping, HemisphereToSquareRoundTrips) {
  std::mt19937 gen(8);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 100000; ++i) {
    const float3 w = pg_sample_cosine_hemisphere(float2(u(gen), u(gen)));
    if (w.z < 1e-3f) continue;
    const float3 back = pg_square_to_hemisphere(pg_hemisphere_to_square(w));
    ASSERT_NEAR(back.x, w.x, 1e-4f);
    ASSERT_NEAR(back.y, w.y, 1e-4f);
    ASSERT_NEAR(back.z, w.z, 1e-4f);
  }
}

// The Jacobian |dM/du x dM/dv| is 2*pi everywhere (area preserving up to the constant):
// central differences in double-checked float, including near edges and corners.
TEST(Mapping, JacobianIsTwoPiEverywhere) {
  const float h = 1e-3f;
  auto jacobian = [&](float x, float y) {
    const float3 dx =
        (pg_square_to_hemisphere(float2(x + h, y)) - pg_square_to_hemisphere(float2(x - h, y))) /
        (2.0f * h);
    const float3 dy =
        (pg_square_to_hemisphere(float2(x, y + h)) - pg_square_to_hemisphere(float2(x, y - h))) /
        (2.0f * h);
    return length(cross(dx, dy));
  };
  const float points[] = {0.0015f,        0.01f, 0.1f, 0.25f, 0.37f,
                          0.5f + 0.0015f, 0.63f, 0.9f, 0.99f, 0.9985f};
  for (float x : points)
    for (float y : points) {
      // The map has creases on the diagonals (wedge boundaries): stay off them by 2h.
      if (std::fabs(std::fabs(x - 0.5f) - std::fabs(y - 0.5f)) < 2.5f * h) continue;
      EXPECT_NEAR(jacobian(x, y), 2.0f * PG_PI, 0.02f * 2.0f * PG_PI) << x << "," << y;
    }
}

TEST(Mapping, CornersAndCentre) {
  const float3 c = pg_square_to_hemisphere(float2(0.5f, 0.5f));
  EXPECT_NEAR(c.z, 1.0f, 1e-6f);
  for (float x : {0.0f, 1.0f})
    for (float y : {0.0f, 1.0f}) {
      const float3 w = pg_square_to_hemisphere(float2(x, y));
      EXPECT_NEAR(w.z, 0.0f, 1e-5f);  // corners map to the horizon
      EXPECT_NEAR(length(w), 1.0f, 1e-5f);
    }
}

// The samplers' cos and sin (kernels/shared/sincos.h) against double-precision ones: 2^23 + 1
// evenly spaced angles of the octant [-pi/4, pi/4] and small ones down to 1e-30, and 2^20 + 1
// evenly spaced points of the turn [0, 1] with its eighths. The bound, 2e-7 absolute (below 2
// ulp of values near 1), holds with room: the largest error found is 8.9e-8.
TEST(Mapping, CosSinByPolynomialsWithinTwoUlp) {
  double worst = 0.0;
  auto check = [&](double angle, float2 cs, const char* where, double at) {
    const double err =
        std::max(std::fabs(cs.x - std::cos(angle)), std::fabs(cs.y - std::sin(angle)));
    worst = std::max(worst, err);
    if (err > 2e-7)
      ADD_FAILURE() << where << " " << at << ": (" << cs.x << ", " << cs.y << ") error " << err;
  };
  const int m = 1 << 22;
  for (int i = -m; i <= m; ++i) {  // evenly spaced over the octant, and both ends exactly
    const float a =
        std::clamp(static_cast<float>(i) / m * (PG_PI / 4.0f), -PG_PI / 4.0f, PG_PI / 4.0f);
    check(a, pg_cos_sin_octant(a), "octant", a);
  }
  for (float a = 1e-30f; a < 1e-2f; a *= 1.01f) check(a, pg_cos_sin_octant(a), "octant", a);
  const int n = 1 << 20;
  for (int i = 0; i <= n; ++i) {
    const float u = static_cast<float>(i) / n;
    check(2.0 * M_PI * u, pg_cos_sin_turn(u), "turn", u);
  }
  for (float u : {0.125f, 0.25f, 0.375f, 0.5f, 0.625f, 0.75f, 0.875f, 1.0f, 0.99999994f})
    check(2.0 * M_PI * u, pg_cos_sin_turn(u), "turn", u);
  std::printf("[ info     ] cos and sin by polynomials: largest error %.3g\n", worst);
}

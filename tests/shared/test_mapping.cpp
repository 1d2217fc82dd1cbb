// Closed-form checks of the square <-> hemisphere mapping M (paper eq. 2).
#include <gtest/gtest.h>

#include <random>

#include "shared/mapping.h"

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

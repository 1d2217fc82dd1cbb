// The samples as they cross the bus back (kernels/shared/sample_packing.h, include/rtpg/
// guiding_layout.h "Packed samples"): the direction's octahedral floats come back within 5e-7
// rad everywhere on the sphere, its folds and poles included; the density exactly, with the
// strategy.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "rtpg/guiding_layout.h"
#include "shared/sample_packing.h"
#include "support/angles.h"

using namespace rtpg::shared;

namespace {

using rtpg::testing::angle_between;

// Radians, with margin (measured 3.5e-7 over 1e6 directions): a few times the rounding of a
// unit vector stored in three floats.
constexpr double kMaxAngle = 5e-7;

TEST(SamplePacking, DirectionsComeBackWithinTheirBound) {
  std::mt19937 gen(17);
  std::normal_distribution<float> normal;
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  double worst = 0.0;
  for (int k = 0; k < 1000000; ++k) {
    float3 v(normal(gen), normal(gen), normal(gen));
    if (k % 4 == 1) v.z = 1e-4f * unit(gen);  // near the equator, where the folds meet
    if (k % 4 == 2) v.x = 1e-6f * unit(gen);  // near a fold of the lower half
    v = normalize(v);
    const float3 back = pg_unpack_direction(pg_pack_direction(v));
    const double angle = angle_between(back, v);
    worst = std::max(worst, angle);
    ASSERT_LT(angle, kMaxAngle) << v.x << " " << v.y << " " << v.z;
    ASSERT_NEAR(dot(back, back), 1.0f, 4.0f * std::numeric_limits<float>::epsilon());
  }
  // The axes, both poles and the folds' signed zeros.
  const float3 special[] = {{0, 0, 1},      {0, 0, -1},       {1, 0, 0},           {-1, 0, 0},
                            {0, 1, 0},      {0, -1, 0},       {1, 0, -0.0f},       {-0.0f, 0, -1},
                            {0, -0.0f, -1}, {0.6f, -0.8f, 0}, {-0.6f, 0.0f, -0.8f}};
  for (const float3& v : special) {
    const float3 back = pg_unpack_direction(pg_pack_direction(v));
    EXPECT_LT(angle_between(back, v), kMaxAngle) << v.x << " " << v.y << " " << v.z;
  }
  std::printf("[ info     ] worst angle %.3g rad over 1e6 directions\n", worst);
}

TEST(SamplePacking, DensityAndStrategyComeBackExactly) {
  const float densities[] = {0.0f, 1e-38f, 1e-30f, 0.0318f,
                             1.0f, 3.5e4f, 1e30f,  std::numeric_limits<float>::infinity()};
  for (float pdf : densities) {
    for (uint strategy : {PG_STRATEGY_BSDF, PG_STRATEGY_GUIDE}) {
      const float packed = pg_pack_sample_density(pdf, strategy);
      EXPECT_EQ(pg_sample_density_of(packed), pdf) << pdf << " " << strategy;
      // A zero density is no sample whichever strategy drew it, as the renderer reads it.
      const uint expected =
          pdf == 0.0f && strategy == PG_STRATEGY_BSDF ? PG_STRATEGY_NONE : strategy;
      EXPECT_EQ(pg_sample_strategy_of(packed), expected) << pdf << " " << strategy;
    }
  }
  EXPECT_EQ(pg_sample_strategy_of(pg_pack_sample_density(0.0f, PG_STRATEGY_NONE)),
            PG_STRATEGY_NONE);
  EXPECT_EQ(pg_sample_density_of(pg_pack_sample_density(0.0f, PG_STRATEGY_NONE)), 0.0f);
  // A NaN density (which the renderer treats as no sample) stays NaN.
  EXPECT_TRUE(std::isnan(pg_sample_density_of(
      pg_pack_sample_density(std::numeric_limits<float>::quiet_NaN(), PG_STRATEGY_GUIDE))));
}

}  // namespace

// The VPLs' packed channel (kernels/shared/vpl_packing.h, include/rtpg/guiding_layout.h "VPLs"):
// round trips and error bounds of each field, and the public packer's agreement with it.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "rtpg/errors.h"
#include "rtpg/vpl_packing.h"
#include "support/angles.h"
#include "shared/vpl_packing.h"

using namespace rtpg::shared;

namespace {

using rtpg::testing::angle_between;

TEST(VplPacking, UnitVectorsWithinTheirAngularBound) {
  std::mt19937 gen(11);
  std::normal_distribution<float> g;
  double worst = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    float3 n(g(gen), g(gen), g(gen));
    n = n * (1.0f / std::sqrt(dot(n, n)));
    // Three quarters of them near the octahedron's edges and vertices, where the map folds.
    if (i % 4 == 1) n.z = n.z * 1e-3f;
    if (i % 4 == 2) n.x = n.x * 1e-3f;
    if (i % 4 == 3) n.y = n.y * 1e-4f;
    n = n * (1.0f / std::sqrt(dot(n, n)));
    const float3 m = pg_unpack_unit_vector(pg_pack_unit_vector(n));
    ASSERT_NEAR(std::sqrt(dot(m, m)), 1.0f, 1e-6f);
    worst = std::max(worst, angle_between(n, m));
  }
  EXPECT_LT(worst, PG_OCTAHEDRAL_MAX_ANGLE);
  // The axes come back exactly; the zero vector (a distant VPL's) packs as +z.
  for (int axis = 0; axis < 3; ++axis)
    for (float s : {1.0f, -1.0f}) {
      float3 n(0.0f);
      n[axis] = s;
      const float3 m = pg_unpack_unit_vector(pg_pack_unit_vector(n));
      EXPECT_EQ(m, n) << axis << " " << s;
    }
  EXPECT_EQ(pg_unpack_unit_vector(pg_pack_unit_vector(float3(0.0f))), float3(0.0f, 0.0f, 1.0f));
}

TEST(VplPacking, Bfloat16RoundsToNearestEven) {
  for (uint b = 0; b < 0x10000u; ++b) {
    const uint exponent = (b >> 7) & 0xffu;
    if (exponent == 0xffu) continue;  // infinities and NaNs: radiance is finite
    const float v = as_float(b << 16);
    ASSERT_EQ(pg_bfloat16_bits(v), b) << std::hex << b;
    ASSERT_EQ(as_uint(pg_float_of_bfloat16(b)), b << 16);
    // The midpoint to the next value rounds to the even one of the two; either side of it,
    // to the nearer.
    const uint next = (b + 1u) & 0xffffu;
    if (((next >> 7) & 0xffu) == 0xffu) continue;
    const float mid = as_float((b << 16) | 0x8000u);
    ASSERT_EQ(pg_bfloat16_bits(mid), (b & 1u) ? next : b) << std::hex << b;
    ASSERT_EQ(pg_bfloat16_bits(as_float((b << 16) | 0x7fffu)), b) << std::hex << b;
    ASSERT_EQ(pg_bfloat16_bits(as_float((b << 16) | 0x8001u)), next) << std::hex << b;
  }
  // Finite values above the largest bfloat16 stay finite.
  const float largest = pg_float_of_bfloat16(0x7f7fu);
  EXPECT_EQ(pg_float_of_bfloat16(pg_bfloat16_bits(std::numeric_limits<float>::max())), largest);
  EXPECT_TRUE(std::isfinite(largest));
}

TEST(VplPacking, RadianceWithinHalfAUnitInTheLastPlace) {
  std::mt19937 gen(3);
  std::uniform_real_distribution<float> exponent(-30.0f, 30.0f);
  double worst = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const float v = std::pow(10.0f, exponent(gen));  // 1e-30 .. 1e30: a sun's radiance and less
    const float r = pg_float_of_bfloat16(pg_bfloat16_bits(v));
    worst = std::max(worst, std::fabs(static_cast<double>(r) - v) / v);
  }
  EXPECT_LE(worst, std::ldexp(1.0, -8));
}

TEST(VplPacking, ChannelKeepsEveryField) {
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (uint info = 0; info < 0x10000u; ++info) {
    const float3 normal = pg_unpack_unit_vector(pg_pack_unit_vector(
        float3(u(gen) - 0.5f, u(gen) - 0.5f, u(gen) - 0.5f)));  // already on the grid
    const float density = std::ldexp(u(gen), static_cast<int>(info % 200u) - 100);
    const float3 radiance(pg_float_of_bfloat16(info), pg_float_of_bfloat16(info ^ 0x1234u),
                          pg_float_of_bfloat16(info & 0x7f00u));
    if (!std::isfinite(radiance.x) || !std::isfinite(radiance.y)) continue;
    const uint4 p = pg_pack_vpl_normal_radiance(normal, density, radiance, info);
    ASSERT_EQ(pg_vpl_info(p), info);
    ASSERT_EQ(pg_vpl_mixture_density(p), density);
    ASSERT_EQ(as_uint(pg_vpl_radiance(p).x), as_uint(radiance.x)) << info;
    ASSERT_EQ(as_uint(pg_vpl_radiance(p).y), as_uint(radiance.y)) << info;
    ASSERT_EQ(as_uint(pg_vpl_radiance(p).z), as_uint(radiance.z)) << info;
    ASSERT_LT(angle_between(pg_vpl_normal(p), normal), 1e-6) << info;
    // The parts the path tracer writes at different times are the same words.
    ASSERT_EQ(p, pg_make_uint4(pg_pack_vpl_normal(normal), pg_pack_vpl_density(density),
                               pg_pack_vpl_radiance_rg(radiance),
                               pg_pack_vpl_radiance_b_info(radiance, info)));
  }
}

TEST(VplPacking, PublicPackerWritesTheKernelsLayout) {
  const std::array<std::uint32_t, 4> p =
      rtpg::pack_vpl_normal_radiance({0.6f, 0.0f, -0.8f}, 0.25f, {1.0f, 2.0f, 1e6f}, 0x0201u);
  const uint4 q = pg_pack_vpl_normal_radiance(float3(0.6f, 0.0f, -0.8f), 0.25f,
                                              float3(1.0f, 2.0f, 1e6f), 0x0201u);
  EXPECT_EQ(p[0], q.x);
  EXPECT_EQ(p[1], q.y);
  EXPECT_EQ(p[2], q.z);
  EXPECT_EQ(p[3], q.w);
  EXPECT_THROW(
      rtpg::pack_vpl_normal_radiance({0.0f, 0.0f, 1.0f}, 1.0f, {1.0f, 1.0f, 1.0f}, 0x10000u),
      rtpg::GuiderError);
}

}  // namespace

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
  double worst = 0.0, worst8 = 0.0;
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
    const float3 m8 = pg_unpack_unit_vector8(pg_pack_unit_vector8(n));
    ASSERT_NEAR(std::sqrt(dot(m8, m8)), 1.0f, 1e-6f);
    worst8 = std::max(worst8, angle_between(n, m8));
  }
  EXPECT_LT(worst, PG_OCTAHEDRAL_MAX_ANGLE);
  EXPECT_LT(worst8, PG_OCTAHEDRAL8_MAX_ANGLE);
  std::printf("[ info     ] worst angles %.3g rad (16 bits), %.3g rad (8 bits)\n", worst, worst8);
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

// Every 8-bit code's 16-bit one (pg_unit_vector8_to_16, what the device's VPL unpacking hands
// the training): each coordinate the nearest 16-bit value to k / 127, computed here in double,
// and the same direction as the 8-bit code within the 16-bit packing's bound. Through the unit
// vector and back (the float path it replaced) the bits agree except on the square's border,
// whose two halves fold onto the same directions, and where a coordinate lies within float
// rounding of a half.
TEST(VplPacking, EightBitNormalsBecomeSixteenBitOnesOfTheSameDirection) {
  double worst = 0.0;
  int other_bits = 0;
  for (uint code = 0; code < 0x10000u; ++code) {
    const uint bits = pg_unit_vector8_to_16(code);
    int k[2];
    for (int c = 0; c < 2; ++c) {
      k[c] = std::max(static_cast<int>(static_cast<std::int8_t>((code >> (8 * c)) & 0xffu)), -127);
      const long nearest = std::lround(static_cast<double>(k[c]) * 32767.0 / 127.0);
      ASSERT_EQ(static_cast<int>(static_cast<std::int16_t>((bits >> (16 * c)) & 0xffffu)), nearest)
          << std::hex << code;
    }
    const float3 n8 = pg_unpack_unit_vector8(code), n16 = pg_unpack_unit_vector(bits);
    worst = std::max(worst, angle_between(n8, n16));
    if (bits != pg_pack_unit_vector(n8)) {
      ++other_bits;
      const auto border_or_near_half = [](int v) {
        return std::abs(v) == 127 || std::abs(v) == 63 || std::abs(v) == 64;
      };
      EXPECT_TRUE(border_or_near_half(k[0]) || border_or_near_half(k[1]))
          << std::hex << code << std::dec << ": " << k[0] << " " << k[1];
    }
  }
  EXPECT_LT(worst, PG_OCTAHEDRAL_MAX_ANGLE);
  std::printf("[ info     ] worst angle %.3g rad; %d codes differ from the float path's bits\n",
              worst, other_bits);
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

// The shared-exponent radiance (pg_pack_rgbe): the brightest channel within 2^-8 of its value,
// each other within 2^-7 of the brightest (2^-8 but where the brightest rounds up to a power), over
// 12 decades and every hue; black, negative and NaN channels as 0; a sun's radiance (1e6 to 1e9)
// kept; above 2^127 saturated.
TEST(VplPacking, SharedExponentRadianceWithinItsBound) {
  std::mt19937 gen(23);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int k = 0; k < 200000; ++k) {
    const float scale = std::pow(10.0f, -6.0f + 15.0f * u(gen));
    float3 c(u(gen) * scale, u(gen) * scale, u(gen) * scale);
    if (k % 5 == 0) c[k % 3] = 0.0f;
    const float m = std::max(c.x, std::max(c.y, c.z));
    const float3 back = pg_unpack_rgbe(pg_pack_rgbe(c));
    for (int ch = 0; ch < 3; ++ch) {
      const float bound = std::ldexp(m, -7);
      ASSERT_LE(std::fabs(back[ch] - c[ch]), bound) << k << " " << ch << " " << c[ch];
      if (c[ch] == m) {
        ASSERT_LE(std::fabs(back[ch] - c[ch]), std::ldexp(c[ch], -8)) << k;
      }
    }
  }
  EXPECT_EQ(pg_pack_rgbe(float3(0.0f)), 0u);
  EXPECT_EQ(pg_unpack_rgbe(0u), float3(0.0f));
  EXPECT_EQ(pg_unpack_rgbe(pg_pack_rgbe(float3(-1.0f, std::nanf(""), 2.0f))), float3(0, 0, 2));
  EXPECT_EQ(pg_unpack_rgbe(pg_pack_rgbe(float3(1e-31f))), float3(0.0f));  // below 2^-100
  // Powers of two and values that round up to the next power come back exactly or within bound.
  EXPECT_EQ(pg_unpack_rgbe(pg_pack_rgbe(float3(1.0f, 0.5f, 0.25f))), float3(1.0f, 0.5f, 0.25f));
  EXPECT_EQ(pg_unpack_rgbe(pg_pack_rgbe(float3(255.9f, 0.0f, 0.0f))).x, 256.0f);
  const float huge = pg_unpack_rgbe(pg_pack_rgbe(float3(1e38f * 3.0f, 0.0f, 0.0f))).x;
  EXPECT_TRUE(std::isfinite(huge));
  EXPECT_GT(huge, 1e38f);
}

// A VPL through the bus (its distance, pg_pack_unit_vector8, pg_pack_rgbe; pg_unpack_vpl) as the
// device rebuilds it from its own point and sample: at, beyond (escaped) and without a hit, for
// either strategy, the position within a few ulp of where the host found it, the densities in
// area measure within the normal's rounding of the host's conversion, the radiance within its
// shared exponent, the info bits the host's.
TEST(VplPacking, BusRoundTripRebuildsTheVpl) {
  std::mt19937 gen(29);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::normal_distribution<float> g;
  const auto unit = [&] {
    float3 v(g(gen), g(gen), g(gen));
    return v * (1.0f / std::sqrt(dot(v, v)));
  };
  for (int k = 0; k < 20000; ++k) {
    const float3 x0(u(gen) * 5.0f, u(gen) * 5.0f, u(gen) * 5.0f);
    float3 w = unit();
    const float d = std::pow(10.0f, -2.0f + 3.0f * (0.5f + 0.5f * u(gen)));
    float3 n = unit();
    if (dot(n, w) > 0.0f) n = -n;  // facing x0
    const float cos_y = std::fabs(dot(n, w));
    if (cos_y < 0.05f) continue;  // grazing: the 8-bit normal's cosine error is the whole bound
    const float density = 0.3f + 2.0f * (0.5f + 0.5f * u(gen)), bsdf = 0.5f * density;
    const uint strategy = k % 2 ? PG_STRATEGY_BSDF : PG_STRATEGY_GUIDE;
    const float strategy_pdf = strategy == PG_STRATEGY_BSDF ? bsdf : density;
    const float3 radiance(0.5f + 0.5f * u(gen), 2.0f, 0.01f);
    const bool distant = k % 7 == 0, invalid = k % 11 == 0;
    // What the path tracer writes (host/render/path_tracer.cpp).
    const float3 y = distant ? w : x0 + w * d;
    const float to_area = distant ? 1.0f : cos_y / (d * d);
    uint info = strategy << PG_VPL_STRATEGY_SHIFT;
    if (!invalid) info |= PG_VPL_VALID | (distant ? PG_VPL_DISTANT : 0u);
    const float4 position(y.x, y.y, y.z, strategy_pdf * to_area);
    const uint4 nr =
        pg_pack_vpl_normal_radiance(distant ? float3(0.0f) : n, density * to_area, radiance, info);
    // And its packed form, as the path tracer writes it beside (host/render/path_tracer.cpp).
    const uint distance = invalid ? 0u : distant ? 0x7f800000u : as_uint(length(y - x0));
    const uint normal = distant ? 0u : pg_pack_unit_vector8(n);
    const pg_vpl v = pg_unpack_vpl(distance, pg_pack_rgbe(radiance), normal, x0,
                                   float4(w.x, w.y, w.z, density), strategy, bsdf);
    if (invalid) {
      ASSERT_EQ(v.normal_radiance, uint4(0u)) << k;
      ASSERT_EQ(v.position, float4(0.0f)) << k;
      continue;
    }
    ASSERT_EQ(pg_vpl_info(v.normal_radiance), info) << k;
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(v.position[c], y[c], 1e-6f * (std::fabs(y[c]) + 10.0f * (1.0f + d))) << k;
    // The cosine through the 8-bit normal: within sin(2e-2) of the exact one.
    const float area_bound = distant ? 1e-6f : PG_OCTAHEDRAL8_MAX_ANGLE / cos_y + 1e-5f;
    ASSERT_NEAR(v.position.w / position.w, 1.0f, area_bound) << k;
    ASSERT_NEAR(pg_vpl_mixture_density(v.normal_radiance) / pg_vpl_mixture_density(nr), 1.0f,
                area_bound)
        << k;
    ASSERT_LT(angle_between(pg_vpl_normal(v.normal_radiance), distant ? float3(0, 0, 1) : n),
              PG_OCTAHEDRAL8_MAX_ANGLE + PG_OCTAHEDRAL_MAX_ANGLE)
        << k;
    const float3 l = pg_vpl_radiance(v.normal_radiance), l0 = pg_vpl_radiance(nr);
    // The shared exponent's 2^-7 of the brightest (2), and the two bfloat16 roundings.
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(l[c], l0[c], std::ldexp(2.0f, -6)) << k;
  }
}

}  // namespace

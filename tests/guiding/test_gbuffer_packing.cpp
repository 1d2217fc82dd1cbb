// The G-buffer as it crosses the bus (kernels/shared/gbuffer_packing.h, include/rtpg/
// guiding_layout.h "Packed G-buffer"): the half float's rounding checked against its definition
// over every half, and each packed field's round trip and error bound.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "rtpg/guiding_layout.h"
#include "support/angles.h"
#include "shared/gbuffer_packing.h"

using namespace rtpg::shared;

namespace {

using rtpg::testing::angle_between;

// Every finite half's value comes back to its bits (both signs, subnormals, zero).
TEST(GBufferPacking, EveryFiniteHalfRoundTrips) {
  for (uint bits = 0; bits < 0x10000u; ++bits) {
    if ((bits & 0x7c00u) == 0x7c00u) continue;  // infinities and NaNs: never made
    const float v = pg_float_of_half(bits);
    ASSERT_TRUE(std::isfinite(v)) << bits;
    ASSERT_EQ(pg_half_bits(v), bits) << "half " << bits << " = " << v;
    ASSERT_EQ(std::signbit(v), (bits & 0x8000u) != 0u) << bits;
  }
  // The value of the smallest subnormal, the largest subnormal and the largest half.
  EXPECT_EQ(pg_float_of_half(1u), std::ldexp(1.0f, -24));
  EXPECT_EQ(pg_float_of_half(0x03ffu), std::ldexp(1023.0f, -24));
  EXPECT_EQ(pg_float_of_half(0x7bffu), 65504.0f);
}

// Between every two neighbouring halves, a float rounds to the nearer one, and a float exactly
// half-way to the one whose last bit is 0 (round to nearest, ties to even: IEEE 754's
// conversion). Checked at the midpoint and at the floats just beside it.
TEST(GBufferPacking, HalvesRoundToNearestTiesToEven) {
  for (uint bits = 0; bits < 0x7bffu; ++bits) {
    const float lo = pg_float_of_half(bits), hi = pg_float_of_half(bits + 1u);
    const float mid = 0.5f * (lo + hi);  // exact: halves have 11 significant bits
    ASSERT_EQ(static_cast<double>(mid), 0.5 * (static_cast<double>(lo) + hi));
    const uint even = (bits & 1u) == 0u ? bits : bits + 1u;
    ASSERT_EQ(pg_half_bits(mid), even) << bits;
    ASSERT_EQ(pg_half_bits(std::nextafter(mid, 0.0f)), bits) << bits;
    ASSERT_EQ(pg_half_bits(std::nextafter(mid, 1e30f)), bits + 1u) << bits;
    ASSERT_EQ(pg_half_bits(-mid), even | 0x8000u) << bits;
  }
}

TEST(GBufferPacking, HalvesSaturateInsteadOfOverflowing) {
  EXPECT_EQ(pg_half_bits(65504.0f), 0x7bffu);
  EXPECT_EQ(pg_half_bits(65519.0f), 0x7bffu);  // would round to infinity
  EXPECT_EQ(pg_half_bits(1e30f), 0x7bffu);
  EXPECT_EQ(pg_half_bits(std::numeric_limits<float>::max()), 0x7bffu);
  EXPECT_EQ(pg_half_bits(-1e30f), 0xfbffu);
  EXPECT_EQ(pg_half_bits(1e-30f), 0u);                 // below half the smallest subnormal: zero
  EXPECT_EQ(pg_half_bits(std::ldexp(1.0f, -25)), 0u);  // tie: to even (0)
  EXPECT_EQ(pg_half_bits(std::nextafter(std::ldexp(1.0f, -25), 1.0f)), 1u);
}

// Random pixels of every kind of value a renderer writes: what the layout says travels exactly
// does, the normal comes back within the octahedral bound, the material within a half's
// rounding.
TEST(GBufferPacking, PixelsRoundTripWithinTheirBounds) {
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), wide(-1e4f, 1e4f);
  std::normal_distribution<float> normal;
  const auto random_unit = [&] {
    float3 v(normal(gen), normal(gen), normal(gen));
    return v * (1.0f / std::sqrt(dot(v, v)));
  };
  for (int k = 0; k < 200000; ++k) {
    // Scales from 1e-4 to 1e4 (the extreme-scale scenes), colours down to 1e-4.
    const float scale = std::pow(10.0f, -4.0f + 8.0f * unit(gen));
    const float4 position_depth(wide(gen) * scale, wide(gen) * scale, wide(gen) * scale,
                                unit(gen) * 1e4f * scale);
    const float3 n = random_unit();
    const float4 shading_normal(n.x, n.y, n.z, 0.0f);
    const float dark = std::pow(10.0f, -4.0f * unit(gen));
    const float4 bcr(unit(gen) * dark, unit(gen), unit(gen), unit(gen));
    const float4 ms(unit(gen), 0.04f * unit(gen), 0.0f, 0.0f);
    const uint flags = static_cast<uint>(gen() & 0xfu);
    const uint material = static_cast<uint>(gen() & PG_PACKED_MATERIAL_MAX);

    const uint4 surface = pg_pack_gbuffer_surface(position_depth, shading_normal, bcr);
    const uint2 shading = pg_pack_gbuffer_shading(ms, flags, material);

    ASSERT_EQ(pg_unpack_gbuffer_depth(surface), position_depth.w);
    ASSERT_EQ(pg_unpack_gbuffer_flags(shading), flags);
    ASSERT_EQ(pg_unpack_gbuffer_material(shading), material);
    const float4 n2 = pg_unpack_gbuffer_shading_normal(surface);
    ASSERT_EQ(n2.w, 0.0f);
    ASSERT_LT(angle_between(pg_float4_xyz(n2), n), PG_OCTAHEDRAL_MAX_ANGLE) << k;
    const float4 bcr2 = pg_unpack_gbuffer_base_color_roughness(surface);
    const float4 ms2 = pg_unpack_gbuffer_metallic_specular(shading);
    for (int c = 0; c < 4; ++c) {
      // Relative 2^-11 in the normal range, absolute 2^-25 among the subnormals.
      const float bound =
          std::max(std::fabs(bcr[c]) * std::ldexp(1.0f, -11), std::ldexp(1.0f, -25));
      ASSERT_LE(std::fabs(bcr2[c] - bcr[c]), bound) << k << " channel " << c;
    }
    for (int c = 0; c < 2; ++c)
      ASSERT_LE(std::fabs(ms2[c] - ms[c]),
                std::max(std::fabs(ms[c]) * std::ldexp(1.0f, -11), std::ldexp(1.0f, -25)));
    ASSERT_EQ(ms2.z, 0.0f);
    ASSERT_EQ(ms2.w, 0.0f);
  }
}

// The sky's pixels as GBuffer::resize writes them (normal +z, everything else 0) come back bit
// for bit, the position at the origin whatever the camera.
TEST(GBufferPacking, SkyPixelsRoundTripExactly) {
  const float4 zero(0.0f), up(0.0f, 0.0f, 1.0f, 0.0f);
  const uint4 surface = pg_pack_gbuffer_surface(zero, up, zero);
  const uint2 shading = pg_pack_gbuffer_shading(zero, PG_GBUF_SKY, 0u);
  rtpg::pg_pinhole_camera camera{};
  camera.position_x = 3.0f;
  camera.forward_z = -1.0f;
  EXPECT_EQ(pg_gbuffer_position_depth(camera, float3(0.0f, 0.0f, -1.0f),
                                      pg_unpack_gbuffer_depth(surface)),
            zero);
  EXPECT_EQ(pg_unpack_gbuffer_shading_normal(surface), up);
  EXPECT_EQ(pg_unpack_gbuffer_base_color_roughness(surface), zero);
  EXPECT_EQ(pg_unpack_gbuffer_metallic_specular(shading), zero);
  EXPECT_EQ(pg_unpack_gbuffer_flags(shading), PG_GBUF_SKY);
}

}  // namespace

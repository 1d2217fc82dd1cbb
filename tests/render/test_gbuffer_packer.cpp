// The host's G-buffer packer (host/render/gbuffer_packer.h): the lane variant (AVX2, F16C) gives
// the shared functions' bits (kernels/shared/gbuffer_packing.h) for every kind of pixel, at
// ranges that do not start or end on a multiple of its eight lanes; material ids and flags that
// do not fit are reported, not silently cut.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "render/gbuffer_packer.h"
#include "render/guided_first_bounce.h"
#include "rtpg/cl_runtime.h"
#include "shared/gbuffer_packing.h"

namespace rtpg {
namespace {

using shared::float2;
using shared::float3;
using shared::float4;

// Pixels of every kind the packing meets: sky (GBuffer::resize's values), unit vectors on the
// axes and the octahedron's folds (z = +-0, x or y = 0), random ones, colours from 0 through
// half-float subnormals to above the largest half, positions at extreme scales.
GBuffer varied_gbuffer(int w, int h, std::uint32_t seed) {
  GBuffer g;
  g.resize(w, h);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::normal_distribution<float> normal;
  const float3 special[] = {{0, 0, 1},     {0, 0, -1},          {1, 0, 0},
                            {-1, 0, 0},    {0, 1, 0},           {0, -1, 0},
                            {1, 0, -0.0f}, {0.6f, -0.8f, 0.0f}, {-0.6f, 0.0f, -0.8f}};
  const float colour[] = {0.0f, -0.0f, 1e-9f, 3e-8f, 6.1e-5f, 0.04f, 0.5f, 1.0f, 70000.0f, 1e30f};
  const auto unit = [&] {
    if (gen() % 4 == 0) return special[gen() % std::size(special)];
    float3 v(normal(gen), normal(gen), normal(gen));
    return v * (1.0f / std::sqrt(dot(v, v)));
  };
  for (std::size_t i = 0; i < g.pixel_count(); ++i) {
    if (gen() % 10 == 0) continue;  // sky
    const float scale = std::pow(10.0f, 6.0f * u(gen));
    g.position_depth[i] = float4(u(gen) * scale, u(gen) * scale, u(gen) * scale, scale);
    const float3 n = unit(), v = unit();
    g.shading_normal[i] = float4(n, 0.0f);
    g.view_dir[i] = float4(v, 0.0f);
    const auto c = [&] {
      return gen() % 3 == 0 ? colour[gen() % std::size(colour)] : 0.5f + 0.5f * u(gen);
    };
    g.base_color_roughness[i] = float4(c(), c(), c(), c());
    g.metallic_specular[i] = float4(c(), c(), 0.0f, 0.0f);
    g.flags[i] = gen() % 16u;
    g.material[i] = gen() % (PG_PACKED_MATERIAL_MAX + 1u);
    g.motion[i] = float2(100.0f * u(gen), 100.0f * u(gen));
  }
  return g;
}

struct Packed {
  std::vector<shared::uint4> surface, view_material;
  std::vector<shared::uint2> shading;
  std::vector<float2> motion;
  explicit Packed(std::size_t n) : surface(n), view_material(n), shading(n), motion(n) {}
  PackedGBufferView view() {
    return {surface.data(), view_material.data(), shading.data(), motion.data()};
  }
};

TEST(GBufferPacker, LanesGiveTheSharedFunctionsBits) {
  if (!cpu_runs_gbuffer_packer_lanes()) GTEST_SKIP() << "this CPU has no AVX2 and F16C";
  const GBuffer g = varied_gbuffer(61, 37, 3);
  const std::size_t n = g.pixel_count();
  // Whole image, then ranges starting and ending off the lanes' multiples of eight.
  const std::pair<std::size_t, std::size_t> ranges[] = {{0, n}, {3, 3 + 8 * 20 + 5}, {n - 7, n}};
  for (const auto& [first, last] : ranges) {
    SCOPED_TRACE(std::to_string(first) + ".." + std::to_string(last));
    Packed base(n), lanes(n);
    EXPECT_TRUE(pack_gbuffer(g, first, last, base.view(), CpuCode::baseline));
    EXPECT_TRUE(pack_gbuffer(g, first, last, lanes.view(), CpuCode::avx2));
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(lanes.surface[i], base.surface[i]) << i;
      ASSERT_EQ(lanes.view_material[i], base.view_material[i]) << i;
      ASSERT_EQ(lanes.shading[i], base.shading[i]) << i;
      ASSERT_EQ(lanes.motion[i], base.motion[i]) << i;
    }
    // And they are the shared functions' words, outside the range untouched.
    for (std::size_t i = 0; i < n; ++i) {
      const bool inside = i >= first && i < last;
      const shared::uint4 s =
          inside ? shared::pg_pack_gbuffer_surface(g.position_depth[i], g.shading_normal[i])
                 : shared::uint4(0u);
      ASSERT_EQ(base.surface[i], s) << i;
    }
  }
}

TEST(GBufferPacker, MaterialIdsAndFlagsThatDoNotFitAreReported) {
  std::vector<CpuCode> codes = {CpuCode::baseline};
  if (cpu_runs_gbuffer_packer_lanes()) codes.push_back(CpuCode::avx2);
  for (CpuCode code : codes) {
    for (std::size_t bad : {std::size_t{0}, std::size_t{13}, std::size_t{40}}) {
      GBuffer g = varied_gbuffer(41, 1, 7);
      Packed p(g.pixel_count());
      EXPECT_TRUE(pack_gbuffer(g, 0, g.pixel_count(), p.view(), code));
      g.material[bad] = PG_PACKED_MATERIAL_MAX + 1u;
      EXPECT_FALSE(pack_gbuffer(g, 0, g.pixel_count(), p.view(), code)) << bad;
      g.material[bad] = 0u;
      g.flags[bad] = 0x100u;
      EXPECT_FALSE(pack_gbuffer(g, 0, g.pixel_count(), p.view(), code)) << bad;
    }
  }
}

// The guided first bounce with --host-transfer packed refuses, with the reason and the way out, a
// G-buffer whose material id does not fit, and goes on with the next good one.
TEST(GBufferPacker, PackedTransferRefusesAMaterialIdThatDoesNotFit) {
  ClRuntime cl;
  GBuffer g = varied_gbuffer(19, 7, 5);
  GuidedFirstBounce sampler(cl, 19, 7, GuidingSettings{}, HostTransfer::packed);
  ASSERT_EQ(sampler.host_transfer(), HostTransfer::packed);
  sampler.begin_frame(g, SampleCoordinates{1, 0, 0});
  g.material[100] = PG_PACKED_MATERIAL_MAX + 1u;
  try {
    sampler.begin_frame(g, SampleCoordinates{1, 1, 0});
    ADD_FAILURE() << "no GuiderError";
  } catch (const GuiderError& e) {
    EXPECT_NE(std::string(e.what()).find("material id"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--host-transfer pinned"), std::string::npos) << e.what();
  }
  g.material[100] = 0u;
  EXPECT_NO_THROW(sampler.begin_frame(g, SampleCoordinates{1, 2, 0}));
}

}  // namespace
}  // namespace rtpg

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
#include "render/renderer.h"
#include "rtpg/cl_runtime.h"
#include "scene/scene_loader.h"
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
  std::vector<shared::uint4> surface;
  std::vector<shared::uint2> shading;
  explicit Packed(std::size_t n) : surface(n), shading(n) {}
  PackedGBufferView view() { return {surface.data(), shading.data()}; }
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
      ASSERT_EQ(lanes.shading[i], base.shading[i]) << i;
    }
    // And they are the shared functions' words, outside the range untouched.
    for (std::size_t i = 0; i < n; ++i) {
      const bool inside = i >= first && i < last;
      const shared::uint4 s =
          inside ? shared::pg_pack_gbuffer_surface(g.position_depth[i], g.shading_normal[i],
                                                   g.base_color_roughness[i])
                 : shared::uint4(0u);
      ASSERT_EQ(base.surface[i], s) << i;
      const shared::uint2 m = inside ? shared::pg_pack_gbuffer_shading(g.metallic_specular[i],
                                                                       g.flags[i], g.material[i])
                                     : shared::uint2(0u);
      ASSERT_EQ(base.shading[i], m) << i;
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

// What the device derives instead of receiving is the renderer's own G-buffer: each pixel's
// camera ray (pg_gbuffer_camera_ray, from gbuffer_cameras) is the renderer's to the bit, so its
// view direction is too; the point at the pixel's depth along it lies within 4e-6 of the depth
// from the renderer's (which interpolates the triangle's corners), and its motion vector within
// 1e-3 pixels; along a camera path at an odd size, with the camera held still, and without
// jitter.
TEST(GBufferPacker, DerivedChannelsAreTheRenderersOwn) {
  const Scene scene = load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
  for (const int held : {-1, 3}) {
    for (const bool jitter : {true, false}) {
      RenderSettings settings;
      settings.width = 37;
      settings.height = 23;
      settings.camera_path = "pan";
      settings.camera_frame = held;
      settings.jitter = jitter;
      Renderer renderer(scene, settings);
      for (int f = 0; f < 3; ++f) {
        SCOPED_TRACE("frame " + std::to_string(f) + (held >= 0 ? ", camera held" : "") +
                     (jitter ? "" : ", no jitter"));
        renderer.render_frame(f);
        const GBuffer& g = renderer.gbuffer();
        const pg_gbuffer_cameras cameras = gbuffer_cameras(g);
        EXPECT_EQ(cameras.width, 37);
        EXPECT_EQ(cameras.height, 23);
        EXPECT_EQ(cameras.moved, f > 0 && held < 0 ? 1 : 0);
        EXPECT_EQ(cameras.jitter, jitter ? 1 : 0);
        EXPECT_EQ(cameras.jitter_frame, static_cast<std::uint32_t>(f));
        std::size_t moving = 0, surfaces = 0;
        float worst_position = 0.0f, worst_motion = 0.0f;
        for (std::size_t i = 0; i < g.pixel_count(); ++i) {
          const auto x = static_cast<shared::uint>(i % 37), y = static_cast<shared::uint>(i / 37);
          const float3 ray = shared::pg_gbuffer_camera_ray(cameras, x, y);
          ASSERT_EQ(shared::pg_gbuffer_view_dir(ray), g.view_dir[i]) << i;
          const float4 pd =
              shared::pg_gbuffer_position_depth(cameras.current, ray, g.position_depth[i].w);
          if (!g.has_surface(i)) {
            ASSERT_EQ(pd, g.position_depth[i]) << i;
            continue;
          }
          ++surfaces;
          ASSERT_EQ(pd.w, g.position_depth[i].w) << i;
          worst_position =
              std::max(worst_position, glm::length(float3(pd) - float3(g.position_depth[i])) /
                                           g.position_depth[i].w);
          const float2 m = shared::pg_gbuffer_motion(cameras, float3(pd), x, y);
          worst_motion = std::max(worst_motion, glm::length(m - g.motion[i]));
          if (m != float2(0.0f)) ++moving;
        }
        EXPECT_LT(worst_position, 4e-6f);
        EXPECT_LT(worst_motion, 1e-3f);
        EXPECT_GT(surfaces, g.pixel_count() / 2);
        EXPECT_EQ(moving > surfaces / 2, cameras.moved == 1) << moving << " of " << surfaces;
      }
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

// The refusal tests' first frame: g's G-buffer, then a state of the sampler's own changed so
// that it differs from anything reprojection derives (the state written, returned).
std::vector<float> first_frame_with_a_state(GuidedFirstBounce& sampler, const GBuffer& g) {
  std::vector<float> state;
  sampler.begin_frame(g, SampleCoordinates{1, 0, 0});
  sampler.guider().read_state(state);
  for (std::size_t i = 0; i < state.size(); ++i) state[i] += 0.125f * static_cast<float>(i % 5);
  sampler.guider().write_state(state);
  return state;
}

// A refused frame leaves the sampler as it was: the next good frame reprojects from the last
// good frame's G-buffer. Before, the refused frame had already swapped the two device G-buffers,
// so the next one reprojected from a buffer never written (history lost, or on later frames a
// G-buffer three frames old). The state written after the first frame carries over exactly as in
// a sampler that never saw the refused frame.
TEST(GBufferPacker, ARefusedFrameLeavesTheHistoryAsItWas) {
  ClRuntime cl;
  GBuffer g = varied_gbuffer(19, 7, 5);
  GuidedFirstBounce refused(cl, 19, 7, GuidingSettings{}, HostTransfer::packed);
  GuidedFirstBounce clean(cl, 19, 7, GuidingSettings{}, HostTransfer::packed);
  std::vector<float> state;
  for (GuidedFirstBounce* sampler : {&refused, &clean})
    state = first_frame_with_a_state(*sampler, g);
  g.material[100] = PG_PACKED_MATERIAL_MAX + 1u;
  EXPECT_THROW(refused.begin_frame(g, SampleCoordinates{1, 1, 0}), GuiderError);
  g.material[100] = 0u;
  refused.begin_frame(g, SampleCoordinates{1, 2, 0});
  clean.begin_frame(g, SampleCoordinates{1, 2, 0});
  std::vector<float> after_refusal, after_clean;
  refused.guider().read_state(after_refusal);
  clean.guider().read_state(after_clean);
  ASSERT_EQ(after_refusal.size(), after_clean.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < after_clean.size(); ++i) differ += after_refusal[i] != after_clean[i];
  EXPECT_EQ(differ, 0u) << "of " << after_clean.size() << " floats";
  // The comparison can fail: part of the state written survives the clean sampler's
  // reprojection unchanged (257 of 1,064 floats; the rest is re-derived or reset), and the
  // sampler that swapped its G-buffers on the refused frame ended 44 floats apart from it.
  std::size_t kept = 0;
  for (std::size_t i = 0; i < state.size(); ++i) kept += after_clean[i] == state[i];
  EXPECT_GT(kept, 0u);
}

// A G-buffer of the sampler's pixel count in another shape (7x19 for 19x7), or one of another
// size, is refused by every transfer before anything is copied or swapped, and the next good
// frame reprojects as if the bad one had never come (the same state as a sampler that never saw
// it). Before, a transposed G-buffer passed every byte-size check, and a smaller one went up
// through pinned staging as far as it reached, the rest of the device buffer left as it was.
TEST(GBufferPacker, AGBufferOfAnotherShapeIsRefusedAndLeavesTheHistory) {
  ClRuntime cl;
  GBuffer g = varied_gbuffer(19, 7, 5);
  const GBuffer transposed = varied_gbuffer(7, 19, 5), smaller = varied_gbuffer(8, 7, 5);
  for (HostTransfer transfer : {HostTransfer::in_place, HostTransfer::pinned, HostTransfer::packed,
                                HostTransfer::pageable}) {
    SCOPED_TRACE(static_cast<int>(transfer));
    GuidedFirstBounce refused(cl, 19, 7, GuidingSettings{}, transfer, Overlap::off);
    GuidedFirstBounce clean(cl, 19, 7, GuidingSettings{}, transfer, Overlap::off);
    // In place the two frames must be two G-buffers (reads_gbuffers_in_place).
    GBuffer second = g;
    for (GuidedFirstBounce* sampler : {&refused, &clean}) first_frame_with_a_state(*sampler, g);
    for (const GBuffer* bad : {&transposed, &smaller}) {
      try {
        refused.begin_frame(*bad, SampleCoordinates{1, 1, 0});
        ADD_FAILURE() << "a " << bad->width << "x" << bad->height << " G-buffer was taken";
      } catch (const GuiderError& e) {
        EXPECT_NE(std::string(e.what()).find("19x7 sampler"), std::string::npos) << e.what();
      }
    }
    refused.begin_frame(second, SampleCoordinates{1, 2, 0});
    clean.begin_frame(second, SampleCoordinates{1, 2, 0});
    std::vector<float> after_refusal, after_clean;
    refused.guider().read_state(after_refusal);
    clean.guider().read_state(after_clean);
    EXPECT_EQ(after_refusal, after_clean);
  }
}

// The guided first bounce with --host-transfer packed sends the VPLs in the form the path
// tracer writes beside the layout (VplBuffer::for_bus, which the renderer sets from
// sends_packed_vpls()); VPLs without it are refused, naming the flag, not sent as garbage.
TEST(GBufferPacker, PackedTransferRefusesVplsNotPackedForTheBus) {
  ClRuntime cl;
  const GBuffer g = varied_gbuffer(19, 7, 5);
  GuidedFirstBounce sampler(cl, 19, 7, GuidingSettings{}, HostTransfer::packed, Overlap::off);
  EXPECT_TRUE(sampler.sends_packed_vpls());
  const SampleCoordinates at{1, 0, 0};
  sampler.begin_frame(g, at);
  sampler.sample(g, at);
  VplBuffer vpls;
  vpls.resize(g.pixel_count());
  try {
    sampler.end_frame(g, vpls, at);
    ADD_FAILURE() << "no GuiderError";
  } catch (const GuiderError& e) {
    EXPECT_NE(std::string(e.what()).find("for_bus"), std::string::npos) << e.what();
  }
  vpls.for_bus = true;
  vpls.resize(g.pixel_count());  // every VPL invalid: distance 0
  EXPECT_NO_THROW(sampler.end_frame(g, vpls, at));
}

}  // namespace
}  // namespace rtpg

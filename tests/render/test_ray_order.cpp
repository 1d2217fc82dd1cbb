// The order the bounce rays go to Embree in (trace/ray_order.h, PathTracerSettings::
// bounce_ray_order): RayOrder's groups and counting sort, and that grouping changes no pixel and
// no VPL.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "forwarding_sampler.h"
#include "same_image.h"
#include "render/first_bounce.h"
#include "render/renderer.h"
#include "render/vpl_buffer.h"
#include "scene/scene_loader.h"
#include "trace/ray_order.h"

namespace rtpg {
namespace {

// Lists of random lengths (empty and full ones among them) laid out `stride` apart, each slot
// with a random group: order() is std::stable_sort of the listed slots by group, in two calls
// with different lists (the second reuses the first's storage).
TEST(RayOrder, OrdersTheListedSlotsStablyByGroup) {
  std::mt19937 rng(11);
  for (int call = 0; call < 2; ++call) {
    const std::size_t stride = 64, lists = call == 0 ? 37 : 5;
    std::vector<std::uint32_t> counts(lists);
    std::vector<std::uint16_t> groups(stride * lists);
    std::vector<std::uint32_t> expected;
    for (std::size_t l = 0; l < lists; ++l) {
      counts[l] = l % 7 == 0 ? 0u : l % 5 == 0 ? stride : rng() % (stride + 1);
      for (std::size_t s = l * stride; s < l * stride + stride; ++s) {
        // Few groups in the first call, so that groups repeat across lists and chunks;
        // any group in the second.
        groups[s] = static_cast<std::uint16_t>(rng() % (call == 0 ? 9u : RayOrder::kGroups));
        if (s < l * stride + counts[l]) expected.push_back(static_cast<std::uint32_t>(s));
      }
    }
    std::stable_sort(expected.begin(), expected.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return groups[a] < groups[b]; });
    RayOrder order(glm::vec3(0.0f), glm::vec3(1.0f));
    EXPECT_EQ(order.order(groups.data(), stride, counts.data(), lists), expected) << call;
  }
}

TEST(RayOrder, NoListsNoSlots) {
  RayOrder order(glm::vec3(0.0f), glm::vec3(1.0f));
  EXPECT_TRUE(order.order(nullptr, 64, nullptr, 0).empty());
}

// The group's high bits are the direction's octant, the low ones the origin's cell in Morton
// order; origins outside the bounds, or NaN, fall into edge cells; flat bounds (no extent along
// an axis) put every origin in that axis's first cell.
TEST(RayOrder, GroupsByOctantThenTheOriginsCell) {
  constexpr int kBits = RayOrder::kCellBits;
  constexpr std::uint32_t kCells = 1u << kBits;
  const RayOrder order(glm::vec3(-1.0f, 0.0f, 10.0f), glm::vec3(1.0f, 8.0f, 12.0f));
  const glm::vec3 corner(-1.0f, 0.0f, 10.0f), far_corner(1.0f, 8.0f, 12.0f);
  const std::uint32_t last_cell = (1u << (3 * kBits)) - 1u;
  for (std::uint32_t octant = 0; octant < 8; ++octant) {
    const glm::vec3 d((octant & 1u) ? -1.0f : 1.0f, (octant & 2u) ? -0.5f : 0.5f,
                      (octant & 4u) ? -2.0f : 0.0f);
    EXPECT_EQ(order.group(corner, d), octant << (3 * kBits)) << octant;
    EXPECT_EQ(order.group(far_corner, d), octant << (3 * kBits) | last_cell) << octant;
  }
  const glm::vec3 plus(1.0f);
  // One cell along x only: Morton bit 0; along y: bit 1; along z: bit 2.
  const float step_x = 2.0f / kCells, step_y = 8.0f / kCells, step_z = 2.0f / kCells;
  EXPECT_EQ(order.group(corner + glm::vec3(1.5f * step_x, 0.0f, 0.0f), plus), 1u);
  EXPECT_EQ(order.group(corner + glm::vec3(0.0f, 1.5f * step_y, 0.0f), plus), 2u);
  EXPECT_EQ(order.group(corner + glm::vec3(0.0f, 0.0f, 1.5f * step_z), plus), 4u);
  EXPECT_EQ(order.group(glm::vec3(-100.0f, -100.0f, -100.0f), plus), 0u);
  EXPECT_EQ(order.group(glm::vec3(100.0f, 100.0f, 100.0f), plus), last_cell);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_LT(order.group(glm::vec3(nan), glm::vec3(nan)), RayOrder::kGroups);
  const RayOrder flat(glm::vec3(0.0f), glm::vec3(4.0f, 0.0f, 4.0f));
  EXPECT_EQ(flat.group(glm::vec3(4.0f, 3.0f, 0.0f), plus) & 2u, 0u);
}

// BSDF sampling that asks for each frame's VPLs (as a guide would, to train on them) and keeps
// them.
class VplKeepingSampler final : public ForwardingSampler {
 public:
  explicit VplKeepingSampler(std::vector<VplBuffer>& frames)
      : ForwardingSampler(std::make_unique<BsdfFirstBounce>()), frames_(frames) {}
  bool wants_vpls() const override { return true; }
  void end_frame(const GBuffer&, const VplBuffer& vpls, const SampleCoordinates&) override {
    frames_.push_back(vpls);
  }

 private:
  std::vector<VplBuffer>& frames_;
};

// Grouping reorders the paths between bounces (rays_ and active_ in group order), so every
// per-path record must follow its path: the Cornell box at an odd size, two samples a pixel, a
// moving camera, once with the VPLs a guide trains on and once without; every frame's image and
// VPLs the same to the bit with the bounce rays grouped and listed.
TEST(RayOrder, GroupingLeavesImagesAndVplsAsTheyAre) {
  const Scene scene = load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
  for (const bool with_vpls : {false, true}) {
    RenderSettings grouped;
    grouped.width = 23;
    grouped.height = 17;
    grouped.spp = 2;
    grouped.camera_path = "pan";
    RenderSettings listed = grouped;
    grouped.path_tracer.bounce_ray_order = BounceRayOrder::grouped;
    listed.path_tracer.bounce_ray_order = BounceRayOrder::listed;
    Renderer a(scene, grouped), b(scene, listed);
    std::vector<VplBuffer> vpls_a, vpls_b;
    if (with_vpls) {
      a.set_first_bounce_sampler(std::make_unique<VplKeepingSampler>(vpls_a));
      b.set_first_bounce_sampler(std::make_unique<VplKeepingSampler>(vpls_b));
    }
    for (int frame = 0; frame < 3; ++frame) {
      const FrameStats sa = a.render_frame(frame), sb = b.render_frame(frame);
      EXPECT_EQ(sa.extra.at("bounce_rays_grouped"), 1.0);
      EXPECT_EQ(sb.extra.at("bounce_rays_grouped"), 0.0);
      EXPECT_EQ(sa.secondary_rays, sb.secondary_rays);
      expect_same_lit_image(a.image(), b.image(),
                            "frame " + std::to_string(frame) + (with_vpls ? ", with VPLs" : ""));
    }
    if (!with_vpls) continue;
    ASSERT_EQ(vpls_a.size(), vpls_b.size());
    ASSERT_FALSE(vpls_a.empty());
    for (std::size_t f = 0; f < vpls_a.size(); ++f) {
      const VplBuffer &va = vpls_a[f], &vb = vpls_b[f];
      ASSERT_EQ(va.info.size(), vb.info.size());
      std::size_t valid = 0;
      for (std::size_t i = 0; i < va.info.size(); ++i) {
        EXPECT_EQ(va.info[i], vb.info[i]) << "pass " << f << ", pixel " << i;
        if ((va.info[i] & PG_VPL_VALID) == 0u) continue;
        ++valid;
        EXPECT_TRUE(same_bits(va.position[i], vb.position[i])) << "pass " << f << ", pixel " << i;
        EXPECT_TRUE(same_bits(va.normal_radiance[i], vb.normal_radiance[i]))
            << "pass " << f << ", pixel " << i;
      }
      EXPECT_GT(valid, va.info.size() / 4) << "pass " << f;
    }
  }
}

}  // namespace
}  // namespace rtpg

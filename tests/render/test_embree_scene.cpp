// The batched ray queries of host/trace/embree_scene.h: the same hits and occlusion answers in
// every ray mode (one by one, packets of 8, streams), for lists of shadow and bounce rays laid out
// a stride apart, and for an image's rays traced in tiles of pixels; empty segments (tmin > tmax,
// or a NaN bound) answered 0 without a query and left out of the count of rays queried; alpha
// masks' transparent texels let rays through.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "scene/scene.h"
#include "scene/shapes.h"
#include "support/scene_edits.h"
#include "trace/embree_scene.h"

namespace rtpg {
namespace {

// A 2x2 quad in the plane y = 0, centred at the origin.
Scene quad_scene() {
  Scene scene;
  scene.materials.push_back(Material{});
  scene.meshes.push_back(make_quad({-1, 0, -1}, {2, 0, 0}, {0, 0, 2}));
  return scene;
}

Ray segment(glm::vec3 origin, glm::vec3 direction, float tmin, float tmax) {
  Ray r;
  r.origin = origin;
  r.direction = direction;
  r.tmin = tmin;
  r.tmax = tmax;
  return r;
}

// Rays down through the quad's plane from y = 1 (even slots above the quad, odd ones beside it),
// alternating between a segment that reaches the plane, one that stops short of it and an empty one
// (tmin > tmax, and a NaN bound); 21 rays, so the last packet
// of 8 is partial and one packet is empty in every lane.
struct Case {
  std::vector<Ray> rays;
  std::vector<std::uint8_t> expected;
  std::size_t segments = 0;  // rays with tmin <= tmax
};

const char* mode_name(RayMode mode) {
  return mode == RayMode::Single ? "single" : mode == RayMode::Packet8 ? "packets of 8" : "stream";
}

Case shadow_slots() {
  Case c;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int i = 0; i < 21; ++i) {
    const float fi = static_cast<float>(i);
    const glm::vec3 origin(i % 2 == 0 ? 0.05f * fi - 0.5f : 1.5f + 0.01f * fi, 1.0f, 0.0f);
    const bool over_quad = std::fabs(origin.x) < 1.0f;
    const int kind = (i >= 8 && i < 16) ? 2 : i % 3;  // slots 8..15: a packet of empty rays
    if (kind == 0) {  // reaches y = -1: blocked where it crosses the quad
      c.rays.push_back(segment(origin, {0, -1, 0}, 0.0f, 2.0f));
      c.expected.push_back(over_quad ? 1 : 0);
      ++c.segments;
    } else if (kind == 1) {  // stops at y = 0.5
      c.rays.push_back(segment(origin, {0, -1, 0}, 0.0f, 0.5f));
      c.expected.push_back(0);
      ++c.segments;
    } else {  // empty: would cross the quad if it were traced over (0, 2)
      c.rays.push_back(segment(origin, {0, -1, 0}, i % 2 ? 1.0f : nan, i % 2 ? 0.0f : 2.0f));
      c.expected.push_back(0);
    }
  }
  return c;
}

TEST(EmbreeScene, OccludedAnswersEmptySegmentsWithZeroAndCountsOnlyRaysQueried) {
  const Scene scene = quad_scene();
  const EmbreeScene tracer(scene);
  const Case c = shadow_slots();
  std::size_t blocked = 0;
  for (std::uint8_t e : c.expected) blocked += e;
  ASSERT_GT(blocked, 0u);  // the case tests both answers
  for (RayMode mode : {RayMode::Single, RayMode::Packet8, RayMode::Stream}) {
    // Garbage in the output first: every slot must be written, empty ones included.
    std::vector<std::uint8_t> occluded(c.rays.size(), 7);
    const std::size_t queried =
        tracer.occluded(c.rays.data(), occluded.data(), c.rays.size(), mode);
    EXPECT_EQ(queried, c.segments) << mode_name(mode);
    for (std::size_t i = 0; i < c.rays.size(); ++i)
      EXPECT_EQ(occluded[i], c.expected[i]) << "ray " << i << ", " << mode_name(mode);
  }
}

TEST(EmbreeScene, OccludedOfNoRaysQueriesNothing) {
  const Scene scene = quad_scene();
  const EmbreeScene tracer(scene);
  std::uint8_t unused = 0;
  for (RayMode mode : {RayMode::Single, RayMode::Packet8, RayMode::Stream})
    EXPECT_EQ(tracer.occluded(nullptr, &unused, 0, mode), 0u) << mode_name(mode);
}

// The path tracer's shadow rays as lists laid out a stride apart (occluded_lists): each list
// answered as occluded() answers the same rays, the places between lists left as they were, and
// the count of rays queried the sum over the lists. Lists of 0 rays, of fewer than a stride, of a
// whole stride, and one longer than a stride whose places past the stride are not touched (stride
// 9: a packet of 8 and one more; 4 lists of the shadow_slots() rays, empty segments included).
TEST(EmbreeScene, OccludedListsAnswerEachListAsOccludedDoes) {
  const Scene scene = quad_scene();
  const EmbreeScene tracer(scene);
  const Case c = shadow_slots();
  constexpr std::size_t kStride = 9;
  // The first list is capped at kStride; the empty one after it shows that nothing past the
  // stride was written.
  const std::vector<std::uint32_t> counts = {12, 0, 5, 9};
  std::vector<Ray> lists(kStride * counts.size());
  std::vector<std::uint8_t> expected(lists.size(), 7);
  std::size_t next = 0, segments = 0;
  for (std::size_t l = 0; l < counts.size(); ++l)
    for (std::size_t k = 0; k < std::min<std::size_t>(counts[l], kStride); ++k, ++next) {
      lists[l * kStride + k] = c.rays[next % c.rays.size()];
      expected[l * kStride + k] = c.expected[next % c.rays.size()];
      segments += c.rays[next % c.rays.size()].tmin <= c.rays[next % c.rays.size()].tmax;
    }
  for (RayMode mode : {RayMode::Single, RayMode::Packet8, RayMode::Stream}) {
    std::vector<std::uint8_t> occluded(lists.size(), 7);
    const std::size_t queried = tracer.occluded_lists(lists.data(), occluded.data(), kStride,
                                                      counts.data(), counts.size(), mode);
    EXPECT_EQ(queried, segments) << mode_name(mode);
    for (std::size_t i = 0; i < lists.size(); ++i)
      EXPECT_EQ(occluded[i], expected[i]) << "place " << i << ", " << mode_name(mode);
  }
}

// The path tracer's bounce rays as lists laid out a stride apart (intersect_lists): each list's
// hits those of intersect() for the same rays, to the bit, and the places between the lists (and
// past a list longer than the stride) untouched. 300 random rays in lists of 0, 1, 37 (a partial
// packet), 64 and 90 (capped at 64) rays, 64 apart, in the three ray modes.
TEST(EmbreeScene, IntersectListsHitAsIntersectDoes) {
  const Scene scene = quad_scene();
  const EmbreeScene tracer(scene);
  std::mt19937 gen(9);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  constexpr std::size_t kStride = 64;
  const std::vector<std::uint32_t> counts = {90, 0, 1, 37, 64};
  std::vector<Ray> lists(kStride * counts.size());
  for (Ray& r : lists) {
    const glm::vec3 origin(u(gen), u(gen), u(gen));
    const glm::vec3 to(0.7f * u(gen), 0.0f, 0.7f * u(gen));
    r = segment(origin, to - origin, 0.0f, 2.0f);
  }
  Hit untouched;
  untouched.mesh = 12345;
  for (RayMode mode : {RayMode::Single, RayMode::Packet8, RayMode::Stream}) {
    std::vector<Hit> hits(lists.size(), untouched);
    tracer.intersect_lists(lists.data(), hits.data(), kStride, counts.data(), counts.size(), mode);
    std::size_t hit_count = 0;
    for (std::size_t l = 0; l < counts.size(); ++l) {
      const std::size_t n = std::min<std::size_t>(counts[l], kStride);
      std::vector<Hit> expected(n);
      tracer.intersect(lists.data() + l * kStride, expected.data(), n, RayMode::Single);
      for (std::size_t k = 0; k < kStride; ++k) {
        const Hit& got = hits[l * kStride + k];
        if (k >= n) {
          EXPECT_EQ(got.mesh, untouched.mesh)
              << "list " << l << " place " << k << ", " << mode_name(mode);
          continue;
        }
        const Hit& want = expected[k];
        ASSERT_EQ(got.mesh, want.mesh) << "list " << l << " ray " << k << ", " << mode_name(mode);
        hit_count += want.valid();
        if (!want.valid()) continue;
        EXPECT_EQ(got.triangle, want.triangle) << "list " << l << " ray " << k;
        EXPECT_EQ(std::memcmp(&got.t, &want.t, sizeof got.t), 0) << "list " << l << " ray " << k;
      }
    }
    EXPECT_GT(hit_count, 0u) << mode_name(mode);
  }
}

// 2000 rays from random points above and below the quad in random directions (a third of them
// hit it, from either side), more than one TBB range and stream chunk and a partial last one:
// packets and streams return the hits of one-by-one queries to the bit, and the same occlusion.
TEST(EmbreeScene, EveryRayModeGivesTheSameAnswers) {
  const Scene scene = quad_scene();
  const EmbreeScene tracer(scene);
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  std::vector<Ray> rays;
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 origin(u(gen), u(gen), u(gen));
    glm::vec3 to(0.7f * u(gen), 0.0f, 0.7f * u(gen));
    if (i % 3 != 0) to = glm::vec3(u(gen), u(gen), u(gen));  // mostly elsewhere
    rays.push_back(segment(origin, to - origin, 0.0f, i % 5 == 0 ? 0.5f : 2.0f));
  }
  std::vector<Hit> single(rays.size());
  std::vector<std::uint8_t> single_occluded(rays.size());
  tracer.intersect(rays.data(), single.data(), rays.size(), RayMode::Single);
  tracer.occluded(rays.data(), single_occluded.data(), rays.size(), RayMode::Single);
  std::size_t hits = 0;
  for (const Hit& h : single) hits += h.valid();
  EXPECT_GT(hits, rays.size() / 5);
  EXPECT_LT(hits, rays.size() / 2);
  for (RayMode mode : {RayMode::Packet8, RayMode::Stream}) {
    std::vector<Hit> got(rays.size());
    std::vector<std::uint8_t> occluded(rays.size(), 7);
    tracer.intersect(rays.data(), got.data(), rays.size(), mode);
    tracer.occluded(rays.data(), occluded.data(), rays.size(), mode);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Hit &a = single[i], &b = got[i];
      ASSERT_EQ(a.mesh, b.mesh) << "ray " << i << ", " << mode_name(mode);
      EXPECT_EQ(occluded[i], single_occluded[i]) << "ray " << i << ", " << mode_name(mode);
      EXPECT_EQ(occluded[i], a.valid() ? 1 : 0) << "ray " << i << ", " << mode_name(mode);
      if (!a.valid()) continue;
      EXPECT_EQ(a.triangle, b.triangle) << "ray " << i << ", " << mode_name(mode);
      EXPECT_EQ(std::memcmp(&a.t, &b.t, sizeof a.t), 0) << "ray " << i << ", " << mode_name(mode);
      EXPECT_EQ(std::memcmp(&a.u, &b.u, sizeof a.u), 0) << "ray " << i << ", " << mode_name(mode);
      EXPECT_EQ(std::memcmp(&a.v, &b.v, sizeof a.v), 0) << "ray " << i << ", " << mode_name(mode);
    }
  }
}

// The 2x2 quad in y = 0 (mesh 0) alpha-tested by `mask` at `cutoff`, over a 4x4 floor at y = -1
// (mesh 1).
Scene masked_quad_over_floor(const Texture& mask, float cutoff) {
  Scene scene;
  scene.textures.push_back(mask);
  Material masked;
  masked.alpha_texture = 0;
  masked.alpha_cutoff = cutoff;
  scene.materials = {masked, Material{}};
  scene.meshes.push_back(make_quad({-1, 0, -1}, {2, 0, 0}, {0, 0, 2}));
  Mesh floor = make_quad({-2, -1, -2}, {4, 0, 0}, {0, 0, 4});
  floor.material = 1;
  scene.meshes.push_back(floor);
  return scene;
}

// A quad whose left half is transparent in its alpha mask (u < 1/2: texels of alpha 0 up to a
// quarter texel from the middle, and from the wrap's edge), over a floor: rays straight down
// through the transparent half hit the floor and are not occluded on their way to it, through
// the opaque half they hit the quad, in every ray mode, for 8-bit and float masks.
TEST(EmbreeScene, AlphaMaskLetsRaysThroughItsTransparentTexels) {
  for (const bool eight_bit : {true, false}) {
    const Texture mask = test::left_half_transparent_mask(eight_bit);
    // u = (x + 1) / 2 on the quad (make_quad's corners take uv (0, 0), (1, 0), (1, 1), (0, 1)).
    const Scene scene = masked_quad_over_floor(mask, 0.5f);
    const EmbreeScene tracer(scene);

    std::mt19937 gen(17);
    std::uniform_real_distribution<float> band(0.15f, 0.35f), z(-0.9f, 0.9f);
    std::vector<Ray> down, to_middle;
    std::vector<bool> transparent;
    for (int i = 0; i < 200; ++i) {
      const bool left = i % 2 == 0;
      const float u = left ? band(gen) : band(gen) + 0.5f;
      const glm::vec3 origin(2.0f * u - 1.0f, 1.0f, z(gen));
      down.push_back(segment(origin, {0, -1, 0}, 0.0f, 1e30f));
      to_middle.push_back(segment(origin, {0, -1, 0}, 0.0f, 1.5f));  // ends above the floor
      transparent.push_back(left);
    }
    for (RayMode mode : {RayMode::Single, RayMode::Packet8, RayMode::Stream}) {
      std::vector<Hit> hits(down.size());
      std::vector<std::uint8_t> occluded(down.size(), 7);
      tracer.intersect(down.data(), hits.data(), down.size(), mode);
      tracer.occluded(to_middle.data(), occluded.data(), to_middle.size(), mode);
      for (std::size_t i = 0; i < down.size(); ++i) {
        ASSERT_TRUE(hits[i].valid()) << "ray " << i << ", " << mode_name(mode);
        EXPECT_EQ(hits[i].mesh, transparent[i] ? 1u : 0u)
            << "ray " << i << ", " << mode_name(mode) << (eight_bit ? ", 8-bit" : ", float");
        EXPECT_EQ(occluded[i], transparent[i] ? 0 : 1)
            << "ray " << i << ", " << mode_name(mode) << (eight_bit ? ", 8-bit" : ", float");
      }
    }
  }
}

// A mask of alpha 0.4 everywhere is opaque for a cutoff of 0.3 and transparent for one of 0.5
// (hits with alpha >= cutoff stay), for closest hits and occlusion alike.
TEST(EmbreeScene, AlphaCutoffDecidesAtPartialAlpha) {
  for (const float cutoff : {0.3f, 0.5f}) {
    Texture mask;
    mask.width = 1;
    mask.height = 1;
    mask.texels8.push_back({255, 255, 255, 102});  // 102 / 255 = 0.4
    const Scene scene = masked_quad_over_floor(mask, cutoff);
    const EmbreeScene tracer(scene);
    const Ray down = segment({0.1f, 1.0f, 0.2f}, {0, -1, 0}, 0.0f, 1e30f);
    const Ray to_middle = segment({0.1f, 1.0f, 0.2f}, {0, -1, 0}, 0.0f, 1.5f);
    Hit hit;
    std::uint8_t occluded = 7;
    tracer.intersect(&down, &hit, 1);
    tracer.occluded(&to_middle, &occluded, 1);
    const bool opaque = cutoff < 0.4f;
    ASSERT_TRUE(hit.valid()) << "cutoff " << cutoff;
    EXPECT_EQ(hit.mesh, opaque ? 0u : 1u) << "cutoff " << cutoff;
    EXPECT_EQ(occluded, opaque ? 1 : 0) << "cutoff " << cutoff;
  }
}

// An image's rays from a point above the quad, spread so that the quad's edge crosses tiles, at
// sizes whose last tiles are partial: intersect_image in each tile shape this CPU runs gives every
// pixel the hit of its own one-by-one query, to the bit, and writes no pixel twice or not at all
// (misses keep kNoHit; hits match).
TEST(EmbreeScene, ImageTilesGiveEveryPixelItsOwnHit) {
  const Scene scene = quad_scene();
  const EmbreeScene tracer(scene);
  std::vector<EmbreeScene::ImageTiles> shapes = {EmbreeScene::ImageTiles::automatic,
                                                 EmbreeScene::ImageTiles::tiles_4x2};
  if (tracer.native_packets_of_16()) shapes.push_back(EmbreeScene::ImageTiles::tiles_4x4);
  const int sizes[][2] = {{1, 1}, {3, 5}, {13, 7}, {16, 16}, {37, 23}};
  for (const auto& size : sizes) {
    const int w = size[0], h = size[1];
    std::vector<Ray> rays;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float sx = (static_cast<float>(x) + 0.5f) / static_cast<float>(w) * 3.0f - 1.5f;
        const float sz = (static_cast<float>(y) + 0.5f) / static_cast<float>(h) * 3.0f - 1.5f;
        rays.push_back(segment({0.1f, 1.0f, -0.2f}, {sx, -1.0f, sz}, 0.0f, 1e30f));
      }
    std::vector<Hit> single(rays.size());
    tracer.intersect(rays.data(), single.data(), rays.size(), RayMode::Single);
    for (const EmbreeScene::ImageTiles shape : shapes) {
      std::vector<Hit> got(rays.size());
      tracer.intersect_image(rays.data(), got.data(), w, h, shape);
      int differing = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hit &a = single[i], &b = got[i];
        differing += a.mesh != b.mesh || (a.valid() && (a.triangle != b.triangle ||
                                                        std::memcmp(&a.t, &b.t, sizeof a.t) != 0 ||
                                                        std::memcmp(&a.u, &b.u, sizeof a.u) != 0 ||
                                                        std::memcmp(&a.v, &b.v, sizeof a.v) != 0));
      }
      EXPECT_EQ(differing, 0) << w << "x" << h << ", shape " << static_cast<int>(shape);
    }
    if (w == 37) {  // the case spans hits and misses
      std::size_t hits = 0;
      for (const Hit& hit : single) hits += hit.valid();
      EXPECT_GT(hits, rays.size() / 4);
      EXPECT_LT(hits, rays.size());
    }
  }
}

}  // namespace
}  // namespace rtpg

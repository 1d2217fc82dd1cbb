// The world-space guide of later path vertices (host/render/world_guide.h): its cells, its
// training from samples, its table's growth and its determinism, and what the path tracer
// records for it. Whole-image unbiasedness with
// it is checked in test_guiding_image.cpp (GuidingImage.UnbiasedWithTheWorldGuide*).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include <tbb/global_control.h>

#include "render/renderer.h"
#include "render/world_guide.h"
#include "scene/shapes.h"
#include "rtpg/guiding_settings.h"
#include "shared/rng.h"

namespace rtpg {
namespace {

WorldGuideSettings settings_for_test(int resolution = 10) {
  WorldGuideSettings s;
  s.resolution = resolution;
  s.em = to_kernel_settings(GuidingSettings{});
  return s;
}

TEST(WorldGuide, CellsSeparatePositionsAndNormalAxes) {
  const WorldGuide guide(glm::vec3(0.0f), glm::vec3(10.0f), settings_for_test(10));
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  const std::uint64_t a = guide.cell_of(glm::vec3(2.1f, 3.1f, 4.1f), up);
  EXPECT_EQ(
      a, guide.cell_of(glm::vec3(2.4f, 3.4f, 4.4f), glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f))));
  EXPECT_NE(a, guide.cell_of(glm::vec3(3.1f, 3.1f, 4.1f), up));  // the next cell along x
  EXPECT_NE(a, guide.cell_of(glm::vec3(2.1f, 3.1f, 4.1f), -up));
  EXPECT_NE(a, guide.cell_of(glm::vec3(2.1f, 3.1f, 4.1f), glm::vec3(1.0f, 0.0f, 0.0f)));
  EXPECT_EQ(WorldGuide::kNoCell, guide.cell_of(glm::vec3(-5.0f, 3.0f, 4.0f), up));
  // The bounds' faces themselves are inside.
  EXPECT_NE(WorldGuide::kNoCell, guide.cell_of(glm::vec3(10.0f, 10.0f, 10.0f), up));
  EXPECT_NE(WorldGuide::kNoCell, guide.cell_of(glm::vec3(0.0f), up));
  // A cell's frame is its normal axis.
  const glm::vec3 normals[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const glm::vec3& n : normals) {
    const shared::pg_frame f = WorldGuide::cell_frame(guide.cell_of(glm::vec3(5.0f), n));
    EXPECT_NEAR(glm::dot(f.n, n), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(f.t, f.n), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(f.b, f.n), 0.0f, 1e-6f);
  }
}

// Samples of one cell drawn uniformly over the square, weighted by a bump around u0 (the light
// arriving from one direction): after a few frames the cell's Gaussian sits on the bump.
TEST(WorldGuide, LearnsWhereTheLightComesFrom) {
  WorldGuide guide(glm::vec3(0.0f), glm::vec3(1.0f), settings_for_test(4));
  const std::uint64_t cell = guide.cell_of(glm::vec3(0.5f), glm::vec3(0.0f, 0.0f, 1.0f));
  PixelGuide g;
  EXPECT_FALSE(guide.guide(cell, g)) << "no model before training";
  const float u0x = 0.7f, u0y = 0.3f, width = 0.05f;
  shared::pg_rng rng = shared::pg_rng_make(1u, 2u, 3u, 4u, 0u);
  for (int frame = 0; frame < 20; ++frame) {
    std::vector<std::vector<WorldTrainingSample>> blocks(1);
    for (int k = 0; k < 400; ++k) {
      const float ux = shared::pg_rng_next(&rng), uy = shared::pg_rng_next(&rng);
      const float d2 = (ux - u0x) * (ux - u0x) + (uy - u0y) * (uy - u0y);
      const float a = std::exp(-0.5f * d2 / (width * width));
      blocks[0].push_back({cell, a, ux, uy, 1.0f / 3.14159265f, 1.0f / 3.14159265f});
    }
    guide.train(blocks);
  }
  ASSERT_TRUE(guide.guide(cell, g));
  EXPECT_NEAR(g.model.mx, u0x, 0.02f);
  EXPECT_NEAR(g.model.my, u0y, 0.02f);
  EXPECT_LT(g.model.l11, 3.0f * width);
  EXPECT_GT(g.model.pi, 0.0f);
  EXPECT_NEAR(glm::dot(g.frame.n, glm::vec3(0.0f, 0.0f, 1.0f)), 1.0f, 1e-6f);
  EXPECT_EQ(guide.cell_count(), 1u);
  EXPECT_EQ(guide.samples_last_frame(), 400u);
}

std::vector<std::vector<WorldTrainingSample>> many_cells(const WorldGuide& guide, int cells,
                                                         int per_cell, std::uint32_t seed) {
  std::vector<std::vector<WorldTrainingSample>> blocks(3);
  shared::pg_rng rng = shared::pg_rng_make(seed, 0u, 0u, 0u, 0u);
  for (int k = 0; k < per_cell; ++k)
    for (int c = 0; c < cells; ++c) {
      const glm::vec3 p(static_cast<float>(c % 50) + 0.5f, static_cast<float>(c / 50) + 0.5f, 0.5f);
      const float ux = shared::pg_rng_next(&rng), uy = shared::pg_rng_next(&rng);
      blocks[static_cast<std::size_t>(c) % 3].push_back(
          {guide.cell_of(p, glm::vec3(0.0f, 0.0f, 1.0f)), 1.0f + ux, ux, uy, 0.3f, 0.3f});
    }
  return blocks;
}

// The models of many_cells' first `cells` cells that have one, six floats each, in cell order.
std::vector<float> cell_models(const WorldGuide& guide, int cells) {
  std::vector<float> out;
  for (int c = 0; c < cells; ++c) {
    PixelGuide g;
    const glm::vec3 p(static_cast<float>(c % 50) + 0.5f, static_cast<float>(c / 50) + 0.5f, 0.5f);
    if (guide.guide(guide.cell_of(p, glm::vec3(0.0f, 0.0f, 1.0f)), g))
      out.insert(out.end(),
                 {g.model.pi, g.model.mx, g.model.my, g.model.l11, g.model.l21, g.model.l22});
  }
  return out;
}

// The table starts at 4096 slots and doubles at half full: 5,000 cells make it grow twice
// during one frame's training, and every cell keeps its model.
TEST(WorldGuide, TheTableGrowsAndKeepsEveryCell) {
  WorldGuide guide(glm::vec3(0.0f), glm::vec3(100.0f), settings_for_test(100));
  const int cells = 5000;
  for (int frame = 0; frame < 2; ++frame) guide.train(many_cells(guide, cells, 4, frame + 1u));
  EXPECT_EQ(guide.cell_count(), static_cast<std::size_t>(cells));
  int with_model = 0;
  for (int c = 0; c < cells; ++c) {
    PixelGuide g;
    const glm::vec3 p(static_cast<float>(c % 50) + 0.5f, static_cast<float>(c / 50) + 0.5f, 0.5f);
    with_model += guide.guide(guide.cell_of(p, glm::vec3(0.0f, 0.0f, 1.0f)), g);
  }
  EXPECT_EQ(with_model, cells);
}

// At most 2^max_cells_log2 cells: samples of cells beyond that are dropped, nothing else.
TEST(WorldGuide, AFullTableDropsNewCells) {
  WorldGuideSettings s = settings_for_test(100);
  s.max_cells_log2 = 11;  // 2,048 cells: the table may grow once, to 4,096 slots... then stops
  WorldGuide guide(glm::vec3(0.0f), glm::vec3(100.0f), s);
  guide.train(many_cells(guide, 5000, 2, 7u));
  EXPECT_LE(guide.cell_count(), std::size_t{2048});
  EXPECT_GT(guide.cell_count(), std::size_t{1000});
  guide.train(many_cells(guide, 5000, 2, 8u));
  EXPECT_LE(guide.cell_count(), std::size_t{2048});
}

// The cells of the frame that fills the table keep every sample: each cell's second sample
// arrives after the table's last cell was made, and a lookup that checked the table's room before
// looking for the cell dropped it (and, below the cap, grew the table for a cell it had). So a
// table capped at the 2,048 cells it is given trains the same models as one with room to spare.
TEST(WorldGuide, TheFrameThatFillsTheTableTrainsEveryCellOnAllItsSamples) {
  const auto models = [](int max_cells_log2) {
    WorldGuideSettings s = settings_for_test(100);
    s.max_cells_log2 = max_cells_log2;
    WorldGuide guide(glm::vec3(0.0f), glm::vec3(100.0f), s);
    guide.train(many_cells(guide, 2048, 2, 11u));
    EXPECT_EQ(guide.cell_count(), 2048u);
    return cell_models(guide, 2048);
  };
  const std::vector<float> capped = models(11), roomy = models(20);
  ASSERT_EQ(roomy.size(), 2048u * 6u);
  EXPECT_EQ(capped, roomy);
}

// max_cells_log2 below the table's first size still bounds the cells: at most 2^5 here.
TEST(WorldGuide, ASmallCapIsKept) {
  WorldGuideSettings s = settings_for_test(100);
  s.max_cells_log2 = 5;
  WorldGuide guide(glm::vec3(0.0f), glm::vec3(100.0f), s);
  guide.train(many_cells(guide, 100, 2, 3u));
  EXPECT_EQ(guide.cell_count(), 32u);
}

// kNoCell (a point outside the grid) is the empty slots' key: samples of it are dropped, and it
// never has a model (a lookup once found the first empty slot, trained it, and then read the
// frame of a normal bin that does not exist).
TEST(WorldGuide, NoCellIsNeitherTrainedNorGuided) {
  WorldGuide guide(glm::vec3(0.0f), glm::vec3(1.0f), settings_for_test(4));
  const std::uint64_t outside = guide.cell_of(glm::vec3(-5.0f), glm::vec3(0.0f, 1.0f, 0.0f));
  ASSERT_EQ(outside, WorldGuide::kNoCell);
  std::vector<std::vector<WorldTrainingSample>> blocks(1);
  for (int k = 0; k < 10; ++k) blocks[0].push_back({outside, 1.0f, 0.4f, 0.6f, 0.3f, 0.3f});
  for (int frame = 0; frame < 3; ++frame) guide.train(blocks);
  PixelGuide g;
  EXPECT_FALSE(guide.guide(outside, g));
  EXPECT_EQ(guide.cell_count(), 0u);
}

// Training sums each cell's samples in the blocks' order, so one thread and many give the same
// models to the bit.
TEST(WorldGuide, TrainsTheSameWhateverTheThreadCount) {
  const auto train = [](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(threads));
    WorldGuide guide(glm::vec3(0.0f), glm::vec3(100.0f), settings_for_test(100));
    for (int frame = 0; frame < 3; ++frame) guide.train(many_cells(guide, 3000, 6, frame + 1u));
    return cell_models(guide, 3000);
  };
  const std::vector<float> one = train(1), many = train(4);
  ASSERT_EQ(one.size(), 3000u * 6u);
  EXPECT_EQ(one, many);
}

// A Lambert floor and wall lit by a delta sun, no emitter and no sky, seen from the front.
Scene floor_and_wall_under_a_delta_sun() {
  Scene scene;
  scene.materials.push_back(Material{});
  scene.materials.back().specular = 0.0f;
  scene.meshes.push_back(make_quad({-2.0f, 0.0f, -2.0f}, {0.0f, 0.0f, 4.0f}, {4.0f, 0.0f, 0.0f}));
  scene.meshes.push_back(make_quad({-2.0f, 0.0f, -1.0f}, {4.0f, 0.0f, 0.0f}, {0.0f, 3.0f, 0.0f}));
  scene.sun.enabled = true;
  scene.sun.direction = glm::normalize(glm::vec3(0.3f, 1.0f, 0.8f));
  scene.sun.irradiance = glm::vec3(3.0f);
  scene.sun.angular_radius = 0.0f;
  scene.camera.view.position = glm::vec3(0.0f, 1.5f, 4.0f);
  scene.camera.view.look_at = glm::vec3(0.0f, 0.5f, -1.0f);
  return scene;
}

// A record's training sample weighs the light the path found after the vertex, not before
// (host/render/path_tracer.cpp, radiance_before, which the vertex after the record writes). A
// floor and a wall lit by a delta sun, no emitter and no sky: light arrives only through
// next-event estimation. With 2 bounces and the world guide recording the first bounce's hit y,
// what comes after y's bounce is the next vertex's emission, always 0: no cell learns a lobe,
// and the next frame guides no vertex. With 3 bounces that vertex's light sample adds light
// after y: cells learn and guide (the control that the first check is not vacuous).
TEST(WorldGuide, RecordsWeighOnlyTheLightFoundAfterTheVertex) {
  const Scene scene = floor_and_wall_under_a_delta_sun();
  const auto guided_in_second_frame = [&](int bounces) {
    RenderSettings settings;
    settings.width = 96;
    settings.height = 64;
    settings.seed = 3;
    settings.path_tracer.max_bounces = bounces;
    settings.world_guide = true;
    settings.world_guide_settings.em = to_kernel_settings(GuidingSettings{});
    settings.world_guide_settings.max_depth = 1;
    Renderer renderer(scene, settings);
    const FrameStats first = renderer.render_frame(0);
    EXPECT_GT(first.extra.at("world_samples"), 100.0) << bounces;  // y was recorded
    return renderer.render_frame(1).guided_vertices;
  };
  EXPECT_EQ(guided_in_second_frame(2), 0u);
  EXPECT_GT(guided_in_second_frame(3), 20u);
}

// The world guide's two thinning settings do what they say: with record_every 4 a quarter of the
// paths record (the samples of a frame 0.22-0.28 of those with every path recording: the paths
// are chosen by a hash, about 1,500 of 6,144, two percent of binomial spread), and a cell guides
// only where its mixing weight exceeds min_guiding_pi (above the clamp's 0.5 none does, so no
// vertex of the next frame is guided; at 0 some are). The scene of the test above, 3 bounces.
TEST(WorldGuide, RecordEveryAndMinimumPiThinWhatTheGuideDoes) {
  const Scene scene = floor_and_wall_under_a_delta_sun();
  struct Result {
    double samples_in_first_frame;
    std::uint64_t guided_in_second_frame;
  };
  const auto run = [&](int record_every, float min_pi) {
    RenderSettings settings;
    settings.width = 96;
    settings.height = 64;
    settings.seed = 3;
    settings.path_tracer.max_bounces = 3;
    settings.world_guide = true;
    settings.world_guide_settings.em = to_kernel_settings(GuidingSettings{});
    settings.world_guide_settings.max_depth = 1;
    settings.world_guide_settings.record_every = record_every;
    settings.world_guide_settings.min_guiding_pi = min_pi;
    Renderer renderer(scene, settings);
    const double samples = renderer.render_frame(0).extra.at("world_samples");
    return Result{samples, renderer.render_frame(1).guided_vertices};
  };
  const Result every = run(1, 0.0f), quarter = run(4, 0.0f), none = run(1, 0.6f);
  ASSERT_GT(every.samples_in_first_frame, 1000.0);
  const double share = quarter.samples_in_first_frame / every.samples_in_first_frame;
  EXPECT_GT(share, 0.22);
  EXPECT_LT(share, 0.28);
  EXPECT_GT(every.guided_in_second_frame, 20u);
  EXPECT_EQ(none.guided_in_second_frame, 0u);
}

// The renderer refuses world-guide settings it cannot keep: more than 2^30 cells (the training's
// slot indices are 32 bits), and a borrowed pixel mixture at the vertices the cells guide.
TEST(WorldGuide, TheRendererRefusesSettingsItCannotKeep) {
  const Scene scene = floor_and_wall_under_a_delta_sun();
  RenderSettings settings;
  settings.width = settings.height = 8;
  settings.world_guide = true;
  settings.world_guide_settings = settings_for_test();
  for (const int n : {-1, 31}) {
    settings.world_guide_settings.max_cells_log2 = n;
    EXPECT_THROW(Renderer(scene, settings), RenderSettingError) << n;
  }
  settings.world_guide_settings.max_cells_log2 = 30;
  EXPECT_NO_THROW(Renderer(scene, settings));
  settings.path_tracer.guide_secondary = true;
  EXPECT_THROW(Renderer(scene, settings), RenderSettingError);
}

}  // namespace
}  // namespace rtpg

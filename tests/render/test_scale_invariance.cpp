// Radiance does not depend on the scene's unit of length (issue: robustness, docs/robustness.md).
// The same scene scaled by s (every position and the camera, nothing else) must give the same
// image, with and without guiding (the pixels' guide, and with it the world-space guide of the
// later vertices, whose grid is sized by the scene's extent). Both renders use one seed, so their
// random streams match and the per-frame difference of a tile's mean is a paired sample: its spread
// is what float rounding and changed decisions (a hit instead of a miss) add, and its mean must be
// zero. A fixed absolute ray offset fails this at 1e-3 by a quarter of the image's energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <memory>
#include <string>
#include <vector>

#include "render/guided_first_bounce.h"
#include "render/renderer.h"
#include "rtpg/cl_runtime.h"
#include "scene/scene_loader.h"
#include "support/statistics.h"

namespace rtpg {
namespace {

Scene scaled(Scene scene, float s) {
  for (Mesh& m : scene.meshes)
    for (glm::vec3& p : m.positions) p *= s;
  auto scale_view = [s](CameraView& v) {
    v.position *= s;
    v.look_at *= s;
  };
  scale_view(scene.camera.view);
  for (auto& [name, path] : scene.camera.paths)
    for (CameraView& v : path.views) scale_view(v);
  return scene;
}

struct Series {
  std::vector<std::vector<double>> per_tile;  // [tile][frame] mean luminance
  std::vector<double> whole;                  // [frame]
  std::vector<float> state;                   // the guider's state after the last frame
  // The world guide's cells, samples, mean mixing weight and share at the lower clamp after the
  // last frame, and the vertices it guided over the run (empty without it).
  std::vector<double> world;
};

constexpr int kSize = 48, kTile = 16;

Series render(const Scene& scene, bool guided, bool world, int frames,
              const std::string& camera_path, ClRuntime* cl) {
  RenderSettings settings;
  settings.width = settings.height = kSize;
  settings.camera_path = camera_path;
  settings.seed = 5u;
  settings.path_tracer.max_bounces = scene.max_bounces > 0 ? scene.max_bounces : 8;
  settings.world_guide = world;
  settings.world_guide_settings.em = to_kernel_settings(GuidingSettings{});
  Renderer renderer(scene, settings);
  if (guided)
    renderer.set_first_bounce_sampler(
        std::make_unique<GuidedFirstBounce>(*cl, kSize, kSize, GuidingSettings{}));
  const int tiles = (kSize / kTile) * (kSize / kTile);
  Series s;
  s.per_tile.assign(tiles, {});
  double world_guided = 0.0;
  for (int f = 0; f < frames; ++f) {
    const FrameStats stats = renderer.render_frame(f);
    world_guided += static_cast<double>(stats.guided_vertices);
    if (world && f + 1 == frames)
      s.world = {stats.extra.at("world_cells"), stats.extra.at("world_samples"),
                 stats.extra.at("world_mean_pi"), stats.extra.at("world_at_pi_min")};
    const auto& img = renderer.image();
    std::vector<double> sums(tiles, 0.0);
    double total = 0.0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const glm::vec3 c = img[static_cast<std::size_t>(y) * kSize + x];
        EXPECT_TRUE(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z));
        const double l = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        sums[(y / kTile) * (kSize / kTile) + x / kTile] += l;
        total += l;
      }
    for (int t = 0; t < tiles; ++t) s.per_tile[t].push_back(sums[t] / (kTile * kTile));
    s.whole.push_back(total / (kSize * kSize));
  }
  if (guided)
    static_cast<GuidedFirstBounce&>(renderer.first_bounce_sampler()).guider().read_state(s.state);
  if (world) s.world.push_back(world_guided);
  return s;
}

// Paired test of the per-frame differences (scaled - unscaled) at level 0.01 with a Sidak
// correction over the tiles and the whole image; plus the 1% bound on the image mean.
// The scaled coordinates are rounded (1e-3 has no float), so the two images differ by float
// rounding: up to kRounding of a tile's mean is allowed on top of the statistical bound (seen:
// 5e-8; a fixed ray offset moved the mean by 16% at 1e-3 and 2.7% at 1e4).
constexpr double kRounding = 1e-5;
void expect_same_image(const Series& base, const Series& other, const std::string& what) {
  const int comparisons = static_cast<int>(base.per_tile.size()) + 1;
  const double z = test::normal_two_sided_quantile(1.0 - std::pow(0.99, 1.0 / comparisons));
  auto check = [&](const std::vector<double>& a, const std::vector<double>& b,
                   const std::string& where) {
    test::RunningMoments d;
    double sum_a = 0.0, sum_b = 0.0;
    for (std::size_t f = 0; f < a.size(); ++f) {
      d.add(b[f] - a[f]);
      sum_a += a[f];
      sum_b += b[f];
    }
    const double se = d.standard_error();
    EXPECT_LE(std::fabs(d.mean),
              z * se + kRounding * std::fabs(sum_a) / static_cast<double>(a.size()))
        << what << " " << where << ": mean difference " << d.mean << " (standard error " << se
        << ", bound " << z << " sigma); means " << sum_a / a.size() << " vs " << sum_b / b.size();
    return std::fabs(sum_b - sum_a) / sum_a;
  };
  const double relative = check(base.whole, other.whole, "whole image");
  EXPECT_LE(relative, 0.01) << what << ": the image mean moved by " << 100.0 * relative << "%";
  for (std::size_t t = 0; t < base.per_tile.size(); ++t)
    check(base.per_tile[t], other.per_tile[t], "tile " + std::to_string(t));
}

std::string scene_file(const char* name) {
  return std::string(RTPG_SOURCE_DIR) + "/scenes/" + name;
}

// Where a scene's assets must be ("" for a scene built from shapes only: always there).
std::string scene_assets_of(const char* scene) {
  if (std::string(scene) != "veach-ajar.json") return RTPG_SOURCE_DIR;
  const std::string root = resolve_asset_root(scene_file(scene), {});
  return root.empty() ? "../shared/scenes" : root + "/veach-ajar";
}

// Scaling by a power of two is exact in floats (below overflow and above the denormals), so a
// renderer without any absolute length (an epsilon, an offset, a clamp in metres) gives the
// same bits at every such scale: every frame's image and the guiding state after the last
// frame. The state holds no length (square-space moments; weights lum(L f cos) / r with r a
// solid-angle density made from the VPLs' area-measure densities times d^2 / cos), so its
// bits must match too. At decimal scales the rounded coordinates change a few decisions and EM
// carries them on (up to 6% of the state floats moved by 1e-3 on Veach Ajar, none of the
// image means): there the images are compared statistically.
void expect_identical(const Series& base, const Series& other, const std::string& what) {
  EXPECT_EQ(base.whole, other.whole) << what << ": per-frame image means";
  EXPECT_EQ(base.per_tile, other.per_tile) << what << ": per-frame tile means";
  EXPECT_EQ(base.state, other.state) << what << ": guiding state";
  EXPECT_EQ(base.world, other.world) << what << ": the world guide's cells and guided vertices";
}

struct ScaleCase {
  const char* scene;
  float scale;
  bool guided;
  const char* name;
  bool world = false;  // later vertices guided by the world-space guide too
};

void PrintTo(const ScaleCase& c, std::ostream* os) {
  *os << c.name;
}

class ScaleInvariance : public ::testing::TestWithParam<ScaleCase> {};

TEST_P(ScaleInvariance, SameImageAlongTheCameraPath) {
  const ScaleCase c = GetParam();
  if (!std::filesystem::exists(scene_assets_of(c.scene)))
    GTEST_SKIP() << c.scene << " needs " << scene_assets_of(c.scene);
  const Scene scene = load_scene(scene_file(c.scene));
  std::unique_ptr<ClRuntime> cl;
  if (c.guided) cl = std::make_unique<ClRuntime>();
  const int frames = 48;
  const Series base = render(scene, c.guided, c.world, frames, "pan", cl.get());
  const Series other = render(scaled(scene, c.scale), c.guided, c.world, frames, "pan", cl.get());
  const std::string what =
      std::string(c.scene) +
      (c.guided ? (c.world ? " guided with the world guide" : " guided") : " path traced") +
      " at scale " + std::to_string(c.scale);
  int exponent = 0;
  if (std::frexp(c.scale, &exponent) == 0.5f)
    expect_identical(base, other, what);
  else
    expect_same_image(base, other, what);
  for (float v : other.state) ASSERT_TRUE(std::isfinite(v)) << what << ": guiding state";
  if (c.world) {
    // The guide was used at both scales, not left empty by a grid that missed the scene.
    ASSERT_EQ(other.world.size(), 5u);
    EXPECT_GT(other.world[0], 0.0) << what << ": world cells";
    EXPECT_GT(other.world[4], 0.0) << what << ": vertices guided by the world guide";
  }
}

// Powers of two (exact) and the decimal scales, on the Cornell box (built from shapes:
// always there) and on Veach Ajar (textured; its assets come from ../shared/scenes and its
// cases skip without them).
INSTANTIATE_TEST_SUITE_P(
    Scales, ScaleInvariance,
    ::testing::Values(
        ScaleCase{"cornell-box.json", 0x1p-14f, false, "CornellTwoToMinus14PT"},
        ScaleCase{"cornell-box.json", 0x1p17f, false, "CornellTwoTo17PT"},
        ScaleCase{"cornell-box.json", 0x1p-14f, true, "CornellTwoToMinus14PG"},
        ScaleCase{"cornell-box.json", 0x1p17f, true, "CornellTwoTo17PG"},
        ScaleCase{"veach-ajar.json", 0x1p-10f, true, "VeachAjarTwoToMinus10PG"},
        ScaleCase{"veach-ajar.json", 0x1p10f, true, "VeachAjarTwoTo10PG"},
        ScaleCase{"cornell-box.json", 1e-4f, false, "CornellTenThousandthPT"},
        ScaleCase{"cornell-box.json", 1e-3f, false, "CornellThousandthPT"},
        ScaleCase{"cornell-box.json", 1e3f, false, "CornellThousandPT"},
        ScaleCase{"cornell-box.json", 1e4f, false, "CornellTenThousandPT"},
        ScaleCase{"cornell-box.json", 1e5f, false, "CornellHundredThousandPT"},
        ScaleCase{"cornell-box.json", 1e-4f, true, "CornellTenThousandthPG"},
        ScaleCase{"cornell-box.json", 1e-3f, true, "CornellThousandthPG"},
        ScaleCase{"cornell-box.json", 1e3f, true, "CornellThousandPG"},
        ScaleCase{"cornell-box.json", 1e4f, true, "CornellTenThousandPG"},
        ScaleCase{"cornell-box.json", 1e5f, true, "CornellHundredThousandPG"},
        ScaleCase{"veach-ajar.json", 1e-3f, false, "VeachAjarThousandthPT"},
        ScaleCase{"veach-ajar.json", 1e4f, false, "VeachAjarTenThousandPT"},
        ScaleCase{"veach-ajar.json", 1e-3f, true, "VeachAjarThousandthPG"},
        ScaleCase{"veach-ajar.json", 1e4f, true, "VeachAjarTenThousandPG"},
        // The world guide's cells are a fixed fraction of the scene's extent, so at a power of
        // two the same vertices share the same cells. At a decimal scale rounding moves some
        // vertices into the neighbouring cell and the two runs' paths part: on the Cornell box
        // rarely (paired differences near 1e-5 of the mean), on Veach Ajar so often that 48
        // frames of its heavy-tailed paths spread the paired mean by about 1% a standard error,
        // too wide for the 1% bound. Measured at 1e4, 96 frames, six seeds: differences of
        // +4.7e-3 to -3.3e-3 on a mean of 0.31, of either sign (with seed 5, 1e-3, 1e-2, 1e2 and
        // 1e4 were all 1.2-3.4 standard errors below the one unscaled run they share). So Veach
        // Ajar is checked at powers of two, bit for bit.
        ScaleCase{"cornell-box.json", 0x1p-14f, true, "CornellTwoToMinus14World", true},
        ScaleCase{"cornell-box.json", 0x1p17f, true, "CornellTwoTo17World", true},
        ScaleCase{"cornell-box.json", 1e-3f, true, "CornellThousandthWorld", true},
        ScaleCase{"cornell-box.json", 1e4f, true, "CornellTenThousandWorld", true},
        ScaleCase{"veach-ajar.json", 0x1p10f, true, "VeachAjarTwoTo10World", true},
        ScaleCase{"veach-ajar.json", 0x1p-10f, true, "VeachAjarTwoToMinus10World", true}),
    [](const ::testing::TestParamInfo<ScaleCase>& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace rtpg

// Whole-image checks of guiding (issue: unbiasedness and benefit). Guided frames must average to
// the same image as plain path tracing, and on the indirectly lit Cornell box they must have a
// clearly lower error at 1 sample per pixel once trained.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "rtpg/cl_runtime.h"
#include "render/guided_first_bounce.h"
#include "render/image_io.h"
#include "render/renderer.h"
#include "scene/scene_loader.h"

namespace rtpg {
namespace {

std::string scene_file(const char* name) {
  return std::string(RTPG_SOURCE_DIR) + "/scenes/" + name;
}

// Per-frame means of tiles (and of the whole image) over many frames, for a z-test of two
// independent estimators: the frame-to-frame spread gives the standard error honestly, even
// though pixels within a frame share a G-buffer and training state.
struct TileSeries {
  int tiles_x = 0, tiles_y = 0, tile = 16;
  std::vector<std::vector<double>> per_tile;  // [tile][frame] mean luminance
  std::vector<double> whole;                  // [frame]
  std::uint64_t guided_vertices = 0;          // later vertices that borrowed a guide
};

// How a run is rendered beyond the method: samples per pixel per frame and a camera path
// (empty: the scene's static camera).
struct RunShape {
  int spp = 1;
  std::string camera_path;
  bool guide_secondary = false;  // later vertices borrow their pixel's mixture
};

TileSeries run(const Scene& scene, bool guided, int size, int frames, ClRuntime& cl,
               const RunShape& shape) {
  RenderSettings settings;
  settings.width = settings.height = size;
  settings.spp = shape.spp;
  settings.camera_path = shape.camera_path;
  settings.path_tracer.guide_secondary = guided && shape.guide_secondary;
  settings.jitter = false;  // both methods estimate the same integral per pixel
  settings.seed = guided ? 11u : 12u;
  settings.path_tracer.max_bounces = scene.max_bounces > 0 ? scene.max_bounces : 8;
  Renderer renderer(scene, settings);
  if (guided)
    renderer.set_first_bounce_sampler(
        std::make_unique<GuidedFirstBounce>(cl, size, size, GuidingSettings{}));
  TileSeries s;
  s.tiles_x = s.tiles_y = size / s.tile;
  s.per_tile.assign(s.tiles_x * s.tiles_y, {});
  for (int f = 0; f < frames; ++f) {
    s.guided_vertices += renderer.render_frame(f).guided_vertices;
    const auto& img = renderer.image();
    std::vector<double> sums(s.per_tile.size(), 0.0);
    double total = 0.0;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const glm::vec3 c = img[static_cast<std::size_t>(y) * size + x];
        const double l = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        sums[(y / s.tile) * s.tiles_x + x / s.tile] += l;
        total += l;
      }
    for (std::size_t t = 0; t < sums.size(); ++t)
      s.per_tile[t].push_back(sums[t] / (s.tile * s.tile));
    s.whole.push_back(total / (static_cast<double>(size) * size));
  }
  return s;
}

void mean_and_variance(const std::vector<double>& v, double& mean, double& var_of_mean) {
  double m = 0.0;
  for (double x : v) m += x;
  m /= static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - m) * (x - m);
  mean = m;
  var_of_mean = ss / static_cast<double>(v.size() - 1) / static_cast<double>(v.size());
}

// z-score bound for a two-sided test at level alpha (0.01) after a Sidak correction over m
// comparisons: inverse normal CDF by bisection on erfc.
double z_bound(int m) {
  const double alpha = 1.0 - std::pow(0.99, 1.0 / m);
  double lo = 0.0, hi = 10.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > alpha ? lo : hi) = mid;
  }
  return hi;
}

void expect_same_means(const char* name, int frames, const RunShape& shape = {}) {
  const Scene scene = load_scene(scene_file(name));
  ClRuntime cl;
  const int size = 64;
  const TileSeries pt = run(scene, false, size, frames, cl, shape);
  const TileSeries pg = run(scene, true, size, frames, cl, shape);
  const int comparisons = static_cast<int>(pt.per_tile.size()) + 1;
  const double z = z_bound(comparisons);
  auto check = [&](const std::vector<double>& a, const std::vector<double>& b,
                   const std::string& what) {
    double ma, va, mb, vb;
    mean_and_variance(a, ma, va);
    mean_and_variance(b, mb, vb);
    const double se = std::sqrt(va + vb);
    EXPECT_LE(std::fabs(ma - mb), z * se)
        << name << " " << what << ": PT " << ma << " vs guided " << mb << " (standard error " << se
        << ", bound " << z << " sigma)";
  };
  if (shape.guide_secondary) {
    // The borrowed guides were really used (else the test would compare PT with PT).
    EXPECT_GT(pg.guided_vertices, static_cast<std::uint64_t>(frames) * size * size / 10)
        << name << ": later vertices that sampled a borrowed guide";
  }
  check(pt.whole, pg.whole, "whole image");
  for (std::size_t t = 0; t < pt.per_tile.size(); ++t)
    check(pt.per_tile[t], pg.per_tile[t], "tile " + std::to_string(t));
}

TEST(GuidingImage, UnbiasedOnCornellBox) {
  expect_same_means("cornell-box.json", 160);
}

// At its full depth (8 bounces) the scene's one-path radiance is heavy-tailed: 640 frames keep
// the per-tile means close enough to normal for the z-test (at 160 one tile reached 3.5 sigma,
// and passed at 640: noise, not bias).
TEST(GuidingImage, UnbiasedOnCornellIndirect) {
  expect_same_means("cornell-indirect.json", 640);
}

// Several samples per frame: every sample of a frame is drawn from one model and next-event
// MIS weighs against that same model (training waits for the frame's last sample).
TEST(GuidingImage, UnbiasedAtFourSppOnCornellBox) {
  expect_same_means("cornell-box.json", 80, RunShape{4, ""});
}

// Later vertices borrow the mixture of the pixel that shows them: their BSDF samples, their
// guide samples and next-event MIS use one density (cornell-box: most light arrives by NEE;
// a guide density without the BSDF's (1 - pi) factor fails here by 25 standard errors).
TEST(GuidingImage, UnbiasedWithLaterVerticesGuidedOnCornellBox) {
  expect_same_means("cornell-box.json", 160, RunShape{1, "", true});
}

// A moving camera: every frame reprojects the state before sampling. Both methods render the
// same camera at the same frame index, so their means over the frames agree.
TEST(GuidingImage, UnbiasedAlongCameraPathAtTwoSpp) {
  expect_same_means("cornell-box.json", 120, RunShape{2, "pan"});
}

// cornell-indirect with one indirect bounce (max_bounces 2, the budget first-bounce guiding
// targets), 128x128, fixed seed, 32 frames at 1 spp; the mean relMSE of the last 8 frames with
// guiding is at most 0.7 times that without, against a 1024-spp reference rendered here. At the
// scene's full depth the ratio is 0.79 today (docs/guiding.md): not yet guarded.
TEST(GuidingImage, HalvesErrorOnCornellIndirect) {
  const Scene scene = load_scene(scene_file("cornell-indirect.json"));
  ClRuntime cl;
  const int size = 128;
  RenderSettings settings;
  settings.width = settings.height = size;
  settings.path_tracer.max_bounces = 2;

  ImageRgb reference{size, size, std::vector<glm::vec3>(size * size, glm::vec3(0.0f))};
  {
    RenderSettings ref_settings = settings;
    ref_settings.seed = 1000;
    ref_settings.spp = 4;
    Renderer renderer(scene, ref_settings);
    const int passes = 256;  // 1024 spp
    for (int p = 0; p < passes; ++p) {
      renderer.render_frame(p);
      for (std::size_t i = 0; i < reference.pixels.size(); ++i)
        reference.pixels[i] += renderer.image()[i] / float(passes);
    }
  }
  double error[2] = {0.0, 0.0};
  for (int guided = 0; guided < 2; ++guided) {
    Renderer renderer(scene, settings);
    if (guided)
      renderer.set_first_bounce_sampler(
          std::make_unique<GuidedFirstBounce>(cl, size, size, GuidingSettings{}));
    for (int f = 0; f < 32; ++f) {
      renderer.render_frame(f);
      if (f >= 24)
        error[guided] += relative_mse(ImageRgb{size, size, renderer.image()}, reference) / 8.0;
    }
  }
  RecordProperty("relmse_pt", std::to_string(error[0]));
  RecordProperty("relmse_pg", std::to_string(error[1]));
  EXPECT_LE(error[1], 0.7 * error[0]) << "PT " << error[0] << ", guided " << error[1];
  std::printf(
      "cornell-indirect 128x128, last 8 of 32 frames: relMSE PT %.4f, guided %.4f (ratio %.3f)\n",
      error[0], error[1], error[1] / error[0]);
}

}  // namespace
}  // namespace rtpg

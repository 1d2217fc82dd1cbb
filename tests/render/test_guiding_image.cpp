// Whole-image checks of guiding (issue: unbiasedness and benefit). Guided frames must average to
// the same image as plain path tracing, and on the indirectly lit Cornell box they must have a
// clearly lower error at 1 sample per pixel once trained.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rtpg/cl_runtime.h"
#include "rtpg/guiding_settings.h"
#include "forwarding_sampler.h"
#include "render/guided_first_bounce.h"
#include "render/image_io.h"
#include "render/renderer.h"
#include "scene/scene_loader.h"
#include "shared/bit_packing.h"
#include "shared/vpl_packing.h"
#include "support/scene_edits.h"

namespace rtpg {
namespace {

std::string scene_file(const char* name) {
  return std::string(RTPG_SOURCE_DIR) + "/scenes/" + name;
}

// Per-frame means of tiles (and of the whole image) over many frames, for a paired z-test of
// two independent estimators: the frame-to-frame spread gives the standard error honestly, even
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
  bool world_guide = false;      // later vertices sample the world-space guide's cells
  int world_max_depth = WorldGuideSettings{}.max_depth;  // the deepest vertex it guides
  bool pi_learning = false;  // the variance-aware mixing weight (GuidingSettings)
  int rows_per_model = 1;    // models shared by rows (GuidingSettings)
  FirstBounceMis first_bounce_mis = FirstBounceMis::bsdf;  // PathTracerSettings
  bool direct_light_in_vpls = true;                        // PathTracerSettings
  HostTransfer transfer = HostTransfer::automatic;         // the guided first bounce's
};

// A guided sampler whose first-bounce samples claim a density 5% too high: every path that
// leaves the primary hit is weighted 5% too low, a bias the unbiasedness checks must reject.
class PdfTooHigh final : public ForwardingSampler {
 public:
  using ForwardingSampler::ForwardingSampler;
  FirstBounceSamples sample(const GBuffer& g, const SampleCoordinates& at) override {
    const FirstBounceSamples inner = ForwardingSampler::sample(g, at);
    direction_pdf_.resize(g.pixel_count());
    strategy_.resize(g.pixel_count());
    for (std::size_t i = 0; i < g.pixel_count(); ++i) {  // as they came, or packed
      const FirstBounceSample s = inner.at(i);
      direction_pdf_[i] = glm::vec4(s.direction, s.pdf * 1.05f);
      strategy_[i] = s.strategy;
    }
    return FirstBounceSamples{direction_pdf_.data(), strategy_.data()};
  }

 private:
  std::vector<glm::vec4> direction_pdf_;
  std::vector<std::uint32_t> strategy_;
};

// A guided sampler whose pdf(), the density next-event estimation at the primary hit weighs its
// light sample against under FirstBounceMis::mixture, is twice the density its samples were
// drawn with. Any density serves multiple importance sampling if both strategies' weights use
// it (they then sum to one for every direction); only the variance changes. So the image must
// stay unbiased: the first bounce's hit on a light must weigh itself with pdf() too, not with
// the sample's own density, which on a device with memory of its own comes from a G-buffer
// rounded for the bus and differs from the host's pdf() by 1e-4 to 1e-3 (docs/guiding.md, "One
// density for both weights at the primary hit").
class MisDensityTwiceTheSamples final : public ForwardingSampler {
 public:
  using ForwardingSampler::ForwardingSampler;
  float pdf(const GBuffer& g, std::size_t i, const shared::pg_lobes& lobes, const glm::vec3& wo,
            const glm::vec3& wi) const override {
    return 2.0f * ForwardingSampler::pdf(g, i, lobes, wo, wi);
  }
};

enum class Method { PathTracing, Guided, GuidedWithBias, GuidedWithOtherMisDensity };

TileSeries run(const Scene& scene, Method method, int size, int frames, ClRuntime& cl,
               const RunShape& shape) {
  const bool guided = method != Method::PathTracing;
  RenderSettings settings;
  settings.width = settings.height = size;
  settings.spp = shape.spp;
  settings.camera_path = shape.camera_path;
  settings.path_tracer.guide_secondary = guided && shape.guide_secondary;
  settings.world_guide = guided && shape.world_guide;
  settings.world_guide_settings.em = to_kernel_settings(GuidingSettings{});
  settings.world_guide_settings.max_depth = shape.world_max_depth;
  settings.path_tracer.first_bounce_mis = shape.first_bounce_mis;
  settings.path_tracer.direct_light_in_vpls = shape.direct_light_in_vpls;
  settings.jitter = false;  // both methods estimate the same integral per pixel
  settings.seed = guided ? 11u : 12u;
  settings.path_tracer.max_bounces = scene.max_bounces > 0 ? scene.max_bounces : 8;
  Renderer renderer(scene, settings);
  if (guided) {
    GuidingSettings guiding;
    guiding.pi_learning = shape.pi_learning ? 1 : 0;
    guiding.rows_per_model = shape.rows_per_model;
    std::unique_ptr<FirstBounceSampler> sampler =
        std::make_unique<GuidedFirstBounce>(cl, size, size, guiding, shape.transfer);
    if (method == Method::GuidedWithBias)
      sampler = std::make_unique<PdfTooHigh>(std::move(sampler));
    if (method == Method::GuidedWithOtherMisDensity)
      sampler = std::make_unique<MisDensityTwiceTheSamples>(std::move(sampler));
    renderer.set_first_bounce_sampler(std::move(sampler));
  }
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

// The outcome of comparing path tracing's per-frame means with another method's: the whole
// image and every 16x16 tile by a z-test at family-wise level 0.01 (Sidak).
struct Comparison {
  std::vector<std::string> rejected;  // what differed beyond the bound
  double z = 0.0;                     // the bound, in standard errors
  double whole_relative_se = 0.0;     // standard error of the whole-image difference / mean
  double worst_tile_relative_se = 0.0;
  double whole_relative_difference = 0.0;  // (other - PT) / PT
  std::uint64_t guided_vertices = 0;
};

Comparison compare_means(const char* name, const Scene& scene, Method method, int frames,
                         const RunShape& shape) {
  ClRuntime cl;
  const int size = 64;
  const TileSeries pt = run(scene, Method::PathTracing, size, frames, cl, shape);
  const TileSeries pg = run(scene, method, size, frames, cl, shape);
  Comparison c;
  c.guided_vertices = pg.guided_vertices;
  c.z = z_bound(static_cast<int>(pt.per_tile.size()) + 1);
  auto check = [&](const std::vector<double>& a, const std::vector<double>& b,
                   const std::string& what, double& relative_se) {
    // Paired by frame (the same camera at the same index, independent seeds): along a camera
    // path the image mean moves from frame to frame, which the difference does not see.
    std::vector<double> difference(a.size());
    for (std::size_t f = 0; f < a.size(); ++f) difference[f] = b[f] - a[f];
    double ma, va, mb, vb, md, vd;
    mean_and_variance(a, ma, va);
    mean_and_variance(b, mb, vb);
    mean_and_variance(difference, md, vd);
    const double se = std::sqrt(vd);
    relative_se = ma > 0.0 ? se / ma : 0.0;
    if (std::fabs(ma - mb) > c.z * se)
      c.rejected.push_back(what + ": PT " + std::to_string(ma) + " vs " + std::to_string(mb) +
                           " (standard error " + std::to_string(se) + ")");
    return (mb - ma) / ma;
  };
  c.whole_relative_difference = check(pt.whole, pg.whole, "whole image", c.whole_relative_se);
  for (std::size_t t = 0; t < pt.per_tile.size(); ++t) {
    double tile_se = 0.0;
    check(pt.per_tile[t], pg.per_tile[t], "tile " + std::to_string(t), tile_se);
    c.worst_tile_relative_se = std::max(c.worst_tile_relative_se, tile_se);
  }
  std::printf(
      "%s: whole image %+.3f%% (relative standard error %.3f%%), worst tile relative standard "
      "error %.2f%%, bound %.2f standard errors, %zu rejected\n",
      name, 100.0 * c.whole_relative_difference, 100.0 * c.whole_relative_se,
      100.0 * c.worst_tile_relative_se, c.z, c.rejected.size());
  return c;
}

Comparison compare_means(const char* name, Method method, int frames, const RunShape& shape) {
  return compare_means(name, load_scene(scene_file(name)), method, frames, shape);
}

// Guided and plain path tracing agree on the whole image and every tile, and the check has
// power: the whole image's standard error is below `max_relative_se` of its mean, so a bias of
// z (3.44) times that is detected. Measured: 0.05-0.07% on cornell-box (bound 0.15%, a 0.5%
// bias is caught), 1.0% on cornell-indirect at 8 bounces (bound 1.5%).
void expect_same_means(const char* name, const Scene& scene, int frames, double max_relative_se,
                       const RunShape& shape) {
  const Comparison c = compare_means(name, scene, Method::Guided, frames, shape);
  for (const std::string& r : c.rejected) ADD_FAILURE() << name << " " << r;
  EXPECT_LE(c.whole_relative_se, max_relative_se) << name;
  if (shape.guide_secondary || shape.world_guide) {
    // The borrowed guides were really used (else the test would compare PT with PT).
    EXPECT_GT(c.guided_vertices, static_cast<std::uint64_t>(frames) * 64 * 64 / 10)
        << name << ": later vertices that sampled a borrowed guide";
  }
}

void expect_same_means(const char* name, int frames, double max_relative_se,
                       const RunShape& shape = {}) {
  expect_same_means(name, load_scene(scene_file(name)), frames, max_relative_se, shape);
}

TEST(GuidingImage, UnbiasedOnCornellBox) {
  expect_same_means("cornell-box.json", 160, 0.0015);
}

// At its full depth (8 bounces) the scene's one-path radiance is heavy-tailed: 640 frames keep
// the per-tile means close enough to normal for the z-test (at 160 one tile reached 3.5 sigma,
// and passed at 640: noise, not bias).
TEST(GuidingImage, UnbiasedOnCornellIndirect) {
  expect_same_means("cornell-indirect.json", 640, 0.015);
}

// Several samples per frame: every sample of a frame is drawn from one model and next-event
// MIS weighs against that same model (training waits for the frame's last sample). 160 frames:
// at 80, when the training walk's start became shared per run of 16 pixels (other random
// draws), the top-left tile reached 3.5 standard errors (bound 3.44); rendered 4x longer with
// two seeds each that tile agreed with path tracing within 0.5%, as two PT seeds do (noise,
// not bias), and at 160 frames the test passes with a smaller standard error.
TEST(GuidingImage, UnbiasedAtFourSppOnCornellBox) {
  expect_same_means("cornell-box.json", 160, 0.0015, RunShape{4, ""});
}

// Later vertices borrow the mixture of the pixel that shows them: their BSDF samples, their
// guide samples and next-event MIS use one density (cornell-box: most light arrives by NEE;
// a guide density without the BSDF's (1 - pi) factor fails here by 25 standard errors).
TEST(GuidingImage, UnbiasedWithLaterVerticesGuidedOnCornellBox) {
  expect_same_means("cornell-box.json", 160, 0.0015, RunShape{1, "", true});
}

// Later vertices sample the world-space guide's cells (render/world_guide.h), trained from every
// later vertex's bounce at the end of each frame: the bounce's density, its hit's MIS weight and
// the light sample's at the vertex use one model for the whole frame. At 2 spp along the camera
// path, and on cornell-indirect, where most of the light arrives after the first bounce.
TEST(GuidingImage, UnbiasedWithTheWorldGuideAlongCameraPathAtTwoSpp) {
  RunShape shape{2, "pan"};
  shape.world_guide = true;
  expect_same_means("cornell-box.json", 120, 0.0015, shape);
}

// The box turned by 20 degrees about a diagonal axis: no wall is aligned with a cell's normal axis,
// so a cell's hemisphere frame differs from every vertex's shading frame (on the box as it is
// they coincide, and a density computed in the wrong one of the two goes unseen; mutant
// world-square-in-vertex-frame).
TEST(GuidingImage, UnbiasedWithTheWorldGuideOnATurnedBox) {
  Scene scene = load_scene(scene_file("cornell-box.json"));
  const glm::vec3 axis = glm::normalize(glm::vec3(1.0f, 1.0f, 0.3f));
  const float angle = glm::radians(20.0f);
  // Rodrigues' rotation matrix.
  const glm::mat3 k(0.0f, axis.z, -axis.y, -axis.z, 0.0f, axis.x, axis.y, -axis.x, 0.0f);
  const glm::mat3 rotation =
      glm::mat3(1.0f) + std::sin(angle) * k + (1.0f - std::cos(angle)) * k * k;
  test::rotate_meshes(scene, rotation, 0.5f * (scene.bounds_min() + scene.bounds_max()));
  RunShape shape{2, ""};
  shape.world_guide = true;
  expect_same_means("cornell-box.json, turned", scene, 480, 0.0015, shape);
}

TEST(GuidingImage, UnbiasedWithTheWorldGuideOnCornellIndirect) {
  RunShape shape;
  shape.world_guide = true;
  shape.world_max_depth = 8;  // every vertex, beyond the default's two
  expect_same_means("cornell-indirect.json", 640, 0.015, shape);
}

// A moving camera: every frame reprojects the state before sampling. Both methods render the
// same camera at the same frame index, so their means over the frames agree.
TEST(GuidingImage, UnbiasedAlongCameraPathAtTwoSpp) {
  expect_same_means("cornell-box.json", 120, 0.0015, RunShape{2, "pan"});
}

// Later vertices borrowing mixtures along a moving camera at 2 spp: the table of borrowable
// pixels (PathTracer::collect_borrowable) is rebuilt for every sample's camera and model.
TEST(GuidingImage, UnbiasedWithLaterVerticesGuidedAlongCameraPathAtTwoSpp) {
  expect_same_means("cornell-box.json", 120, 0.0015, RunShape{2, "pan", true});
}

// The variance-aware mixing weight (--pg-pi-learning 1) changes only the densities the first
// bounce samples with, and next-event MIS weighs against the same ones.
TEST(GuidingImage, UnbiasedWithLearnedMixingWeightAlongCameraPathAtTwoSpp) {
  RunShape shape{2, "pan"};
  shape.pi_learning = true;
  expect_same_means("cornell-box.json", 120, 0.0015, shape);
}

// Models shared by groups of four rows (--pg-rows-per-model 4): a pixel samples with the model of
// the pixel above it where the two show one surface, and its first bounce's density, in the
// samples and in next-event MIS, is that model's, along a moving camera.
TEST(GuidingImage, UnbiasedWithModelsSharedByRowsAlongCameraPathAtTwoSpp) {
  RunShape shape{2, "pan"};
  shape.rows_per_model = 4;
  expect_same_means("cornell-box.json", 120, 0.0015, shape);
}

// The Cornell box under a light that fills most of its ceiling (1.8 m square instead of 0.5 m,
// its emission scaled down by the area), where the light sample's and the first bounce's
// densities are of one size and the guide learns the light: either MIS density must leave the
// image unbiased. Here the weights that do not sum to one (mutant first-bounce-mis-mixed) are
// seen, where the small light's were not: its light sample's density dwarfs both others. The
// third run leaves the light y emits out of the VPLs (--guide-direct-light off), so that the
// pixel keeps it apart from its path (PathTracer::VplPath; mutant vpl-left-out-light-unweighted).
// The last two guide later vertices too (--guide-vertices all), whose light sample and bounce
// weigh each other with the same density as the primary hit's.
TEST(GuidingImage, UnbiasedUnderALargeLightWithEitherMisDensity) {
  Scene scene = load_scene(scene_file("cornell-box.json"));
  test::resize_emitters(scene, 3.6f, 1.0f / (3.6f * 3.6f));
  struct Variant {
    FirstBounceMis mis;
    bool direct_light_in_vpls;
    bool guide_secondary;
  };
  for (const Variant v :
       {Variant{FirstBounceMis::mixture, true, false}, Variant{FirstBounceMis::bsdf, true, false},
        Variant{FirstBounceMis::bsdf, false, false}, Variant{FirstBounceMis::mixture, true, true},
        Variant{FirstBounceMis::bsdf, true, true}}) {
    RunShape shape{2, "pan"};
    shape.first_bounce_mis = v.mis;
    shape.direct_light_in_vpls = v.direct_light_in_vpls;
    shape.guide_secondary = v.guide_secondary;
    const Comparison c =
        compare_means("cornell-box.json, large light", scene, Method::Guided, 120, shape);
    for (const std::string& r : c.rejected)
      ADD_FAILURE() << "mis " << static_cast<int>(v.mis) << ", direct light in VPLs "
                    << v.direct_light_in_vpls << ", later vertices guided " << v.guide_secondary
                    << ": " << r;
    EXPECT_LE(c.whole_relative_se, 0.0015);
  }
}

// The MIS density under FirstBounceMis::mixture is the sampler's pdf() on both sides, whatever
// the density the samples carry (MisDensityTwiceTheSamples): under the large light, where
// weights that do not sum to one are seen, and under a constant sky seen through the box's open
// side, where the first bounce's escaped paths weigh themselves against the sky's light samples.
TEST(GuidingImage, UnbiasedWhenTheMisDensityIsNotTheSamplesOwn) {
  Scene large_light = load_scene(scene_file("cornell-box.json"));
  test::resize_emitters(large_light, 3.6f, 1.0f / (3.6f * 3.6f));
  Scene sky = load_scene(scene_file("cornell-box.json"));
  sky.environment.kind = Environment::Kind::Constant;
  sky.environment.color = glm::vec3(2.0f);
  for (const auto& [name, scene] :
       {std::pair<const char*, const Scene*>{"large light", &large_light},
        std::pair<const char*, const Scene*>{"sky", &sky}}) {
    RunShape shape{2, "pan"};
    shape.first_bounce_mis = FirstBounceMis::mixture;
    const Comparison c = compare_means(
        (std::string("cornell-box.json, MIS density twice the samples', ") + name).c_str(), *scene,
        Method::GuidedWithOtherMisDensity, 120, shape);
    for (const std::string& r : c.rejected) ADD_FAILURE() << name << ": " << r;
    EXPECT_LE(c.whole_relative_se, 0.0015) << name;
  }
}

// The G-buffer packed on its way to the device (--host-transfer packed): the device samples with a
// BSDF and a frame rounded to half floats and octahedral vectors, and returns the density of
// what it did, so the image stays unbiased (kernels/shared/gbuffer_packing.h). Along the camera
// path at 2 spp, the other host transfers' images being the same to the bit
// (EveryHostTransferGivesTheSameImage).
TEST(GuidingImage, UnbiasedWithThePackedGBufferAlongCameraPathAtTwoSpp) {
  RunShape shape{2, "pan"};
  shape.transfer = HostTransfer::packed;
  expect_same_means("cornell-box.json", 120, 0.0015, shape);
}

// Four samples per frame along the camera path: reprojection, a model shared by the frame's
// samples and next-event MIS against it, together.
TEST(GuidingImage, UnbiasedAlongCameraPathAtFourSpp) {
  expect_same_means("cornell-box.json", 60, 0.0015, RunShape{4, "pan"});
}

// The checks above have power: the same comparison rejects a guided sampler whose first-bounce
// pdf is 5% too high (the image then loses 5% of what arrives through the first bounce).
TEST(GuidingImage, RejectsAFivePercentPdfError) {
  const Comparison c = compare_means("cornell-box.json", Method::GuidedWithBias, 160, {});
  EXPECT_FALSE(c.rejected.empty()) << "a 5% pdf error passed as unbiased";
  EXPECT_LT(c.whole_relative_difference, 0.0);
}

// The transfer tests' frames: 37x23 at 2 spp along the scene's first camera path.
// Pixels whose values differ in any bit between two images of the same size.
std::size_t pixels_that_differ(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differ += a[i] != b[i];
  return differ;
}

RenderSettings odd_size_along_camera_path(const Scene& scene) {
  RenderSettings settings;
  settings.width = 37;
  settings.height = 23;
  settings.spp = 2;
  settings.camera_path = scene.camera.paths.begin()->first;
  return settings;
}

// Where the device shares host memory (as PoCL's CPU device does) the guided first bounce
// reads the G-buffer and VPLs in place (the renderer alternating two G-buffers) and the host
// reads the samples in place; elsewhere all three are copied. Both give the same image to the
// bit, at 2 spp (the samples' mapping is released and renewed between samples) along a moving
// camera, at an odd size, over enough frames for each G-buffer to be reused. So does a sampler
// told that the host reads the mixture (the sample kernel then writes it and the host copies or
// maps it, which the renderer's default MIS does not need: FirstBounceSampler::expect_queries);
// without that, asking for the mixture is an error, not a read of stale memory.
TEST(GuidingImage, EveryHostTransferGivesTheSameImage) {
  ClRuntime cl;
  const Scene scene = load_scene(scene_file("cornell-box.json"));
  const RenderSettings settings = odd_size_along_camera_path(scene);
  struct Case {
    HostTransfer transfer;
    bool mixture;  // the host announced as reading the mixture
  };
  // The packed G-buffer (last) rounds what the device samples with: its image is checked for
  // bias elsewhere (UnbiasedWithThePackedGBufferAlongCameraPathAtTwoSpp), its bytes here.
  const Case cases[] = {{HostTransfer::in_place, false}, {HostTransfer::pinned, false},
                        {HostTransfer::pageable, false}, {HostTransfer::automatic, false},
                        {HostTransfer::in_place, true},  {HostTransfer::pinned, true},
                        {HostTransfer::packed, false}};
  constexpr int kCases = static_cast<int>(std::size(cases));
  std::vector<glm::vec3> images[kCases];
  HostTransfer used_by[kCases];
  for (int t = 0; t < kCases; ++t) {
    SCOPED_TRACE(std::string(host_transfer_name(cases[t].transfer)) +
                 (cases[t].mixture ? ", mixture read" : ""));
    Renderer renderer(scene, settings);
    // Training waited for, so that every frame reads the count records of its own training
    // (TrainingOverlappedGivesTheSameImage checks the overlapped order).
    auto guided = std::make_unique<GuidedFirstBounce>(
        cl, settings.width, settings.height, GuidingSettings{}, cases[t].transfer, Overlap::off);
    GuidedFirstBounce* sampler = guided.get();
    const HostTransfer used = guided->host_transfer();
    used_by[t] = used;
    const double count_records = static_cast<double>(sampler->guider().sample_count_record_bytes() +
                                                     sampler->guider().train_count_record_bytes()) /
                                 (settings.width * settings.height);
    renderer.set_first_bounce_sampler(std::move(guided));
    if (cases[t].mixture) sampler->expect_queries({true, true});
    for (int f = 0; f < 5; ++f) {
      const FrameStats stats = renderer.render_frame(f);
      const bool in_place = used == HostTransfer::in_place;
      EXPECT_EQ(stats.extra.at("zero_copy"), in_place ? 1.0 : 0.0);
      EXPECT_EQ(stats.extra.at("host_transfer"), static_cast<double>(used));
      // In place only the kernels' count records are copied; otherwise the G-buffer (96 bytes
      // a pixel, 24 packed) and VPLs (32, 10 packed) go up and each sample's direction,
      // density and strategy (20, 12 packed) come down, with the mixture (24) where the host
      // reads it (include/rtpg/guiding_layout.h).
      const bool packed = used == HostTransfer::packed;
      const double sample_bytes = (packed ? 12.0 : 20.0) + (cases[t].mixture ? 24.0 : 0.0);
      const double gbuffer_bytes = packed ? 24.0 : 96.0, vpl_bytes = packed ? 10.0 : 32.0;
      EXPECT_DOUBLE_EQ(stats.extra.at("host_device_bytes_per_pixel"),
                       (in_place ? 0.0 : gbuffer_bytes + sample_bytes * settings.spp + vpl_bytes) +
                           count_records);
      EXPECT_EQ(stats.time_ms.count("unpack"), used == HostTransfer::packed ? 1u : 0u);
    }
    if (cases[t].transfer == HostTransfer::automatic) {
      // RTPG_HOST_TRANSFER chooses where set (the tests' second run sets it to packed).
      const char* env = std::getenv("RTPG_HOST_TRANSFER");
      const HostTransfer expected = env && *env && std::string(env) != "auto"
                                        ? parse_host_transfer(env)
                                    : cl.info().host_unified_memory ? HostTransfer::in_place
                                                                    : HostTransfer::packed;
      EXPECT_EQ(used, expected);
    }
    const GBuffer& g = renderer.gbuffer();
    const std::size_t pixel = g.pixel_count() / 2;
    ASSERT_TRUE(g.has_surface(pixel));
    const shared::pg_lobes lobes{};
    if (cases[t].mixture) {
      EXPECT_NO_THROW(sampler->pdf(g, pixel, lobes, glm::vec3(0, 0, 1), glm::vec3(0, 0, 1)));
    } else {
      EXPECT_THROW(sampler->pdf(g, pixel, lobes, glm::vec3(0, 0, 1), glm::vec3(0, 0, 1)),
                   GuiderError);
      PixelGuide guide;
      EXPECT_THROW(sampler->pixel_guide(g, pixel, guide), GuiderError);
    }
    images[t] = renderer.image();
  }
  for (int t = 1; t < kCases; ++t) {
    ASSERT_EQ(images[0].size(), images[t].size());
    if (used_by[t] == HostTransfer::packed) continue;
    EXPECT_EQ(pixels_that_differ(images[0], images[t]), 0u)
        << host_transfer_name(cases[t].transfer) << (cases[t].mixture ? ", mixture read" : "")
        << ": of " << images[0].size() << " pixels";
  }
}

// The VPLs sent packed (10 bytes a pixel) reach the training as the host found them: along a
// moving camera at 2 spp (sample 0's directions, which the VPLs followed, kept apart from sample
// 1's) and at an odd size, the device's rebuilt VPLs have the host's info bits, positions within
// 1e-4 of the distance they lie at (and the pixel point's own rounding), densities within the 8-bit
// normal's cosine (and the rounding of the device's BSDF density), radiance within its shared
// exponent.
TEST(GuidingImage, PackedVplsReachTheTrainingAsTheHostFoundThem) {
  const Scene scene = load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
  const RenderSettings settings = odd_size_along_camera_path(scene);
  ClRuntime cl;
  Renderer renderer(scene, settings);
  auto guided = std::make_unique<GuidedFirstBounce>(
      cl, settings.width, settings.height, GuidingSettings{}, HostTransfer::packed, Overlap::off);
  GuidedFirstBounce* sampler = guided.get();
  renderer.set_first_bounce_sampler(std::move(guided));
  const std::size_t n = static_cast<std::size_t>(settings.width) * settings.height;
  std::vector<glm::vec4> position(n);
  std::vector<shared::uint4> nr(n);
  for (int f = 0; f < 4; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    renderer.render_frame(f);
    const GuiderVpls& device = sampler->device_vpls();
    cl.queue().enqueueReadBuffer(device.position, CL_FALSE, 0, n * 16, position.data());
    cl.queue().enqueueReadBuffer(device.normal_radiance, CL_TRUE, 0, n * 16, nr.data());
    const VplBuffer& host = renderer.vpls();
    const GBuffer& g = renderer.gbuffer();
    std::size_t valid = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t info = shared::pg_vpl_info(host.normal_radiance[i]);
      if ((info & PG_VPL_VALID) == 0u) {
        ASSERT_EQ(shared::pg_vpl_info(nr[i]), 0u) << i;
        continue;
      }
      ++valid;
      ASSERT_EQ(shared::pg_vpl_info(nr[i]), info) << i;
      const glm::vec3 y(host.position[i]);
      const float reach =
          (info & PG_VPL_DISTANT) != 0u ? 1.0f : glm::length(y - glm::vec3(g.position_depth[i]));
      // The device's pixel point is the host's within 4e-6 of its depth (GBufferPacker.
      // DerivedChannelsAreTheRenderersOwn).
      ASSERT_LT(glm::length(glm::vec3(position[i]) - y),
                1e-4f * reach + 8e-6f * g.position_depth[i].w)
          << i;
      const float cos_y =
          (info & PG_VPL_DISTANT) != 0u
              ? 1.0f
              : std::fabs(glm::dot(shared::pg_vpl_normal(host.normal_radiance[i]),
                                   glm::normalize(y - glm::vec3(g.position_depth[i]))));
      const float bound = 1e-3f + PG_OCTAHEDRAL8_MAX_ANGLE / std::max(cos_y, 0.02f);
      ASSERT_NEAR(position[i].w / host.position[i].w, 1.0f, bound) << i;
      ASSERT_NEAR(shared::pg_vpl_mixture_density(nr[i]) /
                      shared::pg_vpl_mixture_density(host.normal_radiance[i]),
                  1.0f, bound)
          << i;
      const glm::vec3 l = shared::pg_vpl_radiance(nr[i]),
                      l0 = shared::pg_vpl_radiance(host.normal_radiance[i]);
      const float brightest = std::max(l0.x, std::max(l0.y, l0.z));
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(l[c], l0[c], std::ldexp(brightest, -7)) << i;
    }
    EXPECT_GT(valid, n / 3);
  }
}

// Training left running on the device while the host makes the next frame's camera rays and
// G-buffer (Overlap::on, the default where the device has memory of its own) changes only
// when the host waits for it: with every host transfer, along a moving camera at 2 spp and an odd
// size, the image and the trained state are those of training waited for, to the bit, and each
// frame reports the previous frame's training (its trained share, its kernel time, the wait).
TEST(GuidingImage, TrainingOverlappedGivesTheSameImage) {
  ClRuntime cl;
  const Scene scene = load_scene(scene_file("cornell-box.json"));
  const RenderSettings settings = odd_size_along_camera_path(scene);
  constexpr int kFrames = 5;
  for (HostTransfer transfer : {HostTransfer::in_place, HostTransfer::pinned,
                                HostTransfer::pageable, HostTransfer::packed}) {
    SCOPED_TRACE(host_transfer_name(transfer));
    std::vector<glm::vec3> image[2];
    std::vector<float> state[2];
    std::vector<FrameStats> stats[2];
    for (int overlapped = 0; overlapped < 2; ++overlapped) {
      Renderer renderer(scene, settings);
      auto guided = std::make_unique<GuidedFirstBounce>(cl, settings.width, settings.height,
                                                        GuidingSettings{}, transfer,
                                                        overlapped ? Overlap::on : Overlap::off);
      GuidedFirstBounce* sampler = guided.get();
      EXPECT_EQ(sampler->overlaps_training(), overlapped == 1);
      renderer.set_first_bounce_sampler(std::move(guided));
      for (int f = 0; f < kFrames; ++f) stats[overlapped].push_back(renderer.render_frame(f));
      EXPECT_EQ(sampler->guider().training_pending(), overlapped == 1);
      image[overlapped] = renderer.image();
      sampler->guider().read_state(state[overlapped]);  // after the last frame's training
    }
    EXPECT_EQ(pixels_that_differ(image[0], image[1]), 0u) << "of " << image[0].size() << " pixels";
    EXPECT_EQ(state[0], state[1]);
    for (int f = 0; f < kFrames; ++f) {
      SCOPED_TRACE("frame " + std::to_string(f));
      const FrameStats &waited = stats[0][f], &overlapped = stats[1][f];
      EXPECT_EQ(waited.extra.at("train_overlap"), 0.0);
      EXPECT_EQ(overlapped.extra.at("train_overlap"), 1.0);
      EXPECT_EQ(waited.time_ms.count("train_wait"), 0u);
      ASSERT_EQ(overlapped.time_ms.count("train_wait"), 1u);
      EXPECT_GE(overlapped.time_ms.at("train_wait"), 0.0);
      const double trained_before = f > 0 ? stats[0][f - 1].extra.at("trained_fraction") : 0.0;
      EXPECT_EQ(overlapped.extra.at("trained_fraction"), trained_before);
      EXPECT_EQ(overlapped.time_ms.at("train") > 0.0, f > 0);
      // The count records of frame 0's training are read in frame 1.
      if (f > 0)
        EXPECT_DOUBLE_EQ(overlapped.extra.at("host_device_bytes_per_pixel"),
                         waited.extra.at("host_device_bytes_per_pixel"));
      else
        EXPECT_LT(overlapped.extra.at("host_device_bytes_per_pixel"),
                  waited.extra.at("host_device_bytes_per_pixel"));
    }
  }
  EXPECT_THROW(parse_overlap("sometimes"), GuiderError);
  EXPECT_EQ(parse_overlap("auto"), Overlap::automatic);
}

// The G-buffer's upload, reproject and sample left running on the device while the host makes
// the primary hit's light samples (Overlap::on for sampling; off by default everywhere, docs/
// guiding.md, "The bus and the sampling's overlap on an H200") change nothing but the order of
// the work: with every host transfer, with
// the training waited for and overlapped, along a moving camera at 2 spp and an odd size, the
// image, the state and the statistics are those of sampling waited for, to the bit. So they are
// where the host reads the mixture (later vertices borrowing it) and where next-event
// estimation needs its density (FirstBounceMis::mixture: the renderer then calls sample()).
TEST(GuidingImage, SamplingOverlappedGivesTheSameImage) {
  ClRuntime cl;
  const Scene scene = load_scene(scene_file("cornell-box.json"));
  constexpr int kFrames = 4;
  struct Case {
    HostTransfer transfer;
    Overlap training;
    bool borrow, mixture_mis;
  };
  const Case cases[] = {
      {HostTransfer::in_place, Overlap::off, false, false},
      {HostTransfer::in_place, Overlap::on, false, false},
      {HostTransfer::pinned, Overlap::on, false, false},
      {HostTransfer::pageable, Overlap::off, false, false},
      {HostTransfer::packed, Overlap::on, false, false},
      {HostTransfer::packed, Overlap::off, true, false},
      {HostTransfer::in_place, Overlap::on, false, true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(host_transfer_name(c.transfer)) +
                 (c.training == Overlap::on ? ", training overlapped" : "") +
                 (c.borrow ? ", later vertices borrow" : "") +
                 (c.mixture_mis ? ", mixture MIS" : ""));
    RenderSettings settings = odd_size_along_camera_path(scene);
    settings.path_tracer.guide_secondary = c.borrow;
    if (c.mixture_mis) settings.path_tracer.first_bounce_mis = FirstBounceMis::mixture;
    std::vector<glm::vec3> image[2];
    std::vector<float> state[2];
    std::vector<FrameStats> stats[2];
    for (int overlapped = 0; overlapped < 2; ++overlapped) {
      Renderer renderer(scene, settings);
      auto guided = std::make_unique<GuidedFirstBounce>(cl, settings.width, settings.height,
                                                        GuidingSettings{}, c.transfer, c.training,
                                                        overlapped ? Overlap::on : Overlap::off);
      GuidedFirstBounce* sampler = guided.get();
      EXPECT_EQ(sampler->samples_beside_the_host(), overlapped == 1);
      renderer.set_first_bounce_sampler(std::move(guided));
      for (int f = 0; f < kFrames; ++f) stats[overlapped].push_back(renderer.render_frame(f));
      image[overlapped] = renderer.image();
      sampler->guider().wait_for_training();
      sampler->guider().read_state(state[overlapped]);
    }
    EXPECT_EQ(pixels_that_differ(image[0], image[1]), 0u) << "of " << image[0].size() << " pixels";
    EXPECT_EQ(state[0], state[1]);
    for (int f = 0; f < kFrames; ++f) {
      SCOPED_TRACE("frame " + std::to_string(f));
      const FrameStats &waited = stats[0][f], &overlapped = stats[1][f];
      EXPECT_EQ(waited.extra.at("sample_overlap"), 0.0);
      EXPECT_EQ(overlapped.extra.at("sample_overlap"), 1.0);
      for (const char* name :
           {"guided_fraction", "trained_fraction", "mean_pi", "host_device_bytes_per_pixel"})
        EXPECT_EQ(overlapped.extra.at(name), waited.extra.at(name)) << name;
      EXPECT_EQ(overlapped.shadow_rays, waited.shadow_rays);
      EXPECT_EQ(overlapped.secondary_rays, waited.secondary_rays);
      // Every kernel's time is recorded, whenever the host waited for it.
      EXPECT_EQ(overlapped.time_ms.at("reproject") > 0.0, f > 0);
      EXPECT_GT(overlapped.time_ms.at("sample"), 0.0);
      EXPECT_EQ(overlapped.time_ms.at("train") > 0.0, c.training == Overlap::off || f > 0);
    }
  }
  EXPECT_EQ(parse_overlap("off"), Overlap::off);
}

// A renderer destroyed right after a frame whose training it left running (Overlap::on)
// waits for that training before its host buffers go: read in place, the train kernel reads the
// renderer's VPL and G-buffer memory, which large images allocate by mmap and free by munmap.
TEST(GuidingImage, RendererDestroyedWhileTrainingRuns) {
  ClRuntime cl;
  const Scene scene = load_scene(scene_file("cornell-box.json"));
  RenderSettings settings;
  settings.width = 480;
  settings.height = 270;
  for (HostTransfer transfer : {HostTransfer::in_place, HostTransfer::pageable}) {
    for (int run = 0; run < 8; ++run) {
      Renderer renderer(scene, settings);
      auto guided = std::make_unique<GuidedFirstBounce>(cl, settings.width, settings.height,
                                                        GuidingSettings{}, transfer, Overlap::on);
      GuidedFirstBounce* sampler = guided.get();
      renderer.set_first_bounce_sampler(std::move(guided));
      renderer.render_frame(0);
      renderer.render_frame(1);
      ASSERT_TRUE(sampler->guider().training_pending());
    }
  }
}

// Every guiding setting at a value away from its default still trains and guides: the Cornell
// box at 48x27, six frames, each row of guiding_settings_table() changed alone (the work-group
// size in both directions at once). A setting whose value silently stopped all training went
// unseen before: --pg-weight-clamp did (docs/guiding.md, "The history weight of later E-step
// passes"). A row added to the table without a value here fails the test.
TEST(GuidingImage, EverySettingAwayFromItsDefaultStillGuides) {
  const Scene scene = load_scene(scene_file("cornell-box.json"));
  ClRuntime cl;
  const std::map<std::string, double> values = {{"pi_min", 0.1},
                                                {"pi_max", 0.9},
                                                {"pi_init", 0.2},
                                                {"k_max", 8},
                                                {"step_alpha", 0.7},
                                                {"sigma_eps", 1e-3},
                                                {"sigma_prior", 0.2},
                                                {"reseed_ratio", 3},
                                                {"reseed_samples", 1},
                                                {"weight_clamp", 3},
                                                {"em_passes", 5},
                                                {"max_correlation", 0.5},
                                                {"roughness_skip", 0.5},
                                                {"n_min", 10},
                                                {"n_max", 10},
                                                {"apron", 1},
                                                {"max_weight", 10},
                                                {"reproject_position", 0.5},
                                                {"reproject_normal", 0.5},
                                                {"reproject_view_memory", 2},
                                                {"train_interval", 4},
                                                {"rows_per_model", 2},
                                                {"train_all_samples", 0},
                                                {"pi_learning", 1},
                                                {"local_x", 8},
                                                {"local_y", 8},
                                                {"train_lanes", 4},
                                                {"sample_lanes", 1}};
  RenderSettings settings;
  settings.width = 48;
  settings.height = 27;
  // Along the pan: with a still camera every motion is 0 and the settings that act on moving
  // pixels (reproject_view_memory) would not act at all.
  settings.camera_path = "pan";
  for (const GuidingSettingInfo& row : guiding_settings_table()) {
    SCOPED_TRACE(row.name);
    const auto it = values.find(row.name);
    ASSERT_NE(it, values.end()) << "no value away from the default for this setting";
    GuidingSettings guiding;
    ASSERT_NE(row.get(guiding), it->second);
    row.set(guiding, it->second);
    if (std::string(row.name) == "local_x") guiding.local_y = 8;
    if (std::string(row.name) == "local_y") guiding.local_x = 8;
    Renderer renderer(scene, settings);
    renderer.set_first_bounce_sampler(
        std::make_unique<GuidedFirstBounce>(cl, settings.width, settings.height, guiding));
    FrameStats stats;
    for (int f = 0; f < 6; ++f) stats = renderer.render_frame(f);
    EXPECT_GT(stats.extra.at("trained_fraction"), 0.25);
    EXPECT_GT(stats.extra.at("guided_fraction"), 0.5);
    EXPECT_GT(stats.extra.at("mean_pi"), 0.0);
    EXPECT_EQ(stats.nonfinite_samples, 0u);
  }
}

// In place, last frame's G-buffer is what reprojection compares with, so a caller writing the
// same G-buffer every frame would leave none to compare with: the guided first bounce says so.
TEST(GuidingImage, InPlaceRefusesTheSameGBufferTwoFramesRunning) {
  ClRuntime cl;
  // In place by choice, on any device (where it does not share host memory the OpenCL
  // implementation copies, but the host's G-buffers are still wrapped and must alternate).
  GuidedFirstBounce guided(cl, 8, 4, GuidingSettings{}, HostTransfer::in_place);
  ASSERT_TRUE(guided.reads_gbuffers_in_place());
  GBuffer gbuffers[2];
  for (GBuffer& g : gbuffers) g.resize(8, 4);
  VplBuffer vpls;
  vpls.resize(32);
  guided.begin_frame(gbuffers[0], {1, 0, 0});
  guided.end_frame(gbuffers[0], vpls, {1, 0, 0});
  guided.begin_frame(gbuffers[1], {1, 1, 0});
  guided.end_frame(gbuffers[1], vpls, {1, 1, 0});
  EXPECT_THROW(guided.begin_frame(gbuffers[1], {1, 2, 0}), GuiderError);
}

// cornell-indirect with one indirect bounce (max_bounces 2, the budget first-bounce guiding
// targets), 128x128, fixed seed, 32 frames at 1 spp; the mean relMSE of the last 8 frames with
// guiding is at most half that without (0.21 measured), against a 1024-spp reference rendered
// here. At the scene's full depth (8 bounces) the equal-frame ratio is 0.97, not significant
// (docs/results/equal-frame-2026-11-23/): that gain is not there to guard yet.
// A path-traced reference of the scene with `settings` (size, bounces): 256 frames of
// spp_per_frame samples from seed 1000, averaged (the camera is static).
ImageRgb reference_image(const Scene& scene, const RenderSettings& settings, int spp_per_frame) {
  ImageRgb reference{settings.width, settings.height,
                     std::vector<glm::vec3>(static_cast<std::size_t>(settings.width) *
                                                static_cast<std::size_t>(settings.height),
                                            glm::vec3(0.0f))};
  RenderSettings ref_settings = settings;
  ref_settings.seed = 1000;
  ref_settings.spp = spp_per_frame;
  Renderer renderer(scene, ref_settings);
  const int passes = 256;
  for (int p = 0; p < passes; ++p) {
    renderer.render_frame(p);
    for (std::size_t i = 0; i < reference.pixels.size(); ++i)
      reference.pixels[i] += renderer.image()[i] / float(passes);
  }
  return reference;
}

TEST(GuidingImage, HalvesErrorOnCornellIndirect) {
  const Scene scene = load_scene(scene_file("cornell-indirect.json"));
  ClRuntime cl;
  const int size = 128;
  RenderSettings settings;
  settings.width = settings.height = size;
  settings.path_tracer.max_bounces = 2;

  const ImageRgb reference = reference_image(scene, settings, 4);  // 1024 spp
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
  EXPECT_LE(error[1], 0.5 * error[0]) << "PT " << error[0] << ", guided " << error[1];
  std::printf(
      "cornell-indirect 128x128, last 8 of 32 frames: relMSE PT %.4f, guided %.4f (ratio %.3f)\n",
      error[0], error[1], error[1] / error[0]);
}

// The gain guiding is built for, at a scene's full depth: the part of a 1-spp pixel's error that
// comes from the first bounce's direction (docs/guiding.md, "Where the variance is";
// bench/variance_split.py). With the first bounce shared by a frame's 8 samples
// (SharedRandoms::first_bounce) the error keeps that part whole and an eighth of the rest; with
// nothing shared, an eighth of both; their difference over 7/8 is the first bounce's part alone,
// free of the later bounces' noise that makes the whole error's ratio hard to test at a small size
// (at full depth the later bounces carry half the Cornell box's error and nearly all of
// cornell-indirect's). Returns guided / path-traced, 64x64, frames 32-47, against a 4096-spp
// reference.
double first_bounce_error_ratio(const char* name) {
  const Scene scene = load_scene(scene_file(name));
  ClRuntime cl;
  const int size = 64, spp = 8, frames = 48, window = 16;
  RenderSettings settings;
  settings.width = settings.height = size;
  settings.spp = spp;
  settings.path_tracer.max_bounces = scene.max_bounces > 0 ? scene.max_bounces : 8;

  const ImageRgb reference = reference_image(scene, settings, 16);  // 4096 spp
  // relMSE of the last `window` frames, guided or not, with or without the first bounce shared.
  auto error = [&](bool guided, SharedRandoms shared) {
    RenderSettings s = settings;
    s.path_tracer.shared_randoms = shared;
    Renderer renderer(scene, s);
    if (guided)
      renderer.set_first_bounce_sampler(
          std::make_unique<GuidedFirstBounce>(cl, size, size, GuidingSettings{}));
    double sum = 0.0;
    for (int f = 0; f < frames; ++f) {
      renderer.render_frame(f);
      if (f >= frames - window)
        sum += relative_mse(ImageRgb{size, size, renderer.image()}, reference);
    }
    return sum / window;
  };
  const double k = 1.0 - 1.0 / spp;
  double first_bounce[2];
  for (int guided = 0; guided < 2; ++guided)
    first_bounce[guided] =
        (error(guided, SharedRandoms::first_bounce) - error(guided, SharedRandoms::none)) / k;
  const double ratio = first_bounce[1] / first_bounce[0];
  ::testing::Test::RecordProperty("first_bounce_pt", std::to_string(first_bounce[0]));
  ::testing::Test::RecordProperty("first_bounce_pg", std::to_string(first_bounce[1]));
  std::printf(
      "%s 64x64, 8 spp, last %d of %d frames: first bounce's relMSE PT %.4f, guided %.4f "
      "(ratio %.3f)\n",
      name, window, frames, first_bounce[0], first_bounce[1], ratio);
  EXPECT_GT(first_bounce[0], 0.0) << name;
  return ratio;
}

// Guiding takes at least 15% of the first bounce's error on the Cornell box at 8 bounces.
// Measured 0.680 (seed 0; 0.651 and 0.666 at seeds 5 and 9 in trial builds): the bound is about
// twelve spreads away, and a sampler that stops guiding gives 1. At 240x135 over seeds 1-3 the
// ratio is 0.70 (0.496 -> 0.349 of PT's whole error).
TEST(GuidingImage, CutsTheFirstBouncesErrorOnCornellBoxAtFullDepth) {
  EXPECT_LE(first_bounce_error_ratio("cornell-box.json"), 0.85);
}

// The strongly indirect scene at its full depth (8 bounces), where the whole error does not move
// (the path beyond the first bounce's hit carries 0.88 of it): guiding still takes at least 30% of
// the first bounce's part. Measured 0.424 (seed 0; 0.347 and 0.281 at seeds 5 and 9 in trial
// builds; 0.31 at 240x135 over seeds 1-3).
TEST(GuidingImage, CutsTheFirstBouncesErrorOnCornellIndirectAtFullDepth) {
  EXPECT_LE(first_bounce_error_ratio("cornell-indirect.json"), 0.7);
}

}  // namespace
}  // namespace rtpg

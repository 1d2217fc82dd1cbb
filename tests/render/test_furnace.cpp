// White furnace: the camera sits at the centre of a closed sphere seen from inside, every
// point of which is a Lambertian reflector of albedo a emitting Le. The radiance is then the
// same everywhere and in every direction, L = Le + a L, so L = Le / (1 - a). A renderer that
// keeps at most B path vertices after the primary hit sums the first B + 1 terms of that
// series exactly: L_B = Le (1 - a^(B+1)) / (1 - a). The tests use L_B as the expectation (with
// B large it differs from Le / (1 - a) by under 0.1%; with B small it checks that max_bounces
// means what it says). Russian roulette stays on: it is unbiased, so it changes only the noise.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "render/renderer.h"
#include "scene/scene_loader.h"
#include "support/statistics.h"
#include "support/test_env.h"

namespace rtpg {
namespace {

constexpr float kEmission = 0.5f;

// The icosphere has flat facets with smooth shading normals. At 5 subdivisions the facet
// normals and the shading normals differ by at most about 1 degree (delta ~ 0.017 rad);
// cosine-weighted directions between the two tangent planes are dropped, a fraction of
// about delta^2 / 4 < 1e-4 per bounce, so below 1e-3 of L over the a / (1 - a) <= 4 expected
// bounces. kFacetAllowance covers that systematic loss in the per-pixel bound.
constexpr int kSubdivisions = 5;
constexpr double kFacetAllowance = 1e-3;

struct FurnaceCase {
  float albedo;
  bool next_event;
  int max_bounces;
  int spp_per_frame;
  int frames;
};

void PrintTo(const FurnaceCase& c, std::ostream* os) {
  *os << "albedo " << c.albedo << (c.next_event ? ", NEE+MIS" : ", BSDF only") << ", max_bounces "
      << c.max_bounces << ", " << c.spp_per_frame << " spp x " << c.frames << " frames";
}

std::string case_name(const ::testing::TestParamInfo<FurnaceCase>& info) {
  return fmt::format("albedo{}_{}_bounces{}", static_cast<int>(info.param.albedo * 100.0f + 0.5f),
                     info.param.next_event ? "nee" : "bsdf", info.param.max_bounces);
}

std::string furnace_scene_json(float albedo) {
  return fmt::format(R"({{
  "camera": {{"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov": 90}},
  "materials": {{"furnace": {{"base_color": [{0}, {0}, {0}], "specular": 0,
                             "emission": [{1}, {1}, {1}]}}}},
  "shapes": [{{"type": "sphere", "center": [0, 0, 0], "radius": 1, "subdivisions": {2},
              "inward": true, "material": "furnace"}}]
}})",
                     albedo, kEmission, kSubdivisions);
}

// Sum of the first max_bounces + 1 terms of Le * sum_k a^k.
double expected_radiance(float albedo, int max_bounces) {
  const double a = albedo;
  return kEmission * (1.0 - std::pow(a, max_bounces + 1)) / (1.0 - a);
}

// The furnace's checks on one render. The scene is built with albedo * albedo_factor and judged
// against the radiance of albedo: a factor other than 1 is a deliberately biased BSDF.
struct FurnaceVerdict {
  bool mean_ok = true;  // the image mean within 1% of the closed form
  int outliers = 0;     // pixels beyond their bound
  double image_mean = 0.0, expected = 0.0;
};

FurnaceVerdict run_furnace(const FurnaceCase& c, float albedo_factor) {
  FurnaceVerdict verdict;
  test::TempDir dir;
  const std::string scene_path = (dir.path() / "furnace.json").string();
  std::ofstream(scene_path) << furnace_scene_json(c.albedo * albedo_factor);
  const Scene scene = load_scene(scene_path);

  RenderSettings settings;
  settings.width = 16;
  settings.height = 16;
  settings.spp = c.spp_per_frame;
  settings.seed = 1234;
  settings.path_tracer.max_bounces = c.max_bounces;
  settings.path_tracer.next_event = c.next_event;
  Renderer renderer(scene, settings);

  // Frames are independent (the frame index is part of every random stream): per pixel the
  // frame values are i.i.d., each the mean of spp_per_frame path samples.
  const std::size_t pixel_count = static_cast<std::size_t>(settings.width) * settings.height;
  std::vector<test::RunningMoments> pixels(pixel_count);
  for (int f = 0; f < c.frames; ++f) {
    const FrameStats stats = renderer.render_frame(f);
    EXPECT_EQ(stats.nonfinite_samples, 0u);
    const auto& image = renderer.image();
    for (std::size_t i = 0; i < pixel_count; ++i) {
      // Grey albedo and emission: every channel follows the same path with the same weight.
      EXPECT_EQ(image[i].x, image[i].y);
      EXPECT_EQ(image[i].x, image[i].z);
      pixels[i].add(image[i].x);
    }
  }

  const double expected = expected_radiance(c.albedo, c.max_bounces);
  // By symmetry every pixel's estimator has the same distribution, so the frame-to-frame
  // variance pooled over all pixels (pixel_count * (frames - 1) degrees of freedom, here over
  // a thousand) estimates it to a few per cent, and the image mean's standard error is the
  // per-pixel one over sqrt(pixel_count).
  double pooled_m2 = 0.0, image_mean = 0.0;
  for (const auto& p : pixels) {
    pooled_m2 += p.m2;
    image_mean += p.mean;
  }
  image_mean /= static_cast<double>(pixel_count);
  const double frame_variance = pooled_m2 / static_cast<double>(pixel_count * (c.frames - 1));
  const double pixel_standard_error = std::sqrt(frame_variance / c.frames);
  const double image_standard_error = pixel_standard_error / std::sqrt(double(pixel_count));

  // The 1% criterion is about bias; the noise must be well inside it to make it meaningful.
  EXPECT_LT(image_standard_error, 0.002 * expected);
  verdict.image_mean = image_mean;
  verdict.expected = expected;
  verdict.mean_ok = std::fabs(image_mean - expected) <= 0.01 * expected;

  // Each pixel mean averages frames * spp_per_frame light-tailed samples (roulette keeps the
  // path weights bounded), so it is normal to a good approximation. Overall false-alarm rate
  // 1e-3 over all pixels with the Sidak correction: z ~ 4.6 standard errors per pixel.
  const double per_pixel_alpha = 1.0 - std::pow(1.0 - 1e-3, 1.0 / double(pixel_count));
  const double z = test::normal_two_sided_quantile(per_pixel_alpha);
  const double bound = z * pixel_standard_error + kFacetAllowance * expected;
  EXPECT_LT(pixel_standard_error, 0.03 * expected);
  int outliers = 0;
  for (std::size_t i = 0; i < pixel_count; ++i) {
    if (std::fabs(pixels[i].mean - expected) > bound) {
      if (++outliers <= 5 && albedo_factor == 1.0f)
        ADD_FAILURE() << "pixel " << i << ": " << pixels[i].mean << ", expected " << expected
                      << " +- " << bound;
    }
  }
  verdict.outliers = outliers;
  if (albedo_factor == 1.0f) {
    EXPECT_EQ(outliers, 0) << "bound " << bound << " (z " << z << ", standard error "
                           << pixel_standard_error << ")";
  }
  return verdict;
}

class WhiteFurnace : public ::testing::TestWithParam<FurnaceCase> {};

TEST_P(WhiteFurnace, EveryPixelSeesTheClosedFormRadiance) {
  const FurnaceVerdict v = run_furnace(GetParam(), 1.0f);
  EXPECT_TRUE(v.mean_ok) << "image mean " << v.image_mean
                         << ", expected Le (1 - a^(B+1)) / (1 - a) = " << v.expected;
}

// Power: a BSDF reflecting 0.5% too much (albedo 0.804 for 0.8, 2% more radiance after the
// bounces) fails the image-mean check, with NEE+MIS and with BSDF sampling alone.
TEST(WhiteFurnaceDetection, AnAlbedoHalfAPercentTooHighIsRejected) {
  for (bool next_event : {true, false}) {
    const FurnaceVerdict v = run_furnace(FurnaceCase{0.8f, next_event, 31, 64, 16}, 1.005f);
    EXPECT_FALSE(v.mean_ok) << (next_event ? "NEE+MIS" : "BSDF only") << ": image mean "
                            << v.image_mean << " passed as " << v.expected;
  }
}

// Enough bounces that the dropped tail a^(B+1) / (1 - a) is below 0.1% of Le / (1 - a):
// B = 10 for a = 0.5 (0.5^11 = 4.9e-4), B = 31 for a = 0.8 (0.8^32 = 7.9e-4).
INSTANTIATE_TEST_SUITE_P(Converged, WhiteFurnace,
                         ::testing::Values(FurnaceCase{0.5f, true, 10, 64, 16},
                                           FurnaceCase{0.5f, false, 10, 64, 16},
                                           FurnaceCase{0.8f, true, 31, 64, 16},
                                           FurnaceCase{0.8f, false, 31, 64, 16}),
                         case_name);

// B = 4 with roulette from depth 3: the expectation 1 + a + ... + a^4 = 3.36 Le (a = 0.8) is
// a third below the untruncated 5 Le, so an off-by-one in max_bounces or in where roulette
// ends a path fails this by far more than the bounds.
INSTANTIATE_TEST_SUITE_P(Truncated, WhiteFurnace,
                         ::testing::Values(FurnaceCase{0.8f, true, 4, 64, 16},
                                           FurnaceCase{0.8f, false, 4, 64, 16}),
                         case_name);

}  // namespace
}  // namespace rtpg

// Light transport is linear in the emitted radiance, so the same scene with every emitter (the
// materials' emission, the sky and the sun) scaled by s must give s times the image, with and
// without guiding, and a guide whose statistics are s times as large but whose model is the same
// (docs/robustness.md, "Radiance scale"). Scenes come in any unit (a physical sun is 1.5e9
// W / (sr m^2), a dim room lit in lux 1e-3): a constant in the renderer, the guide or the
// denoiser that compares radiance with an absolute number breaks this. At a power of two every
// product with s is exact in floats (below overflow and above the denormals), so the check is
// bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "denoise/svgf_denoiser.h"
#include "render/guided_first_bounce.h"
#include "render/renderer.h"
#include "rtpg/cl_runtime.h"
#include "rtpg/guiding_layout.h"
#include "scene/scene_loader.h"

namespace rtpg {
namespace {

Scene with_emission_scaled(Scene scene, float s) {
  for (Material& m : scene.materials) m.emission *= s;
  scene.environment.color *= s;
  scene.sun.irradiance *= s;
  return scene;
}

struct Renders {
  std::vector<std::vector<glm::vec3>> frames;    // the renderer's image after each frame
  std::vector<std::vector<glm::vec3>> denoised;  // the denoiser's output after each frame
  std::vector<float> state;                      // the guide's state after the last frame
  std::vector<double> world;                     // the world guide's cells and mean pi
};

constexpr int kWidth = 40, kHeight = 28, kFrames = 6;

Renders render(const Scene& scene, bool guided, bool world, ClRuntime& cl) {
  RenderSettings settings;
  settings.width = kWidth;
  settings.height = kHeight;
  settings.camera_path = "pan";
  settings.seed = 3u;
  settings.spp = 2;
  settings.path_tracer.max_bounces = scene.max_bounces > 0 ? scene.max_bounces : 8;
  settings.world_guide = world;
  settings.world_guide_settings.em = to_kernel_settings(GuidingSettings{});
  Renderer renderer(scene, settings);
  if (guided)
    renderer.set_first_bounce_sampler(
        std::make_unique<GuidedFirstBounce>(cl, kWidth, kHeight, GuidingSettings{}));
  SvgfDenoiser denoiser(cl, kWidth, kHeight);
  Renders run;
  for (int f = 0; f < kFrames; ++f) {
    const FrameStats stats = renderer.render_frame(f);
    run.frames.push_back(renderer.image());
    run.denoised.push_back(denoiser.denoise(renderer.image(), renderer.gbuffer()));
    if (world && f + 1 == kFrames)
      run.world = {stats.extra.at("world_cells"), stats.extra.at("world_mean_pi"),
                   stats.extra.at("world_at_pi_min")};
  }
  if (guided)
    static_cast<GuidedFirstBounce&>(renderer.first_bounce_sampler()).guider().read_state(run.state);
  return run;
}

// Every pixel of b is s times a's, to the bit; reports the first few that are not. Values whose
// product lies below 2^-100 are 0 for any purpose and are only held to that bound: the
// denoiser's exponential weights leave tails near 1e-36 that the smaller scale takes below
// float's normal range, where scaling is no longer exact.
void expect_scaled(const std::vector<std::vector<glm::vec3>>& a,
                   const std::vector<std::vector<glm::vec3>>& b, float s, const std::string& what) {
  ASSERT_EQ(a.size(), b.size());
  int reported = 0;
  for (std::size_t f = 0; f < a.size(); ++f)
    for (std::size_t i = 0; i < a[f].size(); ++i)
      for (int c = 0; c < 3; ++c) {
        const double want = static_cast<double>(a[f][i][c]) * s, got = b[f][i][c];
        const bool same = std::fabs(want) < 0x1p-100 ? std::fabs(got - want) <= 0x1p-100
                                                     : got == static_cast<float>(want);
        if (!same && reported++ < 5) {
          ADD_FAILURE() << what << ", frame " << f << ", pixel " << i << ", channel " << c << ": "
                        << got << " against " << a[f][i][c] << " x " << s;
        }
      }
}

struct RadianceCase {
  const char* scene;
  float scale;
  bool guided;
  bool world;
  const char* name;
};

void PrintTo(const RadianceCase& c, std::ostream* os) {
  *os << c.name;
}

class RadianceScale : public ::testing::TestWithParam<RadianceCase> {};

TEST_P(RadianceScale, ScalesTheImageTheGuideAndTheDenoisedImage) {
  const RadianceCase c = GetParam();
  const Scene scene = load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/" + c.scene);
  ClRuntime cl;
  const Renders base = render(scene, c.guided, c.world, cl);
  const Renders scaled = render(with_emission_scaled(scene, c.scale), c.guided, c.world, cl);
  const std::string what = std::string(c.name);
  double sum = 0.0;
  for (const glm::vec3& p : base.frames.back()) sum += p.x + p.y + p.z;
  ASSERT_GT(sum, 0.0) << what << ": a black image tests nothing";
  expect_scaled(base.frames, scaled.frames, c.scale, what + ": image");
  // The denoiser squares the luminance: its second moments scale by s^2, and at 2^-32 those of
  // pixels whose luminance hardly varies (a variance below 2^-62 at scale 1) fall below float's
  // normal range. It is checked at 2^-16 and 2^16 too, which still resolve an absolute constant
  // (the luminance weight's old 1e-10) to the last bit.
  if (std::fabs(std::log2(c.scale)) <= 16.0f)
    expect_scaled(base.denoised, scaled.denoised, c.scale, what + ": denoised image");
  // The state's running means of the EM statistics (W, S0, Sx, Sy, Sxx, Syy, Sxy) are means of
  // weights a = lum(L f cos) / r, s times as large; the epoch count k is not a radiance.
  ASSERT_EQ(base.state.size(), scaled.state.size());
  int reported = 0, models = 0;
  for (std::size_t i = 0; i < base.state.size(); ++i) {
    const bool epoch = i % PG_STATE_FLOATS_PER_PIXEL == PG_STATE_FLOATS_PER_PIXEL - 1;
    if (epoch && base.state[i] > 0.0f) ++models;
    const float want = epoch ? base.state[i] : base.state[i] * c.scale;
    if (!(scaled.state[i] == want) && reported++ < 5) {
      ADD_FAILURE() << what << ": state float " << i << ": " << scaled.state[i] << ", want "
                    << want;
    }
  }
  if (c.guided) {
    EXPECT_GT(models, 0) << what << ": no pixel built a model";
  }
  EXPECT_EQ(base.world, scaled.world) << what << ": the world guide's cells and mixing weights";
}

// 2^-32 and 2^32 (2^-16 and 2^16 for the denoiser) span the units scenes come in (radiance 1e-3 in
// a dim room in lux to the sun's 1.5e9 in W / (sr m^2)) from the suite's scenes, whose lights are
// near 1-20: the Cornell box (an area light) and the sunlit room (a sun and a constant sky).
INSTANTIATE_TEST_SUITE_P(
    Scales, RadianceScale,
    ::testing::Values(
        RadianceCase{"cornell-box.json", 0x1p-32f, false, false, "CornellTwoToMinus32PT"},
        RadianceCase{"cornell-box.json", 0x1p32f, false, false, "CornellTwoTo32PT"},
        RadianceCase{"cornell-box.json", 0x1p-32f, true, false, "CornellTwoToMinus32PG"},
        RadianceCase{"cornell-box.json", 0x1p32f, true, false, "CornellTwoTo32PG"},
        RadianceCase{"cornell-box.json", 0x1p-32f, true, true, "CornellTwoToMinus32World"},
        RadianceCase{"cornell-box.json", 0x1p32f, true, true, "CornellTwoTo32World"},
        RadianceCase{"cornell-box.json", 0x1p-16f, true, true, "CornellTwoToMinus16World"},
        RadianceCase{"cornell-box.json", 0x1p16f, true, false, "CornellTwoTo16PG"},
        RadianceCase{"sunlit-room.json", 0x1p-16f, true, false, "SunlitRoomTwoToMinus16PG"},
        RadianceCase{"sunlit-room.json", 0x1p-32f, true, false, "SunlitRoomTwoToMinus32PG"},
        RadianceCase{"sunlit-room.json", 0x1p32f, true, false, "SunlitRoomTwoTo32PG"}),
    [](const ::testing::TestParamInfo<RadianceCase>& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace rtpg

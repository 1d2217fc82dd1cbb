// Radiance extremes and long runs with guiding on (issue: robustness; docs/robustness.md,
// "Numerical stress"): a tiny light of emission 1e6, albedo exactly 1, a black scene, and
// 10,000 frames with a moving camera. Every pixel stays finite and non-negative, and every
// pixel's guiding state stays finite, bounded and, where a model exists, positive definite.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "render/guided_first_bounce.h"
#include "render/renderer.h"
#include "rtpg/cl_runtime.h"
#include "rtpg/guiding_layout.h"
#include "rtpg/guiding_settings.h"
#include "scene/scene_loader.h"
#include "shared/pmm.h"
#include "support/pmm_checks.h"
#include "support/scene_edits.h"

namespace rtpg {
namespace {

Scene cornell_box() {
  return load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
}

// The state's bounds: W = E[a] >= S0 = E[a gamma] >= 0 (gamma in [0, 1]), the first and
// second moments of points of the unit square at most S0, k in [0, k_max]; and the model of
// a state with k > 0 exists and is sane.
::testing::AssertionResult state_is_bounded(const std::vector<float>& state,
                                            const pg_kernel_settings& p) {
  for (std::size_t i = 0; i + PG_STATE_FLOATS_PER_PIXEL <= state.size();
       i += PG_STATE_FLOATS_PER_PIXEL) {
    shared::pg_pmm_state s;
    s.s0 = shared::float4(state[i], state[i + 1], state[i + 2], state[i + 3]);
    s.s1 = shared::float4(state[i + 4], state[i + 5], state[i + 6], state[i + 7]);
    const std::size_t pixel = i / PG_STATE_FLOATS_PER_PIXEL;
    if (!shared::pg_pmm_state_finite(s))
      return ::testing::AssertionFailure() << "pixel " << pixel << ": state not finite";
    const float slack = 1e-4f * s.s0.y;  // rounding of the running averages
    if (!(s.s0.x >= 0.0f && s.s0.y >= 0.0f && s.s0.y <= s.s0.x * (1.0f + 1e-4f) &&
          s.s0.z >= -slack && s.s0.z <= s.s0.y + slack && s.s0.w >= -slack &&
          s.s0.w <= s.s0.y + slack && s.s1.x >= -slack && s.s1.x <= s.s0.y + slack &&
          s.s1.y >= -slack && s.s1.y <= s.s0.y + slack && std::fabs(s.s1.z) <= s.s0.y + slack &&
          s.s1.w >= 0.0f && s.s1.w <= p.k_max))
      return ::testing::AssertionFailure()
             << "pixel " << pixel << ": state out of bounds (" << s.s0.x << " " << s.s0.y << " "
             << s.s0.z << " " << s.s0.w << " | " << s.s1.x << " " << s.s1.y << " " << s.s1.z << " "
             << s.s1.w << ")";
    const shared::pg_pmm_model m = shared::pg_pmm_model_from_state(s, p);
    if (s.s1.w > 0.0f && !m.valid)
      return ::testing::AssertionFailure() << "pixel " << pixel << ": k > 0 but no model";
    const ::testing::AssertionResult sane = test::model_is_sane(m, p);
    if (!sane) return ::testing::AssertionFailure() << "pixel " << pixel << ": " << sane.message();
  }
  return ::testing::AssertionSuccess();
}

struct GuidedRun {
  int frames_checked = 0;
  std::size_t pixels_with_model = 0;  // after the last frame
  double image_mean = 0.0;            // of the last frame
};

// Renders `frames` guided frames at size x size; checks the image every frame and the state
// every `state_every` frames and after the last.
GuidedRun run_guided(const Scene& scene, int size, int frames, const std::string& camera_path,
                     int state_every) {
  ClRuntime cl;
  RenderSettings settings;
  settings.width = settings.height = size;
  settings.camera_path = camera_path;
  settings.path_tracer.max_bounces = 8;
  Renderer renderer(scene, settings);
  auto guided = std::make_unique<GuidedFirstBounce>(cl, size, size, GuidingSettings{});
  GuidedFirstBounce& guide = *guided;
  renderer.set_first_bounce_sampler(std::move(guided));
  const pg_kernel_settings p = to_kernel_settings(GuidingSettings{});
  GuidedRun run;
  std::vector<float> state;
  for (int f = 0; f < frames; ++f) {
    // The path tracer replaces a non-finite estimate by 0 and counts it, so the image alone
    // cannot show one: the count must stay 0.
    const std::uint64_t nonfinite = renderer.render_frame(f).nonfinite_samples;
    if (nonfinite != 0) {
      ADD_FAILURE() << "frame " << f << ": " << nonfinite << " non-finite samples";
      return run;
    }
    double sum = 0.0;
    for (const glm::vec3& c : renderer.image()) {
      if (!(c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f && std::isfinite(c.x) && std::isfinite(c.y) &&
            std::isfinite(c.z))) {
        ADD_FAILURE() << "frame " << f << ": pixel (" << c.x << ", " << c.y << ", " << c.z << ")";
        return run;
      }
      sum += c.x + c.y + c.z;
    }
    run.image_mean = sum / (3.0 * size * size);
    if ((f + 1) % state_every == 0 || f + 1 == frames) {
      guide.guider().read_state(state);
      const ::testing::AssertionResult bounded = state_is_bounded(state, p);
      if (!bounded) {
        ADD_FAILURE() << "frame " << f << ": " << bounded.message();
        return run;
      }
      ++run.frames_checked;
    }
  }
  run.pixels_with_model = 0;
  for (std::size_t i = 0; i < state.size(); i += PG_STATE_FLOATS_PER_PIXEL)
    run.pixels_with_model += state[i + 7] > 0.0f;
  return run;
}

TEST(Extremes, TinyLightOfEmissionAMillion) {
  Scene scene = cornell_box();
  test::resize_emitters(scene, 1e-3f, 1.0f);
  for (Material& material : scene.materials)
    if (material.is_emissive()) material.emission = glm::vec3(1e6f);
  const GuidedRun r = run_guided(scene, 32, 64, "", 8);
  EXPECT_EQ(r.frames_checked, 8);
  EXPECT_GT(r.pixels_with_model, 32u * 32u / 2) << "the guide should learn the small light";
}

TEST(Extremes, AlbedoExactlyOne) {
  Scene scene = cornell_box();
  for (Material& m : scene.materials) m.base_color = glm::vec3(1.0f);
  const GuidedRun r = run_guided(scene, 32, 64, "", 8);
  EXPECT_EQ(r.frames_checked, 8);
  EXPECT_GT(r.pixels_with_model, 32u * 32u / 2);
}

// Albedo 0 everywhere: every VPL is dark, so no pixel may build a model from nothing.
TEST(Extremes, BlackScene) {
  Scene scene = cornell_box();
  for (Material& m : scene.materials) m.base_color = glm::vec3(0.0f);
  const GuidedRun r = run_guided(scene, 32, 32, "", 8);
  EXPECT_EQ(r.frames_checked, 4);
  EXPECT_EQ(r.pixels_with_model, 0u);
}

// 10,000 frames at 16x16 with the camera swinging between the ends of the Cornell box's pan
// (a key every second, 333 s at 30 fps): reprojection, re-seeding and EM over a long run.
TEST(Extremes, TenThousandFramesWithAMovingCamera) {
  Scene scene = cornell_box();
  const CameraPath& pan = scene.camera.paths.at("pan");
  CameraPath swing;
  swing.fps = pan.fps;
  for (int key = 0; key <= 340; ++key) {
    swing.times.push_back(static_cast<float>(key));
    swing.views.push_back(pan.views[key % 2 == 0 ? 0 : pan.views.size() - 1]);
  }
  scene.camera.paths["swing"] = swing;
  const GuidedRun r = run_guided(scene, 16, 10000, "swing", 100);
  EXPECT_EQ(r.frames_checked, 100);
  EXPECT_GT(r.pixels_with_model, 16u * 16u / 2);
}

}  // namespace
}  // namespace rtpg

// The order in which the renderer drives a first-bounce sampler within a frame. Training
// changes the model, so it must come after the frame's last sample: samples drawn after it
// would use a model other than the one next-event MIS at the primary hit evaluates (a bias at
// more than one sample per pixel, invisible at one). And the path tracer's own draw of BSDF
// sampling at the primary hit equals the sampler's separate pass.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "render/first_bounce.h"
#include "render/renderer.h"
#include "render/vpl_buffer.h"
#include "same_image.h"
#include "scene/scene_loader.h"

namespace rtpg {
namespace {

// BSDF sampling that records every call it receives (and asks for VPLs, as a guide would, unless
// told not to).
class RecordingSampler final : public FirstBounceSampler {
 public:
  explicit RecordingSampler(std::vector<std::string>& log, bool wants_vpls = true)
      : log_(log), wants_vpls_(wants_vpls) {}
  void begin_frame(const GBuffer&, const SampleCoordinates& at) override {
    log_.push_back("begin " + std::to_string(at.frame));
  }
  void end_frame(const GBuffer&, const VplBuffer& vpls, const SampleCoordinates& at) override {
    std::size_t valid = 0;
    for (std::uint32_t info : vpls.info) valid += (info & PG_VPL_VALID) != 0u;
    log_.push_back("end " + std::to_string(at.frame) + (valid > 0 ? " with vpls" : " no vpls"));
  }
  bool wants_vpls() const override { return wants_vpls_; }
  FirstBounceSamples sample(const GBuffer& g, const SampleCoordinates& at) override {
    log_.push_back("sample " + std::to_string(at.frame) + "." + std::to_string(at.sample));
    return bsdf_.sample(g, at);
  }
  float pdf(const GBuffer& g, std::size_t i, const shared::pg_lobes& lobes, const glm::vec3& wo,
            const glm::vec3& wi) const override {
    return bsdf_.pdf(g, i, lobes, wo, wi);
  }

 private:
  std::vector<std::string>& log_;
  bool wants_vpls_;
  BsdfFirstBounce bsdf_;
};

// The Cornell box at an odd size (23x17), spp samples a pixel.
Scene cornell_box() {
  return load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
}
RenderSettings odd_size(int spp) {
  RenderSettings settings;
  settings.width = 23;
  settings.height = 17;
  settings.spp = spp;
  return settings;
}

TEST(FrameOrder, TrainingFollowsTheFramesLastSample) {
  const Scene scene = cornell_box();
  Renderer renderer(scene, odd_size(3));
  std::vector<std::string> log;
  renderer.set_first_bounce_sampler(std::make_unique<RecordingSampler>(log));
  renderer.render_frame(0);
  renderer.render_frame(1);
  const std::vector<std::string> expected = {
      "begin 0", "sample 0.0", "sample 0.1", "sample 0.2", "end 0 with vpls",
      "begin 1", "sample 1.0", "sample 1.1", "sample 1.2", "end 1 with vpls"};
  EXPECT_EQ(log, expected);
}

// Two samples a pixel, a moving camera, an odd size: every frame's image is the same to the bit
// whether the first bounce comes from BsdfFirstBounce's own pass (RecordingSampler runs it; the
// renderer leaves it out for BsdfFirstBounce itself, samples_the_bsdf()) or from the path
// tracer's. Both keep no VPLs (a pass that keeps them sums its paths from the first bounce's hit,
// equal up to rounding: PathTracer::VplPath) and weigh the primary hit's MIS with the sampler's
// own density (under FirstBounceMis::bsdf a sampler that is not BsdfFirstBounce itself has the
// BSDF's density recomputed from the direction, equal up to rounding).
TEST(FrameOrder, BsdfAtThePrimaryHitEqualsItsOwnPass) {
  const Scene scene = cornell_box();
  RenderSettings settings = odd_size(2);
  settings.camera_path = "pan";
  settings.path_tracer.first_bounce_mis = FirstBounceMis::mixture;
  Renderer in_place(scene, settings), separate(scene, settings);
  ASSERT_TRUE(BsdfFirstBounce().samples_the_bsdf());
  std::vector<std::string> log;
  separate.set_first_bounce_sampler(std::make_unique<RecordingSampler>(log, false));
  for (int frame = 0; frame < 3; ++frame) {
    in_place.render_frame(frame);
    separate.render_frame(frame);
    expect_same_lit_image(in_place.image(), separate.image(), "frame " + std::to_string(frame));
  }
  EXPECT_EQ(std::count(log.begin(), log.end(), "sample 2.1"), 1);  // the pass ran
}

}  // namespace
}  // namespace rtpg

// The diagnostic of host/render/path_tracer.h, SharedRandoms: with the first bounce (and the
// next-event estimate at the primary hit) shared, every sample of a frame repeats sample 0's
// draw there and only the rest of the path takes its own numbers. bench/variance_split.py reads
// the variance of a pixel by where it arises from this; a share that leaked into the rest of the
// path, or missed a part it names, would misplace it.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "forwarding_sampler.h"
#include "render/first_bounce.h"
#include "render/renderer.h"
#include "scene/scene_loader.h"

namespace rtpg {
namespace {

Scene cornell_box() {
  return load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
}

// The Cornell box at an odd size along its pan; `bounces` vertices after the primary hit. Without
// next-event estimation one bounce finds the small light in about 1% of the pixels, so that
// case renders at 67x49.
RenderSettings settings_for(int spp, int bounces, bool next_event, SharedRandoms shared) {
  RenderSettings settings;
  settings.width = next_event ? 23 : 67;
  settings.height = next_event ? 17 : 49;
  settings.spp = spp;
  settings.camera_path = "pan";
  settings.path_tracer.max_bounces = bounces;
  settings.path_tracer.next_event = next_event;
  settings.path_tracer.shared_randoms = shared;
  return settings;
}

// Pixels whose value differs between the last frames of two renderers.
std::size_t differing_pixels(const Renderer& a, const Renderer& b) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.image().size(); ++i) differ += a.image()[i] != b.image()[i];
  return differ;
}

// Pixels whose value differs between frame `frame` of two renderers, and pixels lit in the first.
struct Difference {
  std::size_t differ = 0, lit = 0;
};
Difference render_and_compare(Renderer& a, Renderer& b, int frame) {
  a.render_frame(frame);
  b.render_frame(frame);
  Difference d;
  d.differ = differing_pixels(a, b);
  for (const glm::vec3& c : a.image()) d.lit += c != glm::vec3(0.0f);
  return d;
}

// One bounce and no next-event estimation: a sample's value is its first bounce's alone, so two
// samples sharing it average to the one-sample image exactly (x / 2 + x / 2 = x in floats).
TEST(SharedRandoms, FirstBounceRepeatsSampleZero) {
  const Scene scene = cornell_box();
  Renderer one(scene, settings_for(1, 1, false, SharedRandoms::none));
  Renderer shared(scene, settings_for(2, 1, false, SharedRandoms::first_bounce));
  Renderer own(scene, settings_for(2, 1, false, SharedRandoms::none));
  std::size_t lit = 0, own_differ = 0;
  for (int frame = 0; frame < 3; ++frame) {
    const Difference d = render_and_compare(one, shared, frame);
    EXPECT_EQ(d.differ, 0u) << "frame " << frame;
    lit += d.lit;
    own.render_frame(frame);
    own_differ += differing_pixels(own, one);
  }
  // Lit pixels are those whose bounce found the light (besides the light's own); with samples of
  // their own, two samples find it in other pixels than one does.
  EXPECT_GT(lit, 30u);
  EXPECT_GT(own_differ, 30u);
}

// Two samples that share `repeating` give the one-sample image to the bit over three frames (on
// an image a third of whose pixels are lit), and sharing only `weaker` changes a quarter or more
// of the pixels: `repeating` covers every number of the path that `weaker` leaves its own.
void expect_share_repeats_sample_zero(int bounces, SharedRandoms repeating, SharedRandoms weaker,
                                      const char* left_own) {
  const Scene scene = cornell_box();
  Renderer one(scene, settings_for(1, bounces, true, SharedRandoms::none));
  Renderer shared(scene, settings_for(2, bounces, true, repeating));
  Renderer less(scene, settings_for(2, bounces, true, weaker));
  for (int frame = 0; frame < 3; ++frame) {
    const Difference d = render_and_compare(one, shared, frame);
    EXPECT_EQ(d.differ, 0u) << "frame " << frame;
    EXPECT_GT(d.lit, one.image().size() / 3) << "frame " << frame;
    less.render_frame(frame);
    EXPECT_GT(differing_pixels(less, one), one.image().size() / 4)
        << "frame " << frame << ": " << left_own << " shared";
  }
}

// With next-event estimation at the primary hit, sharing the first bounce leaves the light sample
// each sample's own; sharing the primary vertex repeats it too.
TEST(SharedRandoms, PrimaryVertexAlsoRepeatsTheLightSample) {
  expect_share_repeats_sample_zero(1, SharedRandoms::primary_vertex, SharedRandoms::first_bounce,
                                   "light samples");
}

// Two bounces: the second vertex's light sample and bounce are the last numbers a path draws
// (the vertex after them only adds what its ray found), so sharing the second vertex repeats
// sample 0 exactly, and sharing only the primary vertex does not.
TEST(SharedRandoms, SecondVertexAlsoRepeatsTheFirstBouncesHit) {
  expect_share_repeats_sample_zero(2, SharedRandoms::second_vertex, SharedRandoms::primary_vertex,
                                   "y");
}

// Sample 0 draws as the renderer does in every mode (the shared parts are its numbers), so one
// sample a pixel gives the renderer's image to the bit at full depth: the four renders of
// bench/variance_split.py share their first sample, and a guided run trains on the same VPLs.
TEST(SharedRandoms, SampleZeroIsTheRenderersOwn) {
  const Scene scene = cornell_box();
  Renderer plain(scene, settings_for(1, 8, true, SharedRandoms::none));
  Renderer first(scene, settings_for(1, 8, true, SharedRandoms::first_bounce));
  Renderer primary(scene, settings_for(1, 8, true, SharedRandoms::primary_vertex));
  Renderer second(scene, settings_for(1, 8, true, SharedRandoms::second_vertex));
  for (int frame = 0; frame < 2; ++frame) {
    plain.render_frame(frame);
    for (Renderer* r : {&first, &primary, &second}) {
      r->render_frame(frame);
      EXPECT_EQ(r->image(), plain.image()) << "frame " << frame;
    }
  }
}

// At full depth the rest of the path stays each sample's own: the shared images differ from
// the one-sample image, and from each other only through what follows the shared part.
TEST(SharedRandoms, TheRestOfThePathKeepsItsOwnNumbers) {
  const Scene scene = cornell_box();
  Renderer one(scene, settings_for(1, 8, true, SharedRandoms::none));
  Renderer vertex(scene, settings_for(2, 8, true, SharedRandoms::primary_vertex));
  Renderer second(scene, settings_for(2, 8, true, SharedRandoms::second_vertex));
  for (int frame = 0; frame < 2; ++frame) {
    const Difference d = render_and_compare(one, vertex, frame);
    EXPECT_GT(d.differ, one.image().size() / 4) << "frame " << frame;
    second.render_frame(frame);
    const std::size_t differ = differing_pixels(second, one);
    EXPECT_GT(differ, one.image().size() / 8) << "frame " << frame;
  }
}

// A first-bounce sampler of its own (the guided one draws in the sample kernel) is handed
// sample 0's coordinates for every sample of the frame: BSDF sampling through
// ForwardingSampler (which makes the renderer call sample()), recording each call's sample.
class CoordinateLog final : public ForwardingSampler {
 public:
  explicit CoordinateLog(std::vector<std::uint32_t>& samples)
      : ForwardingSampler(std::make_unique<BsdfFirstBounce>()), samples_(samples) {}
  FirstBounceSamples sample(const GBuffer& g, const SampleCoordinates& at) override {
    samples_.push_back(at.sample);
    return ForwardingSampler::sample(g, at);
  }

 private:
  std::vector<std::uint32_t>& samples_;
};

TEST(SharedRandoms, ASamplerOfItsOwnDrawsWithSampleZero) {
  const Scene scene = cornell_box();
  for (const SharedRandoms shared : {SharedRandoms::none, SharedRandoms::first_bounce,
                                     SharedRandoms::primary_vertex, SharedRandoms::second_vertex}) {
    Renderer renderer(scene, settings_for(3, 2, true, shared));
    std::vector<std::uint32_t> samples;
    renderer.set_first_bounce_sampler(std::make_unique<CoordinateLog>(samples));
    renderer.render_frame(0);
    const std::vector<std::uint32_t> expected = shared == SharedRandoms::none
                                                    ? std::vector<std::uint32_t>{0, 1, 2}
                                                    : std::vector<std::uint32_t>{0, 0, 0};
    EXPECT_EQ(samples, expected);
  }
}

}  // namespace
}  // namespace rtpg

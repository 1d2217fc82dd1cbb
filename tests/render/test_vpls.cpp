// The VPLs the path tracer hands to training (include/rtpg/guiding_layout.h): for every pixel
// whose first bounce found something, the hit y (or the escaped direction), the density of the
// strategy that drew the bounce and the whole sampler's density D, both in area measure at y
// (solid angle for an escaped ray). The images do not depend on these densities (training
// does), so the unbiasedness tests cannot see them: this test recomputes them from the samples
// and the G-buffer of the frame.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "forwarding_sampler.h"
#include "render/first_bounce.h"
#include "render/guided_first_bounce.h"
#include "render/renderer.h"
#include "render/vpl_buffer.h"
#include "rtpg/cl_runtime.h"
#include "scene/scene_loader.h"
#include "shared/bsdf.h"
#include "shared/vpl_packing.h"

namespace rtpg {
namespace {

// Keeps a copy of each frame's first samples.
class KeepsFirstSamples final : public ForwardingSampler {
 public:
  using ForwardingSampler::ForwardingSampler;
  FirstBounceSamples sample(const GBuffer& g, const SampleCoordinates& at) override {
    const FirstBounceSamples s = ForwardingSampler::sample(g, at);
    if (at.sample == 0) {  // as they came, or packed
      direction_pdf.resize(g.pixel_count());
      strategy.resize(g.pixel_count());
      for (std::size_t i = 0; i < g.pixel_count(); ++i) {
        const FirstBounceSample f = s.at(i);
        direction_pdf[i] = glm::vec4(f.direction, f.pdf);
        strategy[i] = f.strategy;
      }
    }
    return s;
  }

  std::vector<glm::vec4> direction_pdf;
  std::vector<std::uint32_t> strategy;
};

struct VplCounts {
  std::size_t surfaces = 0, valid = 0, guided = 0, distant = 0;
};

// Renders `frames` guided frames at 2 spp and checks the last frame's VPLs against its first
// samples (the VPLs come from sample 0).
VplCounts check_vpls(const std::string& scene_file, int frames) {
  const Scene scene = load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/" + scene_file);
  RenderSettings settings;
  settings.width = 37;
  settings.height = 21;
  settings.spp = 2;
  // The runtime outlives the renderer, whose guided sampler uses its queue until destroyed.
  ClRuntime cl;
  Renderer renderer(scene, settings);
  auto keeper = std::make_unique<KeepsFirstSamples>(
      std::make_unique<GuidedFirstBounce>(cl, settings.width, settings.height, GuidingSettings{}));
  const KeepsFirstSamples& kept = *keeper;
  renderer.set_first_bounce_sampler(std::move(keeper));
  for (int f = 0; f < frames; ++f) renderer.render_frame(f);

  const GBuffer& g = renderer.gbuffer();
  const VplBuffer& v = renderer.vpls();
  VplCounts counts;
  for (std::size_t i = 0; i < g.pixel_count(); ++i) {
    if (!g.has_surface(i)) continue;
    ++counts.surfaces;
    const std::uint32_t info = v.info[i];
    const float d = kept.direction_pdf[i].w;
    // The kernels' copy of the info word, packed beside the radiance.
    EXPECT_EQ(shared::pg_vpl_info(v.normal_radiance[i]), info) << "pixel " << i;
    if (!(info & PG_VPL_VALID)) continue;
    SCOPED_TRACE("pixel " + std::to_string(i));
    const float mixture_density = shared::pg_vpl_mixture_density(v.normal_radiance[i]);
    ++counts.valid;
    const std::uint32_t strategy = PG_VPL_STRATEGY(info);
    if (!(d > 0.0f) || strategy != kept.strategy[i]) {
      ADD_FAILURE() << "the VPL's strategy " << strategy << " or the sample's density " << d
                    << " is not the first bounce's (strategy " << kept.strategy[i] << ")";
      continue;
    }
    counts.guided += strategy == kStrategyGuide;
    // The strategy's own density: the BSDF's for a BSDF sample, D for the Gaussian's.
    const glm::vec3 wi_world(kept.direction_pdf[i]);
    const shared::pg_frame frame = gbuffer_frame(g, i);
    const glm::vec3 wo = shared::pg_to_local(frame, glm::vec3(g.view_dir[i]));
    const shared::pg_lobes lobes = shared::pg_make_lobes(gbuffer_material(g, i), wo);
    const float own = strategy == kStrategyBsdf
                          ? shared::pg_bsdf_pdf(lobes, wo, shared::pg_to_local(frame, wi_world))
                          : d;
    if (info & PG_VPL_DISTANT) {
      ++counts.distant;
      EXPECT_NEAR(glm::length(glm::vec3(v.position[i]) - glm::normalize(wi_world)), 0.0f, 1e-6f);
      EXPECT_FLOAT_EQ(v.position[i].w, own);
      EXPECT_FLOAT_EQ(mixture_density, d);
      continue;
    }
    const glm::vec3 to = glm::vec3(v.position[i]) - glm::vec3(g.position_depth[i]);
    const float d2 = glm::dot(to, to);
    const glm::vec3 ng = shared::pg_vpl_normal(v.normal_radiance[i]);
    EXPECT_NEAR(glm::length(ng), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(glm::normalize(to) - glm::normalize(wi_world)), 0.0f, 1e-3f);
    // The packed normal is within PG_OCTAHEDRAL_MAX_ANGLE of the surface's, so its cosine
    // within that much of the one the densities were converted with.
    const float to_area = std::fabs(glm::dot(ng, glm::normalize(wi_world))) / d2;
    const float cos_error = PG_OCTAHEDRAL_MAX_ANGLE / d2;
    EXPECT_NEAR(v.position[i].w, own * to_area, 1e-4f * own * to_area + own * cos_error);
    EXPECT_NEAR(mixture_density, d * to_area, 1e-4f * d * to_area + d * cos_error);
  }
  return counts;
}

TEST(Vpls, CarryTheFirstBouncesDensitiesInAreaMeasure) {
  const VplCounts c = check_vpls("cornell-box.json", 6);
  EXPECT_GT(c.valid, c.surfaces / 2);
  EXPECT_GT(c.guided, c.valid / 20) << "no Gaussian samples: the guided branch is untested";
  EXPECT_GT(c.valid - c.guided, c.valid / 20);
}

TEST(Vpls, EscapedBouncesCarryTheirDirectionAndSolidAngleDensities) {
  const VplCounts c = check_vpls("sunlit-room.json", 6);
  EXPECT_GT(c.valid, c.surfaces / 2);
  EXPECT_GT(c.distant, 0u) << "no first bounce escaped: the distant branch is untested";
}

}  // namespace
}  // namespace rtpg

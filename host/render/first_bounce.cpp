#include "render/first_bounce.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "rtpg/guiding_layout.h"
#include "shared/rng.h"

namespace rtpg {

FirstBounceSample bsdf_first_bounce_sample(const shared::pg_frame& frame, const glm::vec3& wo,
                                           const shared::pg_lobes& lobes,
                                           const SampleCoordinates& at, std::size_t i) {
  return bsdf_first_bounce_sample(
      frame, wo, lobes,
      shared::pg_rng_make(at.seed, static_cast<shared::uint>(i), at.frame, at.sample,
                          PG_RNG_STREAM_FIRST_BOUNCE)
          .state);
}

FirstBounceSample bsdf_first_bounce_sample(const shared::pg_frame& frame, const glm::vec3& wo,
                                           const shared::pg_lobes& lobes,
                                           std::uint32_t stream_start) {
  shared::pg_rng rng;
  rng.state = stream_start;
  const float u_lobe = shared::pg_rng_next(&rng);
  const float u1 = shared::pg_rng_next(&rng);
  const float u2 = shared::pg_rng_next(&rng);
  const shared::pg_bsdf_sample_t bs = shared::pg_bsdf_sample(lobes, wo, u_lobe, u1, u2);
  FirstBounceSample s;
  if (bs.pdf <= 0.0f) return s;
  s.direction = shared::pg_to_world(frame, bs.wi);
  s.pdf = bs.pdf;
  s.strategy = kStrategyBsdf;
  return s;
}

FirstBounceSamples BsdfFirstBounce::sample(const GBuffer& g, const SampleCoordinates& at) {
  direction_pdf_.resize(g.pixel_count());
  strategy_.resize(g.pixel_count());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, g.pixel_count(), 4096), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      FirstBounceSample s;
      if (g.has_surface(i)) {
        const shared::pg_frame frame = gbuffer_frame(g, i);
        const glm::vec3 wo = shared::pg_to_local(frame, glm::vec3(g.view_dir[i]));
        const shared::pg_lobes lobes = shared::pg_make_lobes(gbuffer_material(g, i), wo);
        s = bsdf_first_bounce_sample(frame, wo, lobes, at, i);
      }
      direction_pdf_[i] = glm::vec4(s.direction, s.pdf);
      strategy_[i] = s.strategy;
    }
  });
  return FirstBounceSamples{direction_pdf_.data(), strategy_.data()};
}

float BsdfFirstBounce::pdf(const GBuffer&, std::size_t, const shared::pg_lobes& lobes,
                           const glm::vec3& wo, const glm::vec3& wi) const {
  return shared::pg_bsdf_pdf(lobes, wo, wi);
}

}  // namespace rtpg

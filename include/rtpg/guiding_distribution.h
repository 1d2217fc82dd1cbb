// One pixel's guiding distribution on the host: the mixture of the paper's eq. 2 (a Gaussian
// in Shirley-Chiu square space, weight pi, plus the BSDF) exactly as the sample kernel draws
// from it. A CPU renderer needs its density for the MIS weight of next-event estimation at
// the guided vertex, and may sample it without a device. Built from a pixel's state
// (Guider::read_state) or the mixture the sample kernel wrote, and its G-buffer entries
// (include/rtpg/guiding_layout.h).
//
// A value type without allocation: make one per thread and init() it per pixel.
#pragma once

#include <cstdint>

#include "rtpg/guiding_layout.h"

namespace rtpg {

struct GuidingDirection {
  float direction[3] = {0.0f, 0.0f, 1.0f};  // world space, unit
  float pdf = 0.0f;                         // the mixture's solid-angle density; 0 = none
  std::uint32_t strategy = PG_STRATEGY_NONE;
};

class GuidingDistribution {
 public:
  explicit GuidingDistribution(const pg_kernel_settings& settings);

  // state: the pixel's PG_STATE_FLOATS_PER_PIXEL floats; the rest its G-buffer channels
  // (xyz of shading_normal and view_dir, the four of the others). A pixel guiding skips
  // (pg_guiding_applies: sky, emitter, delta, transmissive, low roughness) or without a
  // trained model gets the BSDF alone.
  void init(const float* state, const float* shading_normal, const float* view_dir,
            const float* base_color_roughness, const float* metallic_specular, std::uint32_t flags);

  // The same from the mixture the sample kernel wrote for the pixel (mixture_a, mixture_b of
  // include/rtpg/guiding_layout.h): no state read-back, no regularisation on the host. The
  // kernel has already applied pg_guiding_applies (a skipped pixel's mixture is zero).
  void init_mixture(const float* mixture_a, const float* mixture_b, const float* shading_normal,
                    const float* view_dir, const float* base_color_roughness,
                    const float* metallic_specular);

  bool guided() const;          // a trained Gaussian takes part
  float mixing_weight() const;  // its pi (0 when not guided)
  // Density of a world direction (unit), in solid angle.
  float pdf(const float* direction) const;
  // One direction from three uniform numbers in [0, 1): xi picks the component.
  GuidingDirection sample(float xi, float u1, float u2) const;

 private:
  pg_kernel_settings settings_;
  // The model, the BSDF lobes and the shading frame (kernels/shared types), stored in place.
  alignas(16) unsigned char pixel_[128];
};

}  // namespace rtpg

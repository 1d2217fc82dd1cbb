#include "rtpg/guiding_distribution.h"

#include <new>
#include <type_traits>

#include "shared/guiding_pixel.h"
#include "shared/pmm.h"

namespace rtpg {
namespace {

namespace sh = shared;

struct Pixel {
  sh::pg_pmm_model model;
  sh::pg_lobes lobes;
  sh::pg_frame frame;
  sh::float3 wo;
};
static_assert(std::is_trivially_copyable_v<Pixel> && std::is_trivially_destructible_v<Pixel>);

}  // namespace

#define RTPG_PIXEL(storage) (*std::launder(reinterpret_cast<Pixel*>(storage)))

GuidingDistribution::GuidingDistribution(const pg_kernel_settings& settings) : settings_(settings) {
  static_assert(sizeof(Pixel) <= sizeof(pixel_) && alignof(Pixel) <= 16,
                "GuidingDistribution::pixel_ holds a Pixel");
  new (pixel_) Pixel{};
  RTPG_PIXEL(pixel_).model.valid = 0;
}

namespace {

sh::float4 load4(const float* v) {
  return sh::float4(v[0], v[1], v[2], v[3]);
}

// Frame, view direction and lobes of a pixel from its G-buffer entries.
void init_surface(Pixel& px, const float* shading_normal, const float* view_dir,
                  const sh::float4& bcr, const float* metallic_specular) {
  px.frame =
      sh::pg_frame_from_normal(sh::float3(shading_normal[0], shading_normal[1], shading_normal[2]));
  px.wo = sh::pg_to_local(px.frame, sh::float3(view_dir[0], view_dir[1], view_dir[2]));
  px.lobes = sh::pg_make_lobes(sh::pg_material_from_gbuffer(bcr, load4(metallic_specular)), px.wo);
}

}  // namespace

void GuidingDistribution::init_mixture(const float* mixture_a, const float* mixture_b,
                                       const float* shading_normal, const float* view_dir,
                                       const float* base_color_roughness,
                                       const float* metallic_specular) {
  Pixel& px = RTPG_PIXEL(pixel_);
  init_surface(px, shading_normal, view_dir, load4(base_color_roughness), metallic_specular);
  px.model =
      sh::pg_pmm_model_from_mixture(load4(mixture_a), sh::float2(mixture_b[0], mixture_b[1]));
}

void GuidingDistribution::init(const float* state, const float* shading_normal,
                               const float* view_dir, const float* base_color_roughness,
                               const float* metallic_specular, std::uint32_t flags) {
  Pixel& px = RTPG_PIXEL(pixel_);
  const sh::float4 bcr = load4(base_color_roughness);
  init_surface(px, shading_normal, view_dir, bcr, metallic_specular);
  sh::pg_pmm_state st = sh::pg_pmm_initial_state();
  if (sh::pg_guiding_applies(flags, bcr.w, settings_)) {
    st.s0 = sh::float4(state[0], state[1], state[2], state[3]);
    st.s1 = sh::float4(state[4], state[5], state[6], state[7]);
  }
  px.model = sh::pg_pmm_model_from_state(st, settings_);
}

bool GuidingDistribution::guided() const {
  return RTPG_PIXEL(const_cast<unsigned char*>(pixel_)).model.valid != 0;
}

float GuidingDistribution::mixing_weight() const {
  const Pixel& px = RTPG_PIXEL(const_cast<unsigned char*>(pixel_));
  return px.model.valid ? px.model.pi : 0.0f;
}

float GuidingDistribution::pdf(const float* direction) const {
  const Pixel& px = RTPG_PIXEL(const_cast<unsigned char*>(pixel_));
  const sh::float3 wi =
      sh::pg_to_local(px.frame, sh::float3(direction[0], direction[1], direction[2]));
  return sh::pg_pmm_pdf(px.model, px.lobes, px.wo, wi);
}

GuidingDirection GuidingDistribution::sample(float xi, float u1, float u2) const {
  const Pixel& px = RTPG_PIXEL(const_cast<unsigned char*>(pixel_));
  const sh::pg_pmm_sample_t s = sh::pg_pmm_sample(px.model, px.lobes, px.wo, xi, u1, u2);
  const sh::float3 w = sh::pg_to_world(px.frame, s.wi);
  GuidingDirection out;
  out.direction[0] = w.x;
  out.direction[1] = w.y;
  out.direction[2] = w.z;
  out.pdf = s.pdf;
  out.strategy = s.strategy;
  return out;
}

#undef RTPG_PIXEL

}  // namespace rtpg

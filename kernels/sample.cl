/* The first-bounce direction of every surface pixel from its mixture (paper eq. 2, 3.1):
 * the Gaussian with probability pi, else the BSDF; skipped pixels and pixels without a model
 * sample the BSDF. Writes the world direction with the mixture density (one-sample MIS), the
 * strategy that produced it, the mixture itself where write_mixture is 1 (for a host that
 * evaluates it in its MIS weights), and the work-group's counts (include/rtpg/guiding_layout.h,
 * "Counts"). */
#include "shared/guiding_pixel.h"
#include "shared/kernel_args.h"
#include "shared/pmm.h"
#include "shared/rng.h"
#include "shared/work_group_sum.h"

/* One pixel inside the image, sampled with the model of pixel model_index (pg_model_pixel);
 * returns its counts (surface, guided, pi, 0). */
static float4 pg_sample_pixel(PG_ARGS_GBUFFER PG_ARGS_STATE PG_ARGS_SAMPLES uint i,
                              uint model_index, uint seed, uint frame, uint sample_index,
                              uint write_mixture, pg_kernel_settings settings) {
  uint f = flags[i];
  if ((f & PG_GBUF_SKY) != 0u) {
    direction_pdf[i] = (float4)(0.0f, 0.0f, 1.0f, 0.0f);
    strategy[i] = PG_STRATEGY_NONE;
    if (write_mixture) {
      mixture_a[i] = (float4)(0.0f);
      mixture_b[i] = (float2)(0.0f);
    }
    return (float4)(0.0f);
  }
  float4 bcr = base_color_roughness[i];
  pg_pmm_state state = pg_pmm_initial_state();
  if (pg_guiding_applies(f, bcr.w, settings)) {
    state.s0 = state0[model_index];
    state.s1 = state1[model_index];
    /* A pixel that shares its model carries it as its own state (pg_shares_model). */
    if (model_index != i) {
      state0[i] = state.s0;
      state1[i] = state.s1;
    }
  }
  pg_pmm_model model = pg_pmm_model_from_state(state, settings);
  pg_frame frame_x = pg_frame_from_normal(shading_normal[i].xyz);
  float3 wo = pg_to_local(frame_x, view_dir[i].xyz);
  pg_lobes lobes = pg_make_lobes(pg_material_from_gbuffer(bcr, metallic_specular[i]), wo);
  pg_rng rng = pg_rng_make(seed, i, frame, sample_index, PG_RNG_STREAM_FIRST_BOUNCE);
  float xi = pg_rng_next(&rng);
  float u1 = pg_rng_next(&rng);
  float u2 = pg_rng_next(&rng);
  pg_pmm_sample_t s = pg_pmm_sample(model, lobes, wo, xi, u1, u2);
  float3 w = pg_to_world(frame_x, s.wi);
  direction_pdf[i] = (float4)(w.x, w.y, w.z, s.pdf);
  strategy[i] = s.strategy;
  if (write_mixture) {
    mixture_a[i] = pg_pmm_mixture_a(model);
    mixture_b[i] = pg_pmm_mixture_b(model);
  }
  return model.valid ? (float4)(1.0f, 1.0f, model.pi, 0.0f) : (float4)(1.0f, 0.0f, 0.0f, 0.0f);
}

/* sharing_decided: 1 where this frame's shares_model is already decided (by reproject or an
 * earlier sample of the frame) and is read, 0 where it is decided and written here
 * (include/rtpg/guiding_layout.h, "Shared models"). */
__kernel void sample(PG_ARGS_GBUFFER PG_ARGS_STATE PG_ARGS_SAMPLES __global uchar* shares_model,
                     __global float4* counts, uint width, uint height, uint seed, uint frame,
                     uint sample_index, uint write_mixture, uint sharing_decided,
                     pg_kernel_settings settings, __local float4* scratch) {
  uint x = get_global_id(0), y = get_global_id(1);
  float4 count = (float4)(0.0f);
  if (x < width && y < height)
    count = pg_sample_pixel(PG_PASS_GBUFFER PG_PASS_STATE PG_PASS_SAMPLES y * width + x,
                            pg_frame_model_pixel(PG_PASS_GBUFFER shares_model, sharing_decided, 1,
                                                 x, y, width, settings),
                            seed, frame, sample_index, write_mixture, settings);
  pg_store_work_group_counts(counts, scratch, count);
}

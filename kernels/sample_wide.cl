/* The sample kernel (sample.cl) with PG_LANES pixels of one row per work-item, in vector lanes
 * (kernels/wide/lanes.h): the variant for CPU devices, whose compilers vectorise it where they
 * cannot vectorise sample.cl's branches (docs/guiding.md, "Several pixels per work-item").
 * Every lane runs both components' samplers and keeps its own by a select (kernels/wide/
 * pmm_wide.h); a work-item skips the Gaussian when none of its lanes picks it and the GGX lobe
 * when none of its lanes has one. Sky pixels and pixels guiding skips are written as sample.cl
 * writes them. */
/* No fused multiply-adds (as in train_wide.cl): near the peak of a narrow GGX lobe D's
 * denominator is a difference of nearly equal numbers, where one fused product moves the
 * density by percents (tests/guiding/test_guiding_kernels.cpp). */
/* Per pixel (hand count; docs/guiding.md, "The roofline"): 232 flops for a Lambert pixel
 * sampling its BSDF (11 divisions, 6 sqrt/sin/cos), +181 where a lane has a GGX lobe, +81 for a
 * trained model's density, +59 where a lane picks the Gaussian (553 at most); 68-100 bytes read,
 * 44 written. */
#pragma OPENCL FP_CONTRACT OFF
#include "shared/guiding_pixel.h"
#include "shared/kernel_args.h"
#include "shared/pmm.h"
#include "shared/rng.h"
#include "wide/pmm_wide.h"

/* Per-lane inputs in private arrays, one row of PG_LANES per field. */
enum {
  IN_NORMAL,
  IN_VIEW = IN_NORMAL + 3,
  IN_BASE_COLOR = IN_VIEW + 3,
  IN_ROUGHNESS = IN_BASE_COLOR + 3,
  IN_METALLIC,
  IN_SPECULAR,
  IN_STATE, /* 8 rows: pg_pmm_state's s0 then s1 */
  IN_XI = IN_STATE + 8,
  IN_U1,
  IN_U2,
  IN_FIELDS
};

__kernel void sample_wide(PG_ARGS_GBUFFER PG_ARGS_IN_STATE PG_ARGS_SAMPLES uint width, uint height,
                          uint seed, uint frame, uint sample_index, pg_kernel_settings settings) {
  int x0 = (int)get_global_id(0) * PG_LANES, y = (int)get_global_id(1);
  if (x0 >= (int)width || y >= (int)height) return;

  float in[IN_FIELDS][PG_LANES];
  int sky[PG_LANES];
  int any_surface = 0, any_specular = 0, any_model = 0;
  for (int l = 0; l < PG_LANES; ++l) {
    /* A lane past the row's end computes on the row's last pixel and stores nothing. */
    int x = min(x0 + l, (int)width - 1), i = y * (int)width + x;
    uint f = flags[i];
    float4 bcr = base_color_roughness[i], ms = metallic_specular[i];
    float4 n = shading_normal[i], v = view_dir[i];
    pg_pmm_state state = pg_pmm_initial_state();
    sky[l] = (f & PG_GBUF_SKY) != 0u;
    any_surface |= !sky[l];
    if (pg_guiding_applies(f, bcr.w, settings)) {
      state.s0 = in_state0[i];
      state.s1 = in_state1[i];
      any_model |= state.s1.w > 0.0f;
    }
    any_specular |= !sky[l] && (ms.y > 0.0f || ms.x > 0.0f);
    pg_put3_rows(in, IN_NORMAL, l, n.xyz);
    pg_put3_rows(in, IN_VIEW, l, v.xyz);
    pg_put3_rows(in, IN_BASE_COLOR, l, bcr.xyz);
    in[IN_ROUGHNESS][l] = bcr.w;
    in[IN_METALLIC][l] = ms.x;
    in[IN_SPECULAR][l] = ms.y;
    in[IN_STATE][l] = state.s0.x;
    in[IN_STATE + 1][l] = state.s0.y;
    in[IN_STATE + 2][l] = state.s0.z;
    in[IN_STATE + 3][l] = state.s0.w;
    in[IN_STATE + 4][l] = state.s1.x;
    in[IN_STATE + 5][l] = state.s1.y;
    in[IN_STATE + 6][l] = state.s1.z;
    in[IN_STATE + 7][l] = state.s1.w;
    pg_rng rng = pg_rng_make(seed, (uint)i, frame, sample_index, PG_RNG_STREAM_FIRST_BOUNCE);
    in[IN_XI][l] = pg_rng_next(&rng);
    in[IN_U1][l] = pg_rng_next(&rng);
    in[IN_U2][l] = pg_rng_next(&rng);
  }

  float out[11][PG_LANES]; /* direction, pdf, strategy, mixture_a, mixture_b */
  if (any_surface) {
    pg_pmm_state_w s;
    s.w = pg_vloadw(0, in[IN_STATE]);
    s.s0 = pg_vloadw(0, in[IN_STATE + 1]);
    s.sx = pg_vloadw(0, in[IN_STATE + 2]);
    s.sy = pg_vloadw(0, in[IN_STATE + 3]);
    s.sxx = pg_vloadw(0, in[IN_STATE + 4]);
    s.syy = pg_vloadw(0, in[IN_STATE + 5]);
    s.sxy = pg_vloadw(0, in[IN_STATE + 6]);
    s.k = pg_vloadw(0, in[IN_STATE + 7]);
    pg_pmm_model_w m = pg_pmm_model_from_state_w(s, settings);
    pg_frame_w frame_x = pg_frame_from_normal_w(pg_get3_rows(in, IN_NORMAL));
    pg_float3w wo = pg_to_local_w(frame_x, pg_get3_rows(in, IN_VIEW));
    pg_lobes_w lobes =
        pg_make_lobes_w(pg_get3_rows(in, IN_BASE_COLOR), pg_vloadw(0, in[IN_ROUGHNESS]),
                        pg_vloadw(0, in[IN_METALLIC]), pg_vloadw(0, in[IN_SPECULAR]), wo);
    pg_intw guided;
    pg_floatw pdf;
    pg_float3w wi =
        pg_pmm_sample_w(m, lobes, wo, pg_vloadw(0, in[IN_XI]), pg_vloadw(0, in[IN_U1]),
                        pg_vloadw(0, in[IN_U2]), any_specular, any_model, &guided, &pdf);
    pg_float3w w = pg_to_world_w(frame_x, wi);
    pg_floatw zero = (pg_floatw)(0.0f);
    pg_vstorew(w.x, 0, out[0]);
    pg_vstorew(w.y, 0, out[1]);
    pg_vstorew(w.z, 0, out[2]);
    pg_vstorew(pdf, 0, out[3]);
    pg_vstorew(select((pg_floatw)(PG_STRATEGY_BSDF), (pg_floatw)(PG_STRATEGY_GUIDE), guided), 0,
               out[4]);
    /* pg_pmm_mixture_a and _b: an invalid model is all zeros. */
    pg_vstorew(select(zero, m.pi, m.valid), 0, out[5]);
    pg_vstorew(select(zero, m.mx, m.valid), 0, out[6]);
    pg_vstorew(select(zero, m.my, m.valid), 0, out[7]);
    pg_vstorew(select(zero, m.l11, m.valid), 0, out[8]);
    pg_vstorew(select(zero, m.l21, m.valid), 0, out[9]);
    pg_vstorew(select(zero, m.l22, m.valid), 0, out[10]);
  }

  for (int l = 0; l < PG_LANES; ++l) {
    int x = x0 + l;
    if (x >= (int)width) break;
    int i = y * (int)width + x;
    if (sky[l]) {
      direction_pdf[i] = (float4)(0.0f, 0.0f, 1.0f, 0.0f);
      strategy[i] = PG_STRATEGY_NONE;
      mixture_a[i] = (float4)(0.0f);
      mixture_b[i] = (float2)(0.0f);
      continue;
    }
    direction_pdf[i] = (float4)(out[0][l], out[1][l], out[2][l], out[3][l]);
    strategy[i] = (uint)out[4][l];
    mixture_a[i] = (float4)(out[5][l], out[6][l], out[7][l], out[8][l]);
    mixture_b[i] = (float2)(out[9][l], out[10][l]);
  }
}

/* The sample kernel (sample.cl) with PG_LANES pixels of one row per work-item, in vector lanes
 * (kernels/wide/lanes.h): the variant for CPU devices, whose compilers vectorise it where they
 * cannot vectorise sample.cl's branches (docs/guiding.md, "Several pixels per work-item").
 * Every lane runs both components' samplers and keeps its own by a select (kernels/wide/
 * pmm_wide.h); a work-item skips the Gaussian when none of its lanes picks it and the GGX lobe
 * when none of its lanes has one. Sky pixels and pixels guiding skips are written as sample.cl
 * writes them; so are the mixture (where write_mixture is 1) and the work-group's counts. */
/* No fused multiply-adds (as in train_wide.cl): near the peak of a narrow GGX lobe D's
 * denominator is a difference of nearly equal numbers, where one fused product moves the
 * density by percents (tests/guiding/test_guiding_kernels.cpp). */
/* Per pixel (hand count; docs/guiding.md, "The roofline"): 248 flops for a Lambert pixel
 * sampling its BSDF (11 divisions, 4 sqrt; cos and sin by polynomials, kernels/wide/
 * sincos_wide.h: 17 flops for an angle of the octant, 35 for a fraction of a turn), +213 where a
 * lane has a GGX lobe, +72 for a trained model's density, +107 where a lane picks the Gaussian
 * (640 at most); 68-100 bytes read,
 * 20 written (44 with the mixture). */
#pragma OPENCL FP_CONTRACT OFF
#include "shared/guiding_pixel.h"
#include "shared/kernel_args.h"
#include "shared/pmm.h"
#include "shared/rng.h"
#include "wide/guiding_pixel_wide.h"
#include "wide/pmm_wide.h"
#include "shared/work_group_sum.h"
#include "wide/rng_wide.h"

/* The lanes' pixels x0 .. x0 + PG_LANES - 1 of row y (x0 inside the image); returns their
 * counts (surfaces, guided, pi, 0). */
/* clang-format off */
static float4 pg_sample_lanes(PG_ARGS_GBUFFER PG_ARGS_STATE PG_ARGS_SAMPLES
                              __global uchar* shares_model, int x0, int y, uint width, uint seed,
                              uint frame, uint sample_index, uint write_mixture,
                              uint sharing_decided, pg_kernel_settings settings) {
  /* clang-format on */
  int w = (int)width, row_start = y * w;

  /* The lanes' inputs, loaded as vectors (kernels/wide/lanes.h). A lane past the row's end
   * computes on its last pixel and stores nothing. Pixels guiding skips sample their BSDF
   * (the initial state has no model). */
  pg_uintw pixel_flags = pg_load_row_uints(flags + row_start, x0, w);
  pg_float3w base_color, normal, view;
  pg_floatw roughness, metallic, specular, unused;
  pg_load_row_float4_rows(base_color_roughness + row_start, x0, w, &base_color.x, &base_color.y,
                          &base_color.z, &roughness);
  pg_load_row_float4_rows(metallic_specular + row_start, x0, w, &metallic, &specular, &unused,
                          &unused);
  pg_intw sky = (pixel_flags & PG_GBUF_SKY) != 0u;
  pg_intw applies = pg_guiding_applies_w(pixel_flags, roughness, settings);
  int any_surface = any(~sky), any_specular = any(~sky & ((specular > 0.0f) | (metallic > 0.0f)));

  pg_float3w direction = pg_make_float3w(0.0f, 0.0f, 1.0f);
  pg_floatw zero = (pg_floatw)(0.0f), pdf = zero;
  pg_uintw strategy_w = (pg_uintw)(PG_STRATEGY_NONE);
  /* Lanes that share the model of the pixel above them (pg_shares_model), as this frame's
   * earlier kernels decided or, where none did, decided here (sample.cl). */
  int sharing = settings.rows_per_model > 1;
  pg_intw shares = (pg_intw)(0);
  if (sharing && sharing_decided) shares = pg_load_row_flags(shares_model + row_start, x0, w);
  pg_pmm_model_w m;
  m.valid = (pg_intw)(0);
  m.pi = m.mx = m.my = m.l11 = m.l21 = m.l22 = zero;
  if (any_surface) {
    pg_pmm_state_w s;
    pg_load_row_float4_rows(state0 + row_start, x0, w, &s.w, &s.s0, &s.sx, &s.sy);
    pg_load_row_float4_rows(state1 + row_start, x0, w, &s.sxx, &s.syy, &s.sxy, &s.k);
    pg_load_row_float4_rows(shading_normal + row_start, x0, w, &normal.x, &normal.y, &normal.z,
                            &unused);
    /* Lanes that share take the model's state. */
    if (sharing && !sharing_decided)
      shares = pg_shares_model_w(
          PG_PASS_GBUFFER x0, y, w,
          pg_model_sharable_w(pixel_flags, roughness, metallic, specular, settings), normal,
          settings);
    if (any(shares)) {
      int model_start = pg_model_row(y, settings) * w;
      pg_pmm_state_w model;
      pg_load_row_float4_rows(state0 + model_start, x0, w, &model.w, &model.s0, &model.sx,
                              &model.sy);
      pg_load_row_float4_rows(state1 + model_start, x0, w, &model.sxx, &model.syy, &model.sxy,
                              &model.k);
      s = pg_pmm_state_select_w(s, model, shares);
      /* Lanes that share carry the model as their own state (pg_shares_model); the
       * others store their own unchanged. No other work-item reads this row's state: a
       * group's first row, the only one read as a model, never shares. */
      pg_store_row_float4_rows(state0 + row_start, x0, w, s.w, s.s0, s.sx, s.sy);
      pg_store_row_float4_rows(state1 + row_start, x0, w, s.sxx, s.syy, s.sxy, s.k);
    }
    s = pg_pmm_state_select_w(pg_pmm_initial_state_w(), s, applies);
    int any_model = any(applies & (s.k > 0.0f));
    pg_load_row_float4_rows(view_dir + row_start, x0, w, &view.x, &view.y, &view.z, &unused);
    pg_intw lane_x = min(x0 + pg_lane_numbers(), (pg_intw)(w - 1));
    pg_uintw rng = pg_rng_make_w(seed, pg_convert_uintw(row_start + lane_x), frame, sample_index,
                                 PG_RNG_STREAM_FIRST_BOUNCE);
    pg_floatw xi = pg_rng_next_w(&rng), u1 = pg_rng_next_w(&rng), u2 = pg_rng_next_w(&rng);

    m = pg_pmm_model_from_state_w(s, settings);
    pg_frame_w frame_x = pg_frame_from_normal_w(normal);
    pg_float3w wo = pg_to_local_w(frame_x, view);
    pg_lobes_w lobes = pg_make_lobes_w(base_color, roughness, metallic, specular, wo);
    pg_intw guided;
    pg_float3w wi =
        pg_pmm_sample_w(m, lobes, wo, xi, u1, u2, any_specular, any_model, &guided, &pdf);
    direction = pg_select3w(pg_to_world_w(frame_x, wi), direction, sky);
    pdf = select(pdf, zero, sky);
    strategy_w = select(select((pg_uintw)(PG_STRATEGY_BSDF), (pg_uintw)(PG_STRATEGY_GUIDE), guided),
                        strategy_w, sky);
    m.valid &= ~sky;
  }

  if (sharing && !sharing_decided) pg_store_row_flags(shares_model + row_start, x0, w, shares);
  pg_store_row_float4_rows(direction_pdf + row_start, x0, w, direction.x, direction.y, direction.z,
                           pdf);
  pg_store_row_uints(strategy + row_start, x0, w, strategy_w);
  pg_intw inside = x0 + pg_lane_numbers() < w;
  if (write_mixture) {
    /* pg_pmm_mixture_a and _b: an invalid model (and a sky pixel) is all zeros. */
    pg_store_row_float4_rows(mixture_a + row_start, x0, w, select(zero, m.pi, m.valid),
                             select(zero, m.mx, m.valid), select(zero, m.my, m.valid),
                             select(zero, m.l11, m.valid));
    pg_store_row_float2_rows(mixture_b + row_start, x0, w, select(zero, m.l21, m.valid),
                             select(zero, m.l22, m.valid));
  }
  pg_intw with_model = inside & m.valid; /* counted as guided: the pixel has a Gaussian */
  return (float4)(pg_sum_lanes(select(zero, (pg_floatw)(1.0f), inside & ~sky)),
                  pg_sum_lanes(select(zero, (pg_floatw)(1.0f), with_model)),
                  pg_sum_lanes(select(zero, m.pi, with_model)), 0.0f);
}

/* clang-format off */
__kernel void sample_wide(PG_ARGS_GBUFFER PG_ARGS_STATE PG_ARGS_SAMPLES
                          __global uchar* shares_model, __global float4* counts, uint width,
                          uint height, uint seed, uint frame, uint sample_index,
                          uint write_mixture, uint sharing_decided, pg_kernel_settings settings,
                          __local float4* scratch) {
  /* clang-format on */
  int x0 = (int)get_global_id(0) * PG_LANES, y = (int)get_global_id(1);
  float4 count = (float4)(0.0f);
  if (x0 < (int)width && y < (int)height)
    count =
        pg_sample_lanes(PG_PASS_GBUFFER PG_PASS_STATE PG_PASS_SAMPLES shares_model, x0, y, width,
                        seed, frame, sample_index, write_mixture, sharing_decided, settings);
  pg_store_work_group_counts(counts, scratch, count);
}

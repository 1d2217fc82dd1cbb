/* The train kernel (train.cl) with PG_LANES pixels of one row per work-item, in vector lanes
 * (kernels/wide/lanes.h): the variant for CPU devices, whose compilers vectorise it where they
 * cannot vectorise train.cl's per-pixel loops (docs/guiding.md, "Several pixels per
 * work-item"). The same training step, lane by lane (kernels/wide/pmm_train_wide.h): per
 * pixel, N neighbour VPLs of the (2*apron+1)^2 window turned into samples, then
 * pg_pmm_train's E-step passes and M-steps. Trip counts are the largest of the lanes; a lane
 * past its own count is masked. VPLs are read from global memory (no tile: a CPU device's
 * caches hold the window). The work-group's record counts the pixels whose state changed
 * (include/rtpg/guiding_layout.h, "Counts"). The state is updated in place, as in train.cl: a
 * work-item none of whose lanes trains this frame reads the lanes' flags, roughness and k and
 * writes nothing; one all of whose lanes share their row group's model, as this frame's reproject
 * or sample kernel decided, reads that decision alone (include/rtpg/guiding_layout.h, "Shared
 * models"). */
/* No fused multiply-adds, here or in the shared functions: the host reference runs them
 * unfused, and near the peak of a narrow GGX lobe (alpha 0.03) D's denominator is a difference
 * of nearly equal numbers, where one fused product moves D, and a sample's weight, by 1e-4
 * relative (tests/guiding/test_guiding_kernels.cpp). */
/* Per pixel (hand count; docs/guiding.md, "The roofline"): 162 + b N + 63 N P + 182 P flops for
 * N neighbours and P E-step passes (a lane runs to its work-item's largest N and P), b = 158 for
 * Lambert lobes, 264 where a lane has a GGX lobe: 1449-1979 at N = 5, P = 1; 9768 at N = 20,
 * P = 3 with GGX (each M^-1 9 flops fewer since it lost its disk detour, two of them square
 * roots and one a division; b includes the 30 of unpacking a VPL's normal, one square root and
 * one division among them, and none for its radiance, which is integer shifts); with
 * pi_learning 8 flops and 2 divisions more per neighbour and pass. Bytes: 116 of its own + 32 N
 * of neighbour VPLs read (each VPL once per image from memory, the rest from cache), 32
 * written: compute-bound. A pixel that does not train this frame: 36 read (20 where guiding
 * does not apply; 1 where it shares a model by the frame's decision), none written. */
#pragma OPENCL FP_CONTRACT OFF
#include "shared/guiding_pixel.h"
#include "shared/kernel_args.h"
#include "shared/pmm_train.h"
#include "shared/work_group_sum.h"
#include "wide/guiding_pixel_wide.h"
#include "wide/pmm_train_wide.h"
#include "wide/vpl_packing_wide.h"

/* The lanes' pixels x0 .. x0 + PG_LANES - 1 of row y (x0 inside the image); returns how many
 * of them changed their state. */
/* clang-format off */
static float pg_train_lanes(PG_ARGS_GBUFFER PG_ARGS_VPLS PG_ARGS_STATE
                            __global const uchar* shares_model, int x0, int y, uint width,
                            uint height, uint seed, uint frame, uint sharing_decided,
                            pg_kernel_settings settings) {
  /* clang-format on */
  int w = (int)width, row_start = y * w, apron = settings.apron, side = 2 * apron + 1;

  /* Per lane, as train.cl per work-item, loaded as vectors (kernels/wide/lanes.h): whether
   * the pixel trains, the state, its N and passes, and what it knows about itself. A lane
   * past the row's end computes on its last pixel, trains nothing and stores nothing. */
  pg_intw lane = pg_lane_numbers();
  pg_intw inside = x0 + lane < w;
  /* A lane that samples with the model of the pixel above it trains none of its own. Where this
   * frame's reproject or sample kernel decided which lanes do (include/rtpg/guiding_layout.h,
   * "Shared models"), a work-item all of whose lanes share reads nothing more; where neither
   * did, it is decided below, as train.cl decides. */
  int sharing = settings.rows_per_model > 1;
  pg_intw shares = (pg_intw)(0);
  if (sharing && sharing_decided) {
    shares = pg_load_row_flags(shares_model + row_start, x0, w);
    if (!any(inside & ~shares)) return 0.0f;
  }
  pg_float3w base_color;
  pg_floatw roughness;
  pg_load_row_float4_rows(base_color_roughness + row_start, x0, w, &base_color.x, &base_color.y,
                          &base_color.z, &roughness);
  pg_uintw pixel_flags = pg_load_row_uints(flags + row_start, x0, w);
  /* pg_guiding_applies and pg_train_this_frame per lane; the lanes share one run of
   * PG_TRAIN_RUN pixels, so the frame's rotation decides for all of them at once. */
  pg_intw active = inside & ~shares & pg_guiding_applies_w(pixel_flags, roughness, settings);
  if (!any(active)) return 0.0f;
  pg_pmm_state_w original;
  pg_load_row_float4_rows(state1 + row_start, x0, w, &original.sxx, &original.syy, &original.sxy,
                          &original.k);
  pg_floatw k = original.k;
  int run_trains =
      settings.train_interval <= 1 ||
      ((uint)x0 / PG_TRAIN_RUN + 3u * (uint)y + frame) % (uint)settings.train_interval == 0u;
  pg_intw mature = k >= 0.25f * settings.k_max;
  if (!run_trains) active &= ~mature;
  if (!any(active)) return 0.0f;
  pg_floatw metallic, specular, unused;
  pg_load_row_float4_rows(metallic_specular + row_start, x0, w, &metallic, &specular, &unused,
                          &unused);
  pg_float3w normal, view;
  pg_load_row_float4_rows(shading_normal + row_start, x0, w, &normal.x, &normal.y, &normal.z,
                          &unused);
  if (sharing && !sharing_decided) {
    active &= ~pg_shares_model_w(
        PG_PASS_GBUFFER x0, y, w,
        active & pg_model_sharable_w(pixel_flags, roughness, metallic, specular, settings), normal,
        settings);
    if (!any(active)) return 0.0f;
  }
  pg_load_row_float4_rows(state0 + row_start, x0, w, &original.w, &original.s0, &original.sx,
                          &original.sy);
  /* pg_pmm_neighbour_count, bounded by the window and the sample array. */
  pg_floatw t = clamp(1.0f - k / settings.k_max, 0.0f, 1.0f);
  pg_intw n = pg_convert_intw(t * (settings.n_max - settings.n_min) + settings.n_min + 0.5f);
  pg_intw counts =
      select((pg_intw)(0), min(n, (pg_intw)(min(side * side, PG_MAX_TRAIN_SAMPLES))), active);
  /* pg_pmm_train's passes: one for a mature pixel and for a new model (k = 0). */
  pg_intw lane_passes = select((pg_intw)(settings.em_passes), (pg_intw)(1), mature | (k <= 0.0f));
  int most_samples = pg_max_lane(counts);
  pg_intw done = ~active, updated = (pg_intw)(0);
  pg_pmm_state_w result = original;

  pg_train_pixels_w px;
  pg_load_row_float4_rows(position_depth + row_start, x0, w, &px.x.x, &px.x.y, &px.x.z, &unused);
  pg_load_row_float4_rows(view_dir + row_start, x0, w, &view.x, &view.y, &view.z, &unused);
  px.frame = pg_frame_from_normal_w(normal);
  px.wo = pg_to_local_w(px.frame, view);
  px.lobes = pg_make_lobes_w(base_color, roughness, metallic, specular, px.wo);
  int any_specular = any(active & (px.lobes.p_specular > 0.0f));
  pg_pmm_model_w m = pg_pmm_model_from_state_w(original, settings);

  /* The s-th neighbour of every lane's walk (pg_train_window_index, stepped without
   * integer division per lane). The lanes lie in one run of PG_TRAIN_RUN pixels, whose walk
   * starts in one cell (pg_train_walk_start), so their s-th neighbours are PG_LANES
   * consecutive pixels of one row: loaded as vectors and transposed where the whole segment
   * is inside the image, lane by lane at the left and right edges. Lanes not asked read no
   * VPL (info 0), as train.cl skips them. */
  pg_train_samples_w samples[PG_MAX_TRAIN_SAMPLES];
  int walk = (int)pg_train_walk_start(seed, x0, y, width, frame, settings);
  for (int s = 0; s < most_samples; ++s) {
    if (s > 0) {
      walk += settings.stride;
      if (walk >= side * side) walk -= side * side;
    }
    int dy = walk / side, sy = y + dy - apron, sx0 = x0 + (walk - dy * side) - apron;
    int row_inside = sy >= 0 && sy < (int)height;
    pg_intw sx = sx0 + lane;
    pg_intw asked_w = (s < counts) & (sx >= 0) & (sx < (int)width) & (pg_intw)(-row_inside);
    /* The VPLs' two channels as rows: position and its density as floats, the packed
     * channel's four words as integers (kernels/wide/lanes.h, pg_load_uint4_rows). A lane not
     * asked reads zeros: info 0, not a VPL. */
    pg_floatw row[4];
    pg_uintw packed[4];
    if (!row_inside) {
      for (int f = 0; f < 4; ++f) {
        row[f] = (pg_floatw)(0.0f);
        packed[f] = (pg_uintw)(0u);
      }
    } else if (sx0 >= 0 && sx0 + PG_LANES <= (int)width) {
      int j = sy * (int)width + sx0;
      pg_load_float4_rows(vpl_position + j, &row[0], &row[1], &row[2], &row[3]);
      pg_load_uint4_rows(vpl_normal_radiance + j, &packed[0], &packed[1], &packed[2], &packed[3]);
      for (int f = 0; f < 4; ++f) {
        row[f] = select((pg_floatw)(0.0f), row[f], asked_w);
        packed[f] = select((pg_uintw)(0u), packed[f], asked_w);
      }
    } else {
      int asked[PG_LANES];
      pg_vstorew(asked_w, 0, asked);
      float vpl[4][PG_LANES];
      uint words[4][PG_LANES];
      for (int l = 0; l < PG_LANES; ++l) {
        float4 position_pdf = (float4)(0.0f);
        uint4 normal_radiance = (uint4)(0u);
        if (asked[l]) {
          int j = sy * (int)width + sx0 + l;
          position_pdf = vpl_position[j];
          normal_radiance = vpl_normal_radiance[j];
        }
        pg_put4_rows(vpl, 0, l, position_pdf);
        words[0][l] = normal_radiance.x;
        words[1][l] = normal_radiance.y;
        words[2][l] = normal_radiance.z;
        words[3][l] = normal_radiance.w;
      }
      for (int f = 0; f < 4; ++f) {
        row[f] = pg_vloadw(0, vpl[f]);
        packed[f] = pg_vloadw(0, words[f]);
      }
    }
    pg_vpls_w v;
    v.position = pg_make_float3w(row[0], row[1], row[2]);
    v.position_pdf = row[3];
    v.normal = pg_unpack_unit_vector_w(packed[0]);
    v.mixture_pdf = pg_as_floatw(packed[1]);
    v.radiance = pg_vpl_radiance_w(packed[2], packed[3]);
    v.info = packed[3] >> 16;
    samples[s] = pg_train_samples_from_vpls_w(px, v, asked_w, settings, any_specular);
  }

  /* pg_pmm_train in the lanes: E-step passes over the samples, each followed by the
   * M-step and the next pass's model. A lane that pg_pmm_train would have left (no update,
   * an invalid model, its last pass) is done and keeps its result. */
  pg_pmm_state_w base = original;
  pg_floatw target = pg_convert_floatw(counts);
  /* pg_pmm_train's history weight: W of the state each lane's model comes from. */
  pg_floatw history_weight = original.w;
  for (int pass = 0; !all(done); ++pass) {
    pg_pmm_batch_w b = pg_pmm_batch_empty_w();
    pg_pmm_e_terms_w terms = pg_pmm_e_terms_of_w(m);
    for (int s = 0; s < most_samples; ++s)
      b = pg_pmm_batch_add_w(b, m, terms, settings, samples[s], history_weight);
    pg_intw live = ~done, step;
    /* A re-seed replaces the history with a new model, the batch's plain moments, which later
     * passes' responsibilities do not change: they give the same state again (spent work, at
     * most em_passes - 1 passes of a re-seeding pixel). */
    base = pg_pmm_state_select_w(base, pg_pmm_initial_state_w(),
                                 live & pg_pmm_batch_reseeds_w(b, settings));
    pg_pmm_state_w next = pg_pmm_update_w(base, b, settings, target, &step);
    updated = select(updated, step, live);
    result = pg_pmm_state_select_w(result, pg_pmm_state_select_w(original, next, step), live);
    pg_intw last = (pass + 1 >= lane_passes);
    if (all(~live | last)) break; /* no lane needs the next pass's model */
    pg_pmm_model_w next_model = pg_pmm_model_from_state_w(next, settings);
    m = pg_pmm_model_select_w(m, next_model, live & step);
    history_weight = select(history_weight, next.w, live & step);
    done |= live & (~step | ~next_model.valid | last);
  }

  float st[8][PG_LANES];
  int changed[PG_LANES];
  pg_vstorew(result.w, 0, st[0]);
  pg_vstorew(result.s0, 0, st[1]);
  pg_vstorew(result.sx, 0, st[2]);
  pg_vstorew(result.sy, 0, st[3]);
  pg_vstorew(result.sxx, 0, st[4]);
  pg_vstorew(result.syy, 0, st[5]);
  pg_vstorew(result.sxy, 0, st[6]);
  pg_vstorew(result.k, 0, st[7]);
  pg_vstorew(updated & 1, 0, changed);
  float trained = 0.0f;
  for (int l = 0; l < PG_LANES; ++l) {
    int x = x0 + l;
    if (x >= w) break;
    int i = row_start + x;
    state0[i] = (float4)(st[0][l], st[1][l], st[2][l], st[3][l]);
    state1[i] = (float4)(st[4][l], st[5][l], st[6][l], st[7][l]);
    trained += (float)changed[l];
  }
  return trained;
}

/* clang-format off */
__kernel void train_wide(PG_ARGS_GBUFFER PG_ARGS_VPLS PG_ARGS_STATE
                         __global const uchar* shares_model, __global float4* counts, uint width,
                         uint height, uint seed, uint frame, uint sharing_decided,
                         pg_kernel_settings settings, __local float4* scratch) {
  /* clang-format on */
  int x0 = (int)get_global_id(0) * PG_LANES, y = (int)get_global_id(1);
  float trained = 0.0f;
  if (x0 < (int)width && y < (int)height)
    trained = pg_train_lanes(PG_PASS_GBUFFER PG_PASS_VPLS PG_PASS_STATE shares_model, x0, y, width,
                             height, seed, frame, sharing_decided, settings);
  pg_store_work_group_counts(counts, scratch, (float4)(trained, 0.0f, 0.0f, 0.0f));
}

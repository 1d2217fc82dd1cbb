/* The train kernel (train.cl) with PG_LANES pixels of one row per work-item, in vector lanes
 * (kernels/wide/lanes.h): the variant for CPU devices, whose compilers vectorise it where they
 * cannot vectorise train.cl's per-pixel loops (docs/guiding.md, "Several pixels per
 * work-item"). The same training step, lane by lane (kernels/wide/pmm_train_wide.h): per
 * pixel, N neighbour VPLs of the (2*apron+1)^2 window turned into samples, then
 * pg_pmm_train's E-step passes and M-steps. Trip counts are the largest of the lanes; a lane
 * past its own count is masked. VPLs are read from global memory (no tile: a CPU device's
 * caches hold the window). trained[i] is 1 where the state changed. */
/* No fused multiply-adds, here or in the shared functions: the host reference runs them
 * unfused, and near the peak of a narrow GGX lobe (alpha 0.03) D's denominator is a difference
 * of nearly equal numbers, where one fused product moves D, and a sample's weight, by 1e-4
 * relative (tests/guiding/test_guiding_kernels.cpp). */
/* Per pixel (hand count; docs/guiding.md, "The roofline"): 162 + b N + 67 N P + 176 P flops for
 * N neighbours and P E-step passes (a lane runs to its work-item's largest N and P), b = 137 for
 * Lambert lobes, 243 where a lane has a GGX lobe: 1358-1888 at N = 5, P = 1; 9570 at N = 20,
 * P = 3 with GGX. Bytes: 116 of its own + 48 N of neighbour VPLs read (each VPL once per image
 * from memory, the rest from cache), 33 written: compute-bound. */
#pragma OPENCL FP_CONTRACT OFF
#include "shared/guiding_pixel.h"
#include "shared/kernel_args.h"
#include "shared/pmm_train.h"
#include "wide/pmm_train_wide.h"

/* Per-lane values in private arrays, one row of PG_LANES per field. */
enum {
  PX_X,
  PX_T = PX_X + 3,
  PX_B = PX_T + 3,
  PX_N = PX_B + 3,
  PX_WO = PX_N + 3,
  PX_DIFFUSE = PX_WO + 3,
  PX_F0 = PX_DIFFUSE + 3,
  PX_ALPHA = PX_F0 + 3,
  PX_P_SPECULAR,
  PX_FIELDS
};

/* The state of every lane from and to eight rows (pg_pmm_state's s0 then s1). */
static inline pg_pmm_state_w get_state(__private float (*rows)[PG_LANES]) {
  pg_pmm_state_w s;
  s.w = pg_vloadw(0, rows[0]);
  s.s0 = pg_vloadw(0, rows[1]);
  s.sx = pg_vloadw(0, rows[2]);
  s.sy = pg_vloadw(0, rows[3]);
  s.sxx = pg_vloadw(0, rows[4]);
  s.syy = pg_vloadw(0, rows[5]);
  s.sxy = pg_vloadw(0, rows[6]);
  s.k = pg_vloadw(0, rows[7]);
  return s;
}

static inline void put_state(__private float (*rows)[PG_LANES], pg_pmm_state_w s) {
  pg_vstorew(s.w, 0, rows[0]);
  pg_vstorew(s.s0, 0, rows[1]);
  pg_vstorew(s.sx, 0, rows[2]);
  pg_vstorew(s.sy, 0, rows[3]);
  pg_vstorew(s.sxx, 0, rows[4]);
  pg_vstorew(s.syy, 0, rows[5]);
  pg_vstorew(s.sxy, 0, rows[6]);
  pg_vstorew(s.k, 0, rows[7]);
}

__kernel void train_wide(
    PG_ARGS_GBUFFER PG_ARGS_VPLS PG_ARGS_IN_STATE PG_ARGS_OUT_STATE __global uchar* trained,
    uint width, uint height, uint seed, uint frame, pg_kernel_settings settings) {
  int x0 = (int)get_global_id(0) * PG_LANES, y = (int)get_global_id(1);
  if (x0 >= (int)width || y >= (int)height) return;
  int apron = settings.apron, side = 2 * apron + 1;

  /* Per lane, as train.cl per work-item: the state, whether the pixel trains, its N, the
   * start of its walk through the window, and what it knows about itself. */
  float pixel[PX_FIELDS][PG_LANES], state[8][PG_LANES];
  int active[PG_LANES], count[PG_LANES], passes[PG_LANES], changed[PG_LANES];
  int lane_index[PG_LANES];
  int any_active = 0, any_specular = 0, most_samples = 0;
  for (int l = 0; l < PG_LANES; ++l) {
    for (int f = 0; f < PX_FIELDS; ++f) pixel[f][l] = 0.0f;
    for (int f = 0; f < 8; ++f) state[f][l] = 0.0f;
    active[l] = 0;
    changed[l] = 0;
    count[l] = 0;
    passes[l] = 0;
    lane_index[l] = l;
    int x = x0 + l;
    if (x >= (int)width) continue;
    int i = y * (int)width + x;
    float4 s0 = in_state0[i], s1 = in_state1[i];
    state[0][l] = s0.x;
    state[1][l] = s0.y;
    state[2][l] = s0.z;
    state[3][l] = s0.w;
    state[4][l] = s1.x;
    state[5][l] = s1.y;
    state[6][l] = s1.z;
    state[7][l] = s1.w;
    float4 bcr = base_color_roughness[i];
    if (!pg_guiding_applies(flags[i], bcr.w, settings) ||
        !pg_train_this_frame(s1.w, x, y, frame, settings))
      continue;
    active[l] = 1;
    any_active = 1;
    pg_frame frame_l = pg_frame_from_normal(shading_normal[i].xyz);
    float3 wo = pg_to_local(frame_l, view_dir[i].xyz);
    pg_lobes lobes = pg_make_lobes(pg_material_from_gbuffer(bcr, metallic_specular[i]), wo);
    pg_put3_rows(pixel, PX_X, l, position_depth[i].xyz);
    pg_put3_rows(pixel, PX_T, l, frame_l.t);
    pg_put3_rows(pixel, PX_B, l, frame_l.b);
    pg_put3_rows(pixel, PX_N, l, frame_l.n);
    pg_put3_rows(pixel, PX_WO, l, wo);
    pg_put3_rows(pixel, PX_DIFFUSE, l, lobes.diffuse);
    pg_put3_rows(pixel, PX_F0, l, lobes.f0);
    pixel[PX_ALPHA][l] = lobes.alpha;
    pixel[PX_P_SPECULAR][l] = lobes.p_specular;
    any_specular |= lobes.p_specular > 0.0f;
    count[l] = min(min(pg_pmm_neighbour_count(s1.w, settings), side * side), PG_MAX_TRAIN_SAMPLES);
    most_samples = max(most_samples, count[l]);
    passes[l] = s1.w >= 0.25f * settings.k_max ? 1 : settings.em_passes;
  }

  if (any_active) {
    pg_train_pixels_w px;
    px.x = pg_get3_rows(pixel, PX_X);
    px.frame.t = pg_get3_rows(pixel, PX_T);
    px.frame.b = pg_get3_rows(pixel, PX_B);
    px.frame.n = pg_get3_rows(pixel, PX_N);
    px.wo = pg_get3_rows(pixel, PX_WO);
    px.lobes.diffuse = pg_get3_rows(pixel, PX_DIFFUSE);
    px.lobes.f0 = pg_get3_rows(pixel, PX_F0);
    px.lobes.alpha = pg_vloadw(0, pixel[PX_ALPHA]);
    px.lobes.p_specular = pg_vloadw(0, pixel[PX_P_SPECULAR]);

    /* The s-th neighbour of every lane's walk (pg_train_window_index, stepped without
     * integer division per lane). The lanes lie in one run of PG_TRAIN_RUN pixels, whose walk
     * starts in one cell (pg_train_walk_start), so their s-th neighbours are PG_LANES
     * consecutive pixels of one row: loaded as vectors and transposed where the whole segment
     * is inside the image, lane by lane at the left and right edges. Lanes not asked read no
     * VPL (info 0), as train.cl skips them. */
    pg_train_samples_w samples[PG_MAX_TRAIN_SAMPLES];
    pg_intw lane = pg_vloadw(0, lane_index), counts = pg_vloadw(0, count);
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
      pg_floatw row[12];
      if (!row_inside) {
        for (int f = 0; f < 12; ++f) row[f] = (pg_floatw)(0.0f);
      } else if (sx0 >= 0 && sx0 + PG_LANES <= (int)width) {
        int j = sy * (int)width + sx0;
        pg_load_float4_rows(vpl_position + j, &row[0], &row[1], &row[2], &row[3]);
        pg_load_float4_rows(vpl_normal + j, &row[4], &row[5], &row[6], &row[7]);
        pg_load_float4_rows(vpl_radiance_info + j, &row[8], &row[9], &row[10], &row[11]);
        for (int f = 0; f < 12; ++f) row[f] = select((pg_floatw)(0.0f), row[f], asked_w);
      } else {
        int asked[PG_LANES];
        pg_vstorew(asked_w, 0, asked);
        float vpl[12][PG_LANES];
        for (int l = 0; l < PG_LANES; ++l) {
          float4 position_pdf = (float4)(0.0f), normal = (float4)(0.0f);
          float4 radiance_info = (float4)(0.0f); /* info 0: not a VPL */
          if (asked[l]) {
            int j = sy * (int)width + sx0 + l;
            position_pdf = vpl_position[j];
            normal = vpl_normal[j];
            radiance_info = vpl_radiance_info[j];
          }
          vpl[0][l] = position_pdf.x;
          vpl[1][l] = position_pdf.y;
          vpl[2][l] = position_pdf.z;
          vpl[3][l] = position_pdf.w;
          vpl[4][l] = normal.x;
          vpl[5][l] = normal.y;
          vpl[6][l] = normal.z;
          vpl[7][l] = normal.w;
          vpl[8][l] = radiance_info.x;
          vpl[9][l] = radiance_info.y;
          vpl[10][l] = radiance_info.z;
          vpl[11][l] = radiance_info.w;
        }
        for (int f = 0; f < 12; ++f) row[f] = pg_vloadw(0, vpl[f]);
      }
      pg_vpls_w v;
      v.position = pg_make_float3w(row[0], row[1], row[2]);
      v.position_pdf = row[3];
      v.normal = pg_make_float3w(row[4], row[5], row[6]);
      v.mixture_pdf = row[7];
      v.radiance = pg_make_float3w(row[8], row[9], row[10]);
      v.info = row[11];
      samples[s] = pg_train_samples_from_vpls_w(px, v, asked_w, settings, any_specular);
    }

    /* pg_pmm_train in the lanes: E-step passes over the samples, each followed by the
     * M-step and the next pass's model. A lane that pg_pmm_train would have left (no update,
     * an invalid model, its last pass) is done and keeps its result. */
    pg_pmm_state_w original = get_state(state), base = original, result = original;
    pg_pmm_model_w m = pg_pmm_model_from_state_w(original, settings);
    pg_intw lane_passes = pg_vloadw(0, passes);
    pg_intw done = pg_vloadw(0, active) == 0, updated = (pg_intw)(0);
    pg_floatw target = pg_convert_floatw(counts);
    for (int pass = 0; !all(done); ++pass) {
      pg_pmm_batch_w b = pg_pmm_batch_empty_w();
      for (int s = 0; s < most_samples; ++s)
        b = pg_pmm_batch_add_w(b, m, settings, samples[s], original.w);
      pg_intw live = ~done, step;
      /* A re-seed replaces the history: later passes refine the new model alone. */
      base = pg_pmm_state_select_w(base, pg_pmm_initial_state_w(), live & b.reseed);
      pg_pmm_state_w next = pg_pmm_update_w(base, b, settings, target, &step);
      updated = select(updated, step, live);
      result = pg_pmm_state_select_w(result, pg_pmm_state_select_w(original, next, step), live);
      pg_intw last = (pass + 1 >= lane_passes);
      if (all(~live | last)) break; /* no lane needs the next pass's model */
      pg_pmm_model_w next_model = pg_pmm_model_from_state_w(next, settings);
      m = pg_pmm_model_select_w(m, next_model, live & step);
      done |= live & (~step | ~next_model.valid | last);
    }
    put_state(state, result);
    pg_vstorew(updated & 1, 0, changed);
  }

  for (int l = 0; l < PG_LANES; ++l) {
    int x = x0 + l;
    if (x >= (int)width) break;
    int i = y * (int)width + x;
    out_state0[i] = (float4)(state[0][l], state[1][l], state[2][l], state[3][l]);
    out_state1[i] = (float4)(state[4][l], state[5][l], state[6][l], state[7][l]);
    trained[i] = (uchar)changed[l];
  }
}

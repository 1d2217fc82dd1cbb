/* Online EM training of every pixel's mixture from the VPLs of its neighbourhood (paper 3.2,
 * 4.2). Built in two variants (build option PG_TRAIN_LOCAL_TILE): 1 loads the work-group's
 * VPL tile plus an apron of `apron` pixels into local memory first (what GPUs need); 0 reads
 * the same VPLs straight from global memory (faster on PoCL's CPU device, docs/guiding.md).
 * Both give identical results. The work-group's record counts the pixels whose state changed
 * (include/rtpg/guiding_layout.h, "Counts"). The state is updated in place: a pixel reads and
 * writes only its own, so a pixel that does not train this frame (no guiding, or a mature pixel off
 * its turn) reads its flags, roughness and k and writes nothing (docs/guiding.md, "Training in
 * place; row loads inlined"). */
#include "shared/kernel_args.h"
#include "shared/pmm_train.h"
#include "shared/work_group_sum.h"

#ifndef PG_TRAIN_LOCAL_TILE
#define PG_TRAIN_LOCAL_TILE 1
#endif

/* Pixel (x, y) inside the image, its window's VPLs in the tile (PG_TRAIN_LOCAL_TILE 1) or in
 * global memory; returns 1 where its state changed. */
/* clang-format off */
static int pg_train_pixel_at(PG_ARGS_GBUFFER PG_ARGS_VPLS PG_ARGS_STATE
                             __global const uchar* shares_model, int x, int y, uint width,
                             uint height, uint seed, uint frame, uint sharing_decided,
                             pg_kernel_settings settings, __local const float4* tile_position,
                             __local const uint4* tile_normal_radiance) {
  /* clang-format on */
  int apron = settings.apron;
#if PG_TRAIN_LOCAL_TILE
  int tw = (int)get_local_size(0) + 2 * apron;
#endif
  int i = y * (int)width + x;
  /* A pixel that samples with the model of the pixel above it trains none of its own: as this
   * frame's reproject or sample kernel decided (include/rtpg/guiding_layout.h, "Shared
   * models"), read first, or, where neither did, decided here. */
  int sharing = settings.rows_per_model > 1;
  if (sharing && sharing_decided && shares_model[i] != 0) return 0;
  float4 bcr = base_color_roughness[i];
  if (!pg_guiding_applies(flags[i], bcr.w, settings)) return 0;
  if (!pg_train_this_frame(state1[i].w, x, y, frame, settings)) return 0;
  uint column = (uint)x, row = (uint)y;
  if (sharing && !sharing_decided &&
      pg_model_pixel(PG_PASS_GBUFFER column, row, width, settings) != (uint)i)
    return 0;
  pg_pmm_state state;
  state.s0 = state0[i];
  state.s1 = state1[i];
  pg_train_pixel px;
  px.x = position_depth[i].xyz;
  px.frame = pg_frame_from_normal(shading_normal[i].xyz);
  px.wo = pg_to_local(px.frame, view_dir[i].xyz);
  px.lobes = pg_make_lobes(pg_material_from_gbuffer(bcr, metallic_specular[i]), px.wo);
  int side = 2 * apron + 1;
  int n = min(min(pg_pmm_neighbour_count(state.s1.w, settings), side * side), PG_MAX_TRAIN_SAMPLES);
  uint start = pg_train_walk_start(seed, x, y, width, frame, settings);
  float4 samples[PG_MAX_TRAIN_SAMPLES];
  float densities[PG_MAX_TRAIN_SAMPLES];
  int kept = 0;
  for (int s = 0; s < n; ++s) {
    int w = pg_train_window_index(start, s, settings);
    int dx = w % side - apron, dy = w / side - apron;
#if PG_TRAIN_LOCAL_TILE
    int t = ((int)get_local_id(1) + apron + dy) * tw + (int)get_local_id(0) + apron + dx;
    kept += pg_train_sample_from_vpl(px, tile_position[t], tile_normal_radiance[t], settings,
                                     &samples[kept], &densities[kept]);
#else
    int sx = x + dx, sy = y + dy;
    if (sx < 0 || sy < 0 || sx >= (int)width || sy >= (int)height) continue;
    int j = sy * (int)width + sx;
    kept += pg_train_sample_from_vpl(px, vpl_position[j], vpl_normal_radiance[j], settings,
                                     &samples[kept], &densities[kept]);
#endif
  }
  int updated = 0;
  state = pg_pmm_train(state, samples, densities, kept, settings, (float)n, settings.em_passes,
                       &updated);
  state0[i] = state.s0;
  state1[i] = state.s1;
  return updated;
}

__kernel void train(PG_ARGS_GBUFFER PG_ARGS_VPLS PG_ARGS_STATE __global const uchar* shares_model,
                    __global float4* counts, uint width, uint height, uint seed, uint frame,
                    uint sharing_decided, pg_kernel_settings settings,
                    __local float4* tile_position, __local uint4* tile_normal_radiance,
                    __local float4* scratch) {
  int x = (int)get_global_id(0), y = (int)get_global_id(1);
#if PG_TRAIN_LOCAL_TILE
  int apron = settings.apron;
  int lw = (int)get_local_size(0), lh = (int)get_local_size(1);
  int tw = lw + 2 * apron, th = lh + 2 * apron;
  int ox = (int)(get_group_id(0) * get_local_size(0)) - apron;
  int oy = (int)(get_group_id(1) * get_local_size(1)) - apron;
  for (int t = (int)(get_local_id(1) * get_local_size(0) + get_local_id(0)); t < tw * th;
       t += lw * lh) {
    int sx = ox + t % tw, sy = oy + t / tw;
    if (sx >= 0 && sy >= 0 && sx < (int)width && sy < (int)height) {
      int j = sy * (int)width + sx;
      tile_position[t] = vpl_position[j];
      tile_normal_radiance[t] = vpl_normal_radiance[j];
    } else {
      tile_position[t] = (float4)(0.0f);
      tile_normal_radiance[t] = (uint4)(0u); /* info 0: not a VPL */
    }
  }
  barrier(CLK_LOCAL_MEM_FENCE);
#endif
  float trained = 0.0f;
  if (x < (int)width && y < (int)height)
    trained = (float)pg_train_pixel_at(PG_PASS_GBUFFER PG_PASS_VPLS PG_PASS_STATE shares_model, x,
                                       y, width, height, seed, frame, sharing_decided, settings,
                                       tile_position, tile_normal_radiance);
  pg_store_work_group_counts(counts, scratch, (float4)(trained, 0.0f, 0.0f, 0.0f));
}

/* Guiding state of the previous frame -> this frame (paper 3.1): nearest-neighbour fetch
 * through the motion vector, rejected on position (depth), normal and material differences
 * (pg_same_surface, as SVGF does) unless one of that pixel's eight neighbours passes
 * (pg_history_candidate), and carried into this pixel's hemisphere frame when the
 * normals differ; under a moving camera a glossy pixel's model ages as its view turns
 * (pg_pmm_view_aged_k). Rejected, disoccluded and skipped pixels restart from the initial
 * state (k = 0). */
/* Per pixel (hand count; rules and roofline: docs/guiding.md, "The roofline"): 78 flops (2
 * divisions, 1 sqrt) where history is kept, 420 more (13 divisions, 6 sqrt; M's cos and sin by
 * polynomials, kernels/shared/sincos.h, 3 x 16 flops) where the state is reframed, about 72 more
 * (the lobes, two lengths, an atan2, an exp, a division) and 48 bytes more read where a model ages
 * (reproject_view_memory > 0); 132 bytes read, 32 written: memory-bound. Where the pixel the motion
 * vector lands on fails the history test, each further candidate costs about 20 flops and 36 bytes
 * (mostly from cache). With rows_per_model > 1 every guided pixel outside a group's first row
 * also costs the sharing test, about 30 flops and 80 bytes of the model pixel's G-buffer, from
 * cache, and every pixel writes its 1-byte decision; a pixel that shares writes nothing else. */
#include "shared/guiding_pixel.h"
#include "shared/kernel_args.h"
#include "shared/pmm.h"

/* clang-format off */
__kernel void reproject(PG_ARGS_GBUFFER PG_ARGS_PREV_GBUFFER PG_ARGS_IN_STATE PG_ARGS_OUT_STATE
                        __global uchar* shares_model, uint width, uint height,
                        pg_kernel_settings settings) {
  /* clang-format on */
  uint x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  uint i = y * width + x;
  pg_pmm_state out = pg_pmm_initial_state();
  int guided = pg_guiding_applies(flags[i], base_color_roughness[i].w, settings);
  /* The frame's first kernel: it decides which pixels share their group's model for the
   * frame's sample and train kernels (include/rtpg/guiding_layout.h, "Shared models"); a pixel
   * guiding skips shares none. */
  if (settings.rows_per_model > 1 && !guided) shares_model[i] = 0;
  if (guided) {
    /* A pixel that shares the model of the pixel above it (pg_shares_model) gets that model's
     * state from the sample kernel, which reads the decision made here: its own would be
     * overwritten unread, so it is neither carried nor written (docs/guiding.md, "Reprojection
     * left to the sample kernel where a model is shared"). */
    if (pg_frame_model_pixel(PG_PASS_GBUFFER shares_model, 0u, 1, x, y, width, settings) != i)
      return;
    float2 mv = motion[i];
    int px = (int)floor((float)x + 0.5f + mv.x);
    int py = (int)floor((float)y + 0.5f + mv.y);
    float3 n = pg_float4_xyz(shading_normal[i]), m = (float3)(0.0f);
    int found = 0;
    uint j = 0;
    for (int t = 0; t < PG_HISTORY_CANDIDATES && !found; ++t) {
      int dx, dy;
      pg_history_candidate(t, &dx, &dy);
      int qx = px + dx, qy = py + dy;
      if (qx < 0 || qy < 0 || qx >= (int)width || qy >= (int)height) continue;
      j = (uint)qy * width + (uint)qx;
      m = pg_float4_xyz(prev_shading_normal[j]);
      found =
          pg_same_surface(position_depth[i], n, material[i], prev_position_depth[j], m,
                          prev_material[j], settings.reproject_position, settings.reproject_normal);
    }
    if (found) {
      pg_pmm_state s;
      s.s0 = in_state0[j];
      s.s1 = in_state1[j];
      pg_frame from = pg_frame_from_normal(m), to = pg_frame_from_normal(n);
      if (pg_pmm_needs_reframe(from, to)) s = pg_pmm_reframe(s, from, to);
      /* A still camera has motion exactly 0 (docs/design.md); its view directions differ
       * only by the sub-pixel jitter, which is no change of view. */
      if (mv.x != 0.0f || mv.y != 0.0f)
        s.s1.w = pg_pmm_view_aged_k(
            s.s1.w, pg_float4_xyz(view_dir[i]), pg_float4_xyz(prev_view_dir[j]),
            pg_material_from_gbuffer(base_color_roughness[i], metallic_specular[i]),
            settings.reproject_view_memory);
      if (pg_pmm_state_finite(s)) out = s;
    }
  }
  out_state0[i] = out.s0;
  out_state1[i] = out.s1;
}

/* Guiding state of the previous frame -> this frame (paper 3.1): nearest-neighbour fetch
 * through the motion vector, rejected on position (depth), normal and material differences
 * (as SVGF does), and carried into this pixel's hemisphere frame when the normals differ.
 * Rejected, disoccluded and skipped pixels restart from the initial state (k = 0). */
#include "shared/guiding_pixel.h"
#include "shared/pmm.h"

__kernel void reproject(__global const float4* prev_state0, __global const float4* prev_state1,
                        __global const float4* prev_position_depth,
                        __global const float4* prev_shading_normal,
                        __global const uint* prev_material, __global float4* state0,
                        __global float4* state1, __global const float4* position_depth,
                        __global const float4* shading_normal,
                        __global const float4* base_color_roughness, __global const uint* flags,
                        __global const uint* material, __global const float2* motion, uint width,
                        uint height, pg_guiding_params params) {
  uint x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  uint i = y * width + x;
  pg_pmm_state out = pg_pmm_initial_state();
  if (pg_guiding_applies(flags[i], base_color_roughness[i].w, params)) {
    float2 mv = motion[i];
    int px = (int)floor((float)x + 0.5f + mv.x);
    int py = (int)floor((float)y + 0.5f + mv.y);
    if (px >= 0 && py >= 0 && px < (int)width && py < (int)height) {
      uint j = (uint)py * width + (uint)px;
      float4 p = position_depth[i], q = prev_position_depth[j];
      float3 n = pg_float4_xyz(shading_normal[i]), m = pg_float4_xyz(prev_shading_normal[j]);
      float3 d = pg_float4_xyz(p) - pg_float4_xyz(q);
      int same_surface = sqrt(dot(d, d)) <= params.reproject_depth * fmax(p.w, 1e-6f) &&
                         dot(n, m) >= params.reproject_normal && prev_material[j] == material[i] &&
                         q.w > 0.0f;
      if (same_surface) {
        pg_pmm_state s;
        s.s0 = prev_state0[j];
        s.s1 = prev_state1[j];
        pg_frame from = pg_frame_from_normal(m), to = pg_frame_from_normal(n);
        if (pg_pmm_needs_reframe(from, to)) s = pg_pmm_reframe(s, from, to);
        if (pg_pmm_state_finite(s)) out = s;
      }
    }
  }
  state0[i] = out.s0;
  state1[i] = out.s1;
}

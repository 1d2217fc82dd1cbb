/* The history test of reprojection, shared by guiding (kernels/reproject.cl, the path tracer's
 * borrowed mixtures) and the denoiser (kernels/svgf_temporal.cl), so both keep history on
 * exactly the same pixels. */
#ifndef RTPG_SHARED_SAME_SURFACE_H
#define RTPG_SHARED_SAME_SURFACE_H

#include "shared/compat.h"

PG_NAMESPACE_BEGIN

/* Does last frame's pixel (prev_*) show the same surface as this one (paper 3.1; the tests
 * of SVGF)? Same material, a position within max_relative_distance of this pixel's depth,
 * normals at least min_normal_cos apart, and a surface at all (depth > 0) in both; no
 * absolute length anywhere, so the test does not depend on the scene's unit. Reprojection keeps
 * history only where this holds. */
PG_FN int pg_same_surface(float4 position_depth, float3 normal, uint material,
                          float4 prev_position_depth, float3 prev_normal, uint prev_material,
                          float max_relative_distance, float min_normal_cos) {
  float3 d = pg_float4_xyz(position_depth) - pg_float4_xyz(prev_position_depth);
  return position_depth.w > 0.0f && sqrt(dot(d, d)) <= max_relative_distance * position_depth.w &&
         dot(normal, prev_normal) >= min_normal_cos && prev_material == material &&
         prev_position_depth.w > 0.0f;
}

/* Where guiding's reprojection looks for last frame's pixel showing this pixel's surface, t = 0
 * .. PG_HISTORY_CANDIDATES - 1, first match wins: the pixel the motion vector lands on, then its
 * four edge neighbours, then its diagonal ones. The camera's sub-pixel jitter makes a pixel on a
 * geometric edge see one surface in one frame and the other in the next; the nearest pixel alone
 * would reject its history every frame there (docs/guiding.md, "History from the neighbourhood").
 */
#define PG_HISTORY_CANDIDATES 9
PG_FN void pg_history_candidate(int t, PG_PRIVATE int* dx, PG_PRIVATE int* dy) {
  if (t == 0) {
    *dx = 0;
    *dy = 0;
  } else if (t <= 4) { /* (0,-1), (-1,0), (1,0), (0,1) */
    *dx = t == 2 ? -1 : (t == 3 ? 1 : 0);
    *dy = t == 1 ? -1 : (t == 4 ? 1 : 0);
  } else { /* (-1,-1), (1,-1), (-1,1), (1,1) */
    *dx = ((t - 5) & 1) != 0 ? 1 : -1;
    *dy = ((t - 5) & 2) != 0 ? 1 : -1;
  }
}

PG_NAMESPACE_END

#endif

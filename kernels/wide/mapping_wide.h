/* The mappings of kernels/shared/mapping.h and the hemisphere frame of kernels/shared/compat.h
 * for PG_LANES directions at once (kernels/wide/lanes.h), operation for operation as the
 * scalar functions named on each. OpenCL C only. */
#ifndef RTPG_WIDE_MAPPING_WIDE_H
#define RTPG_WIDE_MAPPING_WIDE_H

#include "shared/compat.h"
#include "wide/lanes.h"
#include "wide/sincos_wide.h"

/* pg_frame per lane (pg_frame_from_normal: Duff et al. 2017). */
typedef struct {
  pg_float3w t, b, n;
} pg_frame_w;

static inline pg_frame_w pg_frame_from_normal_w(pg_float3w n) {
  pg_floatw s = copysign((pg_floatw)(1.0f), n.z);
  pg_floatw a = -1.0f / (s + n.z);
  pg_floatw b = n.x * n.y * a;
  pg_frame_w f;
  f.t = pg_make_float3w(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
  f.b = pg_make_float3w(b, s + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}

static inline pg_float3w pg_to_local_w(pg_frame_w f, pg_float3w v) {
  return pg_make_float3w(pg_dot3w(v, f.t), pg_dot3w(v, f.b), pg_dot3w(v, f.n));
}

static inline pg_float3w pg_to_world_w(pg_frame_w f, pg_float3w v) {
  return pg_add3w(pg_add3w(pg_scale3w(f.t, v.x), pg_scale3w(f.b, v.y)), pg_scale3w(f.n, v.z));
}

/* pg_square_to_disk (Shirley and Chiu 1997); *dx, *dy the point of the disk. */
static inline void pg_square_to_disk_w(pg_floatw ux, pg_floatw uy, __private pg_floatw* dx,
                                       __private pg_floatw* dy) {
  pg_floatw ox = 2.0f * ux - 1.0f, oy = 2.0f * uy - 1.0f;
  pg_intw wide_x = fabs(ox) > fabs(oy);
  pg_floatw r = select(oy, ox, wide_x);
  /* theta = a in the wide-x wedges, else pi/2 - a (cos theta = sin a, sin theta = cos a). */
  pg_floatw c, s;
  pg_cos_sin_octant_w(select((PG_PI / 4.0f) * (ox / oy), (PG_PI / 4.0f) * (oy / ox), wide_x), &c,
                      &s);
  pg_intw centre = (ox == 0.0f) & (oy == 0.0f);
  *dx = select(r * select(s, c, wide_x), (pg_floatw)(0.0f), centre);
  *dy = select(r * select(c, s, wide_x), (pg_floatw)(0.0f), centre);
}

/* M (pg_square_to_hemisphere): square -> hemisphere, equal-area. */
static inline pg_float3w pg_square_to_hemisphere_w(pg_floatw ux, pg_floatw uy) {
  pg_floatw dx, dy;
  pg_square_to_disk_w(ux, uy, &dx, &dy);
  pg_floatw r2 = dx * dx + dy * dy;
  pg_floatw s = sqrt(fmax(2.0f - r2, 0.0f));
  return pg_make_float3w(dx * s, dy * s, 1.0f - r2);
}

/* M^-1 (pg_hemisphere_to_square) for w.z >= 0. */
static inline void pg_hemisphere_to_square_w(pg_float3w w, __private pg_floatw* ux,
                                             __private pg_floatw* uy) {
  pg_floatw r = sqrt(clamp(1.0f - w.z, 0.0f, 1.0f));
  /* The wedge |x| >= |y| takes its radius from x and its angle from y / x; the other wedge
   * swaps the roles. */
  pg_intw swap = fabs(w.x) < fabs(w.y);
  pg_floatw p = select(w.x, w.y, swap), q = select(w.y, w.x, swap);
  pg_floatw radius = select(-r, r, p > 0.0f);
  /* pg_atan_unit's polynomial. */
  pg_floatw z = q / p, z2 = z * z;
  pg_floatw t = 0.0028662257f;
  t = t * z2 - 0.0161657367f;
  t = t * z2 + 0.0429096138f;
  t = t * z2 - 0.0752896400f;
  t = t * z2 + 0.1065626393f;
  t = t * z2 - 0.1420889944f;
  t = t * z2 + 0.1999355085f;
  t = t * z2 - 0.3333314528f;
  pg_floatw angle = radius * (z + z * z2 * t) * (4.0f / PG_PI);
  pg_floatw a = select(radius, angle, swap), b = select(angle, radius, swap);
  pg_intw centre = (r == 0.0f) | ((w.x == 0.0f) & (w.y == 0.0f));
  *ux = select(clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), (pg_floatw)(0.5f), centre);
  *uy = select(clamp(0.5f * (b + 1.0f), 0.0f, 1.0f), (pg_floatw)(0.5f), centre);
}

/* pg_sample_cosine_hemisphere (Malley's method). */
static inline pg_float3w pg_sample_cosine_hemisphere_w(pg_floatw u1, pg_floatw u2) {
  pg_floatw dx, dy;
  pg_square_to_disk_w(u1, u2, &dx, &dy);
  return pg_make_float3w(dx, dy, sqrt(fmax(1.0f - dx * dx - dy * dy, 0.0f)));
}

#endif

/* The Shirley-Chiu concentric map and the equal-area lift between the unit square and the
 * hemisphere (paper, eq. 2: the mapping M). M is area preserving up to the constant 2*pi:
 * a density p_u on [0,1]^2 becomes p_omega(w) = p_u(M^-1(w)) / (2*pi) on the hemisphere.
 * The same concentric map gives cosine-weighted sampling for the Lambert lobe. */
#ifndef RTPG_SHARED_MAPPING_H
#define RTPG_SHARED_MAPPING_H

#include "shared/compat.h"
#include "shared/sincos.h"

PG_NAMESPACE_BEGIN

/* Shirley and Chiu 1997, in the form of pbrt-v4's SampleUniformDiskConcentric. */
PG_FN float2 pg_square_to_disk(float2 u) {
  float ox = 2.0f * u.x - 1.0f;
  float oy = 2.0f * u.y - 1.0f;
  if (ox == 0.0f && oy == 0.0f) return pg_make_float2(0.0f, 0.0f);
  if (fabs(ox) > fabs(oy)) {
    /* theta = (pi/4) oy / ox */
    float2 cs = pg_cos_sin_octant((PG_PI / 4.0f) * (oy / ox));
    return pg_make_float2(ox * cs.x, ox * cs.y);
  }
  /* theta = pi/2 - a with a = (pi/4) ox / oy: cos theta = sin a, sin theta = cos a */
  float2 cs = pg_cos_sin_octant((PG_PI / 4.0f) * (ox / oy));
  return pg_make_float2(oy * cs.y, oy * cs.x);
}

/* atan(z) for |z| <= 1 by the polynomial of Abramowitz and Stegun 4.4.49 (|error| <= 2e-8):
 * a handful of FMAs instead of a library atan2, which dominated the training kernel. */
PG_FN float pg_atan_unit(float z) {
  float z2 = z * z;
  float p = 0.0028662257f;
  p = p * z2 - 0.0161657367f;
  p = p * z2 + 0.0429096138f;
  p = p * z2 - 0.0752896400f;
  p = p * z2 + 0.1065626393f;
  p = p * z2 - 0.1420889944f;
  p = p * z2 + 0.1999355085f;
  p = p * z2 - 0.3333314528f;
  return z + z * z2 * p;
}

/* M: square -> hemisphere (z up), equal-area: z = 1 - r^2, xy scaled by sqrt(2 - r^2). */
PG_FN float3 pg_square_to_hemisphere(float2 u) {
  float2 d = pg_square_to_disk(u);
  float r2 = d.x * d.x + d.y * d.y;
  float s = pg_safe_sqrt(2.0f - r2);
  return pg_make_float3(d.x * s, d.y * s, 1.0f - r2);
}

/* M^-1 for directions with z >= 0 (callers check the hemisphere). The lift scales the disk
 * point d by sqrt(2 - r^2) and z = 1 - r^2, so the disk radius is sqrt(1 - z) and d points
 * along (x, y): the wedge and the angle come from w itself, and no square root of x^2 + y^2 is
 * needed. Inverse of pg_square_to_disk: in the wedges where |x| >= |y| the forward map has
 * d = o_x (cos t, sin t) with t = (pi/4) o_y / o_x, so t = atan(y / x); in the others
 * t' = pi/2 - t = atan(x / y) with o_y the radius. */
PG_FN float2 pg_hemisphere_to_square(float3 w) {
  float r = sqrt(clamp(1.0f - w.z, 0.0f, 1.0f));
  if (r == 0.0f || (w.x == 0.0f && w.y == 0.0f)) return pg_make_float2(0.5f, 0.5f);
  float a, b;
  if (fabs(w.x) >= fabs(w.y)) {
    a = w.x > 0.0f ? r : -r;
    b = a * pg_atan_unit(w.y / w.x) * (4.0f / PG_PI);
  } else {
    b = w.y > 0.0f ? r : -r;
    a = b * pg_atan_unit(w.x / w.y) * (4.0f / PG_PI);
  }
  return pg_make_float2(clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), clamp(0.5f * (b + 1.0f), 0.0f, 1.0f));
}

/* M and its partial derivatives along u.x and u.y (*dx, *dy), for carrying a Gaussian's
 * covariance through a change of frame (pg_pmm_reframe). The point is computed by the same
 * operations as pg_square_to_hemisphere. Returns 0 at the square's centre, where the concentric
 * map has no derivative (the same point, w = (0, 0, 1)). In the wedge |ox| > |oy| the disk point is
 * ox (cos t, sin t) with t = (pi/4) q, q = oy / ox, so d/dox = (cos t + (pi/4) q sin t, sin t -
 * (pi/4) q cos t) and d/doy = (pi/4) (-sin t, cos t); the other wedge mirrors it; ox = 2 u.x - 1
 * adds a factor 2. The lift (d s, 1 - r^2), s = sqrt(2 - r^2), has ds/dd = -d / s. */
PG_FN int pg_square_to_hemisphere_d(float2 u, PG_PRIVATE float3* w, PG_PRIVATE float3* dx,
                                    PG_PRIVATE float3* dy) {
  float ox = 2.0f * u.x - 1.0f;
  float oy = 2.0f * u.y - 1.0f;
  if (ox == 0.0f && oy == 0.0f) {
    *w = pg_make_float3(0.0f, 0.0f, 1.0f);
    return 0;
  }
  float2 d, d_ox, d_oy; /* the disk point and its derivatives along ox and oy */
  if (fabs(ox) > fabs(oy)) {
    float q = oy / ox;
    float2 cs = pg_cos_sin_octant((PG_PI / 4.0f) * q);
    d = pg_make_float2(ox * cs.x, ox * cs.y);
    d_ox = pg_make_float2(cs.x + (PG_PI / 4.0f) * q * cs.y, cs.y - (PG_PI / 4.0f) * q * cs.x);
    d_oy = pg_make_float2(-(PG_PI / 4.0f) * cs.y, (PG_PI / 4.0f) * cs.x);
  } else {
    float q = ox / oy;
    float2 cs = pg_cos_sin_octant((PG_PI / 4.0f) * q);
    d = pg_make_float2(oy * cs.y, oy * cs.x);
    d_ox = pg_make_float2((PG_PI / 4.0f) * cs.x, -(PG_PI / 4.0f) * cs.y);
    d_oy = pg_make_float2(cs.y - (PG_PI / 4.0f) * q * cs.x, cs.x + (PG_PI / 4.0f) * q * cs.y);
  }
  float r2 = d.x * d.x + d.y * d.y;
  float s = pg_safe_sqrt(2.0f - r2); /* at least 1 on the disk */
  *w = pg_make_float3(d.x * s, d.y * s, 1.0f - r2);
  float3 w_dx = pg_make_float3(s - d.x * d.x / s, -d.x * d.y / s, -2.0f * d.x);
  float3 w_dy = pg_make_float3(-d.x * d.y / s, s - d.y * d.y / s, -2.0f * d.y);
  *dx = (w_dx * d_ox.x + w_dy * d_ox.y) * 2.0f;
  *dy = (w_dx * d_oy.x + w_dy * d_oy.y) * 2.0f;
  return 1;
}

/* M^-1 (pg_hemisphere_to_square, by the same operations) and the gradients of its two coordinates
 * with respect to w (*gx, *gy); along a direction tangent to the sphere they are the map's
 * derivative there. Returns 0 where the disk radius r = sqrt(1 - z) is below min_radius (the
 * pole, where the map has no derivative and the gradients grow as 1 / r). With |x| >= |y|:
 * a = +-r, b = a atan(y / x) 4 / pi, so a' = (0, 0, -+1 / (2 r)) and b' from atan' = 1 / (1 + t^2)
 * (the polynomial's derivative to within its 2e-8); the other wedge mirrors it; u = (a + 1) / 2. */
PG_FN int pg_hemisphere_to_square_d(float3 w, float min_radius, PG_PRIVATE float2* u,
                                    PG_PRIVATE float3* gx, PG_PRIVATE float3* gy) {
  float r = sqrt(clamp(1.0f - w.z, 0.0f, 1.0f));
  if (r == 0.0f || (w.x == 0.0f && w.y == 0.0f)) {
    *u = pg_make_float2(0.5f, 0.5f);
    return 0;
  }
  float a, b;
  float3 da, db;
  if (fabs(w.x) >= fabs(w.y)) {
    a = w.x > 0.0f ? r : -r;
    float t = w.y / w.x, at = pg_atan_unit(t);
    b = a * at * (4.0f / PG_PI);
    float k = a * (4.0f / PG_PI) / (1.0f + t * t); /* d b / d t */
    da = pg_make_float3(0.0f, 0.0f, -0.5f * a / (r * r));
    db = pg_make_float3(-k * t / w.x, k / w.x, da.z * at * (4.0f / PG_PI));
  } else {
    b = w.y > 0.0f ? r : -r;
    float t = w.x / w.y, at = pg_atan_unit(t);
    a = b * at * (4.0f / PG_PI);
    float k = b * (4.0f / PG_PI) / (1.0f + t * t); /* d a / d t */
    db = pg_make_float3(0.0f, 0.0f, -0.5f * b / (r * r));
    da = pg_make_float3(k / w.y, -k * t / w.y, db.z * at * (4.0f / PG_PI));
  }
  *u = pg_make_float2(clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), clamp(0.5f * (b + 1.0f), 0.0f, 1.0f));
  *gx = da * 0.5f;
  *gy = db * 0.5f;
  return r >= min_radius;
}

/* Cosine-weighted hemisphere sampling (Malley's method) and its solid-angle density. */
PG_FN float3 pg_sample_cosine_hemisphere(float2 u) {
  float2 d = pg_square_to_disk(u);
  float z = pg_safe_sqrt(1.0f - d.x * d.x - d.y * d.y);
  return pg_make_float3(d.x, d.y, z);
}

PG_FN float pg_cosine_hemisphere_pdf(float cos_theta) {
  return fmax(cos_theta, 0.0f) * PG_INV_PI;
}

PG_NAMESPACE_END

#endif

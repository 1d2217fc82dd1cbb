/* The Shirley-Chiu concentric map and the equal-area lift between the unit square and the
 * hemisphere (paper, eq. 2: the mapping M). M is area preserving up to the constant 2*pi:
 * a density p_u on [0,1]^2 becomes p_omega(w) = p_u(M^-1(w)) / (2*pi) on the hemisphere.
 * The same concentric map gives cosine-weighted sampling for the Lambert lobe. */
#ifndef RTPG_SHARED_MAPPING_H
#define RTPG_SHARED_MAPPING_H

#include "shared/compat.h"

PG_NAMESPACE_BEGIN

/* Shirley and Chiu 1997, in the form of pbrt-v4's SampleUniformDiskConcentric. */
PG_FN float2 pg_square_to_disk(float2 u) {
  float ox = 2.0f * u.x - 1.0f;
  float oy = 2.0f * u.y - 1.0f;
  if (ox == 0.0f && oy == 0.0f) return pg_make_float2(0.0f, 0.0f);
  float r, theta;
  if (fabs(ox) > fabs(oy)) {
    r = ox;
    theta = (PG_PI / 4.0f) * (oy / ox);
  } else {
    r = oy;
    theta = (PG_PI / 2.0f) - (PG_PI / 4.0f) * (ox / oy);
  }
  return pg_make_float2(r * cos(theta), r * sin(theta));
}

/* Inverse of pg_square_to_disk for points in the closed unit disk. */
PG_FN float2 pg_disk_to_square(float2 d) {
  float r = sqrt(d.x * d.x + d.y * d.y);
  if (r == 0.0f) return pg_make_float2(0.5f, 0.5f);
  float phi = atan2(d.y, d.x);                  /* (-pi, pi] */
  if (phi < -PG_PI / 4.0f) phi += 2.0f * PG_PI; /* [-pi/4, 7pi/4) */
  float a, b;
  if (phi < PG_PI / 4.0f) { /* right wedge: ox = r */
    a = r;
    b = phi * a / (PG_PI / 4.0f);
  } else if (phi < 3.0f * PG_PI / 4.0f) { /* top wedge: oy = r */
    b = r;
    a = -(phi - PG_PI / 2.0f) * b / (PG_PI / 4.0f);
  } else if (phi < 5.0f * PG_PI / 4.0f) { /* left wedge: ox = -r */
    a = -r;
    b = (phi - PG_PI) * a / (PG_PI / 4.0f);
  } else { /* bottom wedge: oy = -r */
    b = -r;
    a = -(phi - 3.0f * PG_PI / 2.0f) * b / (PG_PI / 4.0f);
  }
  return pg_make_float2(clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), clamp(0.5f * (b + 1.0f), 0.0f, 1.0f));
}

/* M: square -> hemisphere (z up), equal-area: z = 1 - r^2, xy scaled by sqrt(2 - r^2). */
PG_FN float3 pg_square_to_hemisphere(float2 u) {
  float2 d = pg_square_to_disk(u);
  float r2 = d.x * d.x + d.y * d.y;
  float s = pg_safe_sqrt(2.0f - r2);
  return pg_make_float3(d.x * s, d.y * s, 1.0f - r2);
}

/* M^-1 for directions with z >= 0 (callers check the hemisphere). */
PG_FN float2 pg_hemisphere_to_square(float3 w) {
  float r2 = clamp(1.0f - w.z, 0.0f, 1.0f);
  float xy = sqrt(w.x * w.x + w.y * w.y);
  float scale = xy > 0.0f ? sqrt(r2) / xy : 0.0f;
  return pg_disk_to_square(pg_make_float2(w.x * scale, w.y * scale));
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

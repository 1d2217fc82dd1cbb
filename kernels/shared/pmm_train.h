/* One pixel's training step (paper 3.2 and 4.2), shared by both variants of the train kernel
 * (VPL tile in local memory, or VPLs read from global memory) and by host tests: take N
 * neighbouring VPLs from the (2*apron+1)^2 window, turn each into an importance-weighted
 * sample of L_i f_r cos at this pixel's point, and run one online EM step. */
#ifndef RTPG_SHARED_PMM_TRAIN_H
#define RTPG_SHARED_PMM_TRAIN_H

#include "rtpg/guiding_layout.h"
#include "shared/bsdf.h"
#include "shared/compat.h"
#include "shared/guiding_pixel.h"
#include "shared/pmm.h"
#include "shared/rng.h"
#include "shared/vpl_packing.h"

PG_NAMESPACE_BEGIN

/* What one pixel knows about itself while training. */
typedef struct {
  float3 x;       /* surface point */
  pg_frame frame; /* shading frame: the model's hemisphere */
  float3 wo;      /* local view direction */
  pg_lobes lobes;
} pg_train_pixel;

/* One VPL (its two channels, include/rtpg/guiding_layout.h) as a training sample of this
 * pixel: x = weight a = lum(L f_r cos) / r, (y, z) = square point, w = BSDF density, and
 * *density = r, the density of its direction in this pixel's solid angle. Returns 0 when the VPL
 * says nothing about this pixel's hemisphere. With train_all_samples every VPL counts at the
 * density its pixel really sampled with (the whole mixture D); otherwise BSDF-strategy VPLs only,
 * at the BSDF's density (paper 3.2). */
PG_FN int pg_train_sample_from_vpl(pg_train_pixel px, float4 position_pdf, uint4 normal_radiance,
                                   pg_kernel_settings p, PG_PRIVATE float4* sample,
                                   PG_PRIVATE float* density_out) {
  uint info = pg_vpl_info(normal_radiance);
  if ((info & PG_VPL_VALID) == 0u) return 0;
  if (!p.train_all_samples && PG_VPL_STRATEGY(info) != PG_STRATEGY_BSDF) return 0;
  float density = p.train_all_samples ? pg_vpl_mixture_density(normal_radiance) : position_pdf.w;
  float3 w;
  float r; /* density of w as seen from this pixel */
  if ((info & PG_VPL_DISTANT) != 0u) {
    w = pg_float4_xyz(position_pdf);
    r = density;
  } else {
    float3 to = pg_float4_xyz(position_pdf) - px.x;
    float d2 = dot(to, to);
    if (!(d2 > 0.0f)) return 0;
    w = to * (1.0f / sqrt(d2));
    /* The VPL's density is in area measure at y: to this pixel's solid angle. */
    float cos_y = -dot(pg_vpl_normal(normal_radiance), w);
    if (cos_y <= 1e-4f) return 0; /* y faces away from x */
    r = density * d2 / cos_y;
  }
  if (!(r > 0.0f) || !isfinite(r)) return 0;
  float3 wl = pg_to_local(px.frame, w);
  if (wl.z <= 0.0f) return 0;
  float3 radiance = pg_vpl_radiance(normal_radiance);
  *density_out = r;
  if (pg_max3(radiance) <= 0.0f) { /* a dark VPL: weight 0, no need to map it */
    *sample = pg_make_float4(0.0f, 0.5f, 0.5f, 0.0f);
    return 1;
  }
  float3 f = pg_bsdf_eval(px.lobes, px.wo, wl) * wl.z;
  float a = pg_luminance(radiance * f) / r;
  float2 u = pg_hemisphere_to_square(wl);
  *sample = pg_make_float4(a, u.x, u.y, pg_bsdf_pdf(px.lobes, px.wo, wl));
  return 1;
}

/* Amortised training (docs/guiding.md, "Cost"): a mature pixel's lobe (k at least a quarter
 * of k_max, where the step size is small) trains on every train_interval-th frame only, in a
 * pattern that rotates over the image; the other frames keep its state. Aligned runs of
 * PG_TRAIN_RUN pixels of a row decide together, so that the lanes of a work-item of
 * train_wide.cl (at most 16, a divisor of the run) train together or not at all: a work-item
 * with one training lane costs as much as one whose lanes all train. */
#define PG_TRAIN_RUN 16u
PG_FN int pg_train_this_frame(float k, int x, int y, uint frame, pg_kernel_settings p) {
  if (p.train_interval <= 1 || k < 0.25f * p.k_max) return 1;
  return ((uint)x / PG_TRAIN_RUN + 3u * (uint)y + frame) % (uint)p.train_interval == 0u;
}

/* Where this frame's walk through pixel (x, y)'s window starts: one random cell per aligned run
 * of PG_TRAIN_RUN pixels of a row (the generator of the run's first pixel), so the s-th
 * neighbours of the pixels of a run are consecutive pixels of one row, which train_wide.cl
 * loads as vectors (docs/guiding.md, "Several pixels per work-item"). Each pixel's walk is as
 * random as with a start of its own; neighbouring runs and frames draw independently. */
PG_FN uint pg_train_walk_start(uint seed, int x, int y, uint width, uint frame,
                               pg_kernel_settings p) {
  uint run_first = (uint)y * width + ((uint)x & ~(PG_TRAIN_RUN - 1u));
  pg_rng rng = pg_rng_make(seed, run_first, frame, 0u, PG_RNG_STREAM_TRAIN);
  int side = 2 * p.apron + 1;
  return pg_rng_next_uint(&rng) % (uint)(side * side);
}

/* The window offset of the s-th neighbour of this frame's walk through the window. */
PG_FN int pg_train_window_index(uint start, int s, pg_kernel_settings p) {
  int side = 2 * p.apron + 1;
  int size = side * side;
  return (int)((start + (uint)(s * p.stride)) % (uint)size);
}

PG_NAMESPACE_END

#endif

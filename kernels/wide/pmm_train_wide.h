/* One pixel's training step (kernels/shared/pmm_train.h, kernels/shared/pmm.h) for PG_LANES
 * pixels at once (kernels/wide/lanes.h): the turning of one neighbour VPL per lane into a
 * training sample, and the E-step of one sample per lane. Lane by lane these are the same
 * operations in the same order as the scalar functions they mirror (named on each), so the
 * train_wide kernel equals the host reference within rounding
 * (tests/guiding/test_guiding_kernels.cpp). OpenCL C only. */
#ifndef RTPG_WIDE_PMM_TRAIN_WIDE_H
#define RTPG_WIDE_PMM_TRAIN_WIDE_H

#include "rtpg/guiding_layout.h"
#include "shared/compat.h"
#include "wide/bsdf_wide.h"
#include "wide/lanes.h"
#include "wide/pmm_wide.h"

/* What PG_LANES pixels know about themselves while training (pg_train_pixel per lane). */
typedef struct {
  pg_float3w x;     /* surface point */
  pg_frame_w frame; /* shading frame */
  pg_float3w wo;    /* local view direction */
  pg_lobes_w lobes;
} pg_train_pixels_w;

/* One VPL per lane (the channels of include/rtpg/guiding_layout.h, split and unpacked). */
typedef struct {
  pg_float3w position; /* or a direction, for a distant VPL */
  pg_floatw position_pdf;
  pg_float3w normal;
  pg_floatw mixture_pdf;
  pg_float3w radiance;
  pg_uintw info;
} pg_vpls_w;

/* A training sample per lane (pg_train_sample_from_vpl's float4 and density, and whether it
 * returned 1). */
typedef struct {
  pg_intw kept;
  pg_floatw a, ux, uy, bsdf_pdf, density;
} pg_train_samples_w;

/* pg_train_sample_from_vpl for every lane whose mask `asked` is set. */
static inline pg_train_samples_w pg_train_samples_from_vpls_w(pg_train_pixels_w px, pg_vpls_w v,
                                                              pg_intw asked, pg_kernel_settings p,
                                                              int any_specular) {
  pg_uintw info = v.info;
  pg_intw ok = asked & ((info & PG_VPL_VALID) != 0u);
  if (!p.train_all_samples) ok &= PG_VPL_STRATEGY(info) == PG_STRATEGY_BSDF;
  pg_floatw density = p.train_all_samples ? v.mixture_pdf : v.position_pdf;
  pg_intw distant = (info & PG_VPL_DISTANT) != 0u;
  pg_float3w to = pg_sub3w(v.position, px.x);
  pg_floatw d2 = pg_dot3w(to, to);
  pg_float3w w = pg_select3w(pg_scale3w(to, 1.0f / sqrt(d2)), v.position, distant);
  /* The VPL's density is in area measure at y: to this pixel's solid angle. */
  pg_floatw cos_y = -pg_dot3w(v.normal, w);
  pg_floatw r = select(density * d2 / cos_y, density, distant);
  ok &= distant | ((d2 > 0.0f) & (cos_y > 1e-4f));
  ok &= (r > 0.0f) & isfinite(r);
  pg_float3w wl = pg_to_local_w(px.frame, w);
  ok &= wl.z > 0.0f;
  pg_train_samples_w s;
  s.kept = ok;
  s.density = r;
  /* A dark VPL: weight 0 at the square's centre. Where no lane has a lit one (most steps in a
   * room lit through an opening, whose one-path VPLs rarely find the light), the BSDF and the
   * mapping are skipped, as the scalar function skips them for a dark VPL (docs/guiding.md,
   * "Dark VPLs skipped in the lanes"). */
  pg_intw dark = pg_max3w(v.radiance) <= 0.0f;
  if (!any(ok & ~dark)) {
    s.a = s.bsdf_pdf = (pg_floatw)(0.0f);
    s.ux = s.uy = (pg_floatw)(0.5f);
    return s;
  }
  pg_floatw pdf;
  pg_float3w f = pg_scale3w(pg_bsdf_eval_pdf_w(px.lobes, px.wo, wl, any_specular, &pdf), wl.z);
  pg_hemisphere_to_square_w(wl, &s.ux, &s.uy);
  s.a = pg_luminance3w(pg_mul3w(v.radiance, f)) / r;
  s.bsdf_pdf = pdf;
  s.a = select(s.a, (pg_floatw)(0.0f), dark);
  s.ux = select(s.ux, (pg_floatw)(0.5f), dark);
  s.uy = select(s.uy, (pg_floatw)(0.5f), dark);
  s.bsdf_pdf = select(s.bsdf_pdf, (pg_floatw)(0.0f), dark);
  return s;
}

/* E-step sums of PG_LANES pixels (pg_pmm_batch per lane). */
typedef struct {
  pg_floatw a, ag, agx, agy, agxx, agyy, agxy;
  pg_floatw ax, ay, axx, ayy, axy;
  pg_floatw count;
  pg_intw reseed; /* a count per lane, as pg_pmm_batch's */
  pg_floatw v1, v2, model_pi;
} pg_pmm_batch_w;

static inline pg_pmm_batch_w pg_pmm_batch_empty_w(void) {
  pg_pmm_batch_w b;
  b.a = b.ag = b.agx = b.agy = b.agxx = b.agyy = b.agxy = (pg_floatw)(0.0f);
  b.ax = b.ay = b.axx = b.ayy = b.axy = (pg_floatw)(0.0f);
  b.count = (pg_floatw)(0.0f);
  b.reseed = (pg_intw)(0);
  b.v1 = b.v2 = b.model_pi = (pg_floatw)(0.0f);
  return b;
}

/* pg_pmm_e_terms per lane. */
typedef struct {
  pg_floatw inv_l11, inv_l22, norm;
} pg_pmm_e_terms_w;

static inline pg_pmm_e_terms_w pg_pmm_e_terms_of_w(pg_pmm_model_w m) {
  pg_pmm_e_terms_w t;
  t.inv_l11 = 1.0f / m.l11;
  t.inv_l22 = 1.0f / m.l22;
  t.norm = m.pi / (PG_TWO_PI * m.l11 * m.l22) * PG_INV_TWO_PI;
  return t;
}

/* pg_pmm_batch_add_terms for the lanes whose sample is kept; terms = pg_pmm_e_terms_of_w(m). */
static inline pg_pmm_batch_w pg_pmm_batch_add_w(pg_pmm_batch_w b, pg_pmm_model_w m,
                                                pg_pmm_e_terms_w terms, pg_kernel_settings p,
                                                pg_train_samples_w s, pg_floatw history_weight) {
  pg_floatw a = s.a;
  pg_intw ok = s.kept & (a >= 0.0f) & (a <= p.max_weight);
  if (p.weight_clamp > 0.0f) a = select(a, fmin(a, p.weight_clamp * history_weight), m.valid);
  pg_intw zero = a == 0.0f;
  if (!any(ok & ~zero)) { /* no lane adds more than its count (pg_pmm_batch_add_terms's a = 0) */
    b.count = select(b.count, b.count + 1.0f, ok);
    return b;
  }
  pg_floatw z1 = (s.ux - m.mx) * terms.inv_l11;
  pg_floatw z2 = (s.uy - m.my - m.l21 * z1) * terms.inv_l22;
  pg_floatw q = z1 * z1 + z2 * z2;
  pg_floatw g = terms.norm * exp(-0.5f * q);
  pg_floatw d = g + (1.0f - m.pi) * s.bsdf_pdf;
  pg_floatw gamma_model = select((pg_floatw)(0.0f), g / d, d > 0.0f);
  pg_floatw gamma = select((pg_floatw)(p.pi_init), gamma_model, m.valid);
  pg_intw finite = ~m.valid | isfinite(gamma_model);
  pg_intw add = ok & ~zero & finite;
  b.count = select(b.count, b.count + 1.0f, ok & (zero | finite));
  b.reseed -= add & m.valid & (q > 25.0f) & (a > p.reseed_ratio * history_weight); /* mask -1 */
  if (p.pi_learning) {
    pg_intw learn = add & m.valid & (s.density > 0.0f) & (d > 0.0f);
    pg_floatw inv_d = 1.0f / d;
    pg_floatw t = (g / m.pi - s.bsdf_pdf) * inv_d;
    pg_floatw e = a * a * s.density * inv_d;
    b.v1 = select(b.v1, b.v1 + e * t, learn);
    b.v2 = select(b.v2, b.v2 + e * t * t, learn);
    b.model_pi = select(b.model_pi, m.pi, learn);
  }
  b.ax = select(b.ax, b.ax + a * s.ux, add);
  b.ay = select(b.ay, b.ay + a * s.uy, add);
  b.axx = select(b.axx, b.axx + a * s.ux * s.ux, add);
  b.ayy = select(b.ayy, b.ayy + a * s.uy * s.uy, add);
  b.axy = select(b.axy, b.axy + a * s.ux * s.uy, add);
  pg_floatw ag = a * gamma;
  b.a = select(b.a, b.a + a, add);
  b.ag = select(b.ag, b.ag + ag, add);
  b.agx = select(b.agx, b.agx + ag * s.ux, add);
  b.agy = select(b.agy, b.agy + ag * s.uy, add);
  b.agxx = select(b.agxx, b.agxx + ag * s.ux * s.ux, add);
  b.agyy = select(b.agyy, b.agyy + ag * s.uy * s.uy, add);
  b.agxy = select(b.agxy, b.agxy + ag * s.ux * s.uy, add);
  return b;
}

/* pg_pmm_batch_reseeds per lane. */
static inline pg_intw pg_pmm_batch_reseeds_w(pg_pmm_batch_w b, pg_kernel_settings p) {
  return b.reseed >= p.reseed_samples;
}

/* pg_pmm_update: the M-step of every lane; *updated is the mask of lanes whose state changed
 * (the others keep s). */
static inline pg_pmm_state_w pg_pmm_update_w(pg_pmm_state_w s, pg_pmm_batch_w b,
                                             pg_kernel_settings p, pg_floatw target_count,
                                             __private pg_intw* updated) {
  pg_floatw inv = 1.0f / b.count;
  /* A new model from the batch's plain moments (pg_pmm_batch_reseeds). */
  pg_intw fresh = (s.k <= 0.0f) | pg_pmm_batch_reseeds_w(b, p);
  pg_floatw w = p.pi_init * inv;
  /* pi_learning: the batch's Gaussian statistics at the Newton step's weight. */
  pg_floatw scale = (pg_floatw)(1.0f);
  if (p.pi_learning) {
    pg_intw learn = (b.ag > 0.0f) & (b.v2 > 0.0f) & isfinite(b.v1) & isfinite(b.v2);
    scale = select(scale, clamp(b.model_pi + 0.5f * b.v1 / b.v2, p.pi_min, p.pi_max) * b.a / b.ag,
                   learn);
  }
  pg_pmm_state_w batch;
  batch.w = b.a * inv;
  batch.s0 = select(b.ag * scale * inv, b.a * w, fresh);
  batch.sx = select(b.agx * scale * inv, b.ax * w, fresh);
  batch.sy = select(b.agy * scale * inv, b.ay * w, fresh);
  batch.sxx = select(b.agxx * scale * inv, b.axx * w, fresh);
  batch.syy = select(b.agyy * scale * inv, b.ayy * w, fresh);
  batch.sxy = select(b.agxy * scale * inv, b.axy * w, fresh);
  batch.k = (pg_floatw)(0.0f);
  pg_floatw k = select(s.k, (pg_floatw)(0.0f), fresh);
  pg_floatw eta = fmax(exp(-p.step_alpha * log(k + 1.0f)), 1.0f / (p.k_max + 1.0f));
  eta *= clamp(b.count / fmax(target_count, 1.0f), 0.0f, 1.0f);
  eta = select(eta, (pg_floatw)(1.0f), k <= 0.0f);
  pg_pmm_state_w out;
  out.w = s.w + (batch.w - s.w) * eta;
  out.s0 = s.s0 + (batch.s0 - s.s0) * eta;
  out.sx = s.sx + (batch.sx - s.sx) * eta;
  out.sy = s.sy + (batch.sy - s.sy) * eta;
  out.sxx = s.sxx + (batch.sxx - s.sxx) * eta;
  out.syy = s.syy + (batch.syy - s.syy) * eta;
  out.sxy = s.sxy + (batch.sxy - s.sxy) * eta;
  out.k = fmin(k + 1.0f, p.k_max);
  /* A batch that gives the Gaussian nothing is a step too (pg_pmm_update). */
  *updated = (b.count > 0.0f) & (b.a > 0.0f) & pg_pmm_state_finite_w(batch) &
             pg_pmm_state_finite_w(out) & (out.s0 > 0.0f);
  return pg_pmm_state_select_w(s, out, *updated);
}

#endif

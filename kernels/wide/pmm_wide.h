/* The mixture model of kernels/shared/pmm.h for PG_LANES pixels at once (kernels/wide/
 * lanes.h): the running statistics and the model they define, the mixture density D and its
 * one-sample sampler. Lane by lane the same operations in the same order as the scalar
 * functions named on each. OpenCL C only. */
#ifndef RTPG_WIDE_PMM_WIDE_H
#define RTPG_WIDE_PMM_WIDE_H

#include "rtpg/guiding_layout.h"
#include "shared/compat.h"
#include "wide/bsdf_wide.h"
#include "wide/lanes.h"
#include "wide/mapping_wide.h"
#include "wide/sincos_wide.h"

/* Mixture models of PG_LANES pixels (pg_pmm_model per lane). */
typedef struct {
  pg_intw valid;
  pg_floatw pi, mx, my, l11, l21, l22;
} pg_pmm_model_w;

/* The running statistics of PG_LANES pixels (pg_pmm_state per lane, kernels/shared/pmm.h). */
typedef struct {
  pg_floatw w, s0, sx, sy;    /* pg_pmm_state.s0 */
  pg_floatw sxx, syy, sxy, k; /* pg_pmm_state.s1 */
} pg_pmm_state_w;

static inline pg_pmm_state_w pg_pmm_initial_state_w(void) {
  pg_pmm_state_w s;
  s.w = s.s0 = s.sx = s.sy = s.sxx = s.syy = s.sxy = s.k = (pg_floatw)(0.0f);
  return s;
}

static inline pg_pmm_state_w pg_pmm_state_select_w(pg_pmm_state_w a, pg_pmm_state_w b,
                                                   pg_intw mask) {
  pg_pmm_state_w s;
  s.w = select(a.w, b.w, mask);
  s.s0 = select(a.s0, b.s0, mask);
  s.sx = select(a.sx, b.sx, mask);
  s.sy = select(a.sy, b.sy, mask);
  s.sxx = select(a.sxx, b.sxx, mask);
  s.syy = select(a.syy, b.syy, mask);
  s.sxy = select(a.sxy, b.sxy, mask);
  s.k = select(a.k, b.k, mask);
  return s;
}

static inline pg_intw pg_pmm_state_finite_w(pg_pmm_state_w s) {
  return isfinite(s.w) & isfinite(s.s0) & isfinite(s.sx) & isfinite(s.sy) & isfinite(s.sxx) &
         isfinite(s.syy) & isfinite(s.sxy) & isfinite(s.k);
}

/* pg_pmm_model_from_state; a lane without a model has valid = 0 and the defaults. */
static inline pg_pmm_model_w pg_pmm_model_from_state_w(pg_pmm_state_w s, pg_kernel_settings p) {
  pg_intw usable = (s.k > 0.0f) & (s.w > 0.0f) & (s.s0 > 0.0f) & pg_pmm_state_finite_w(s);
  pg_pmm_model_w m;
  m.pi = clamp(s.s0 / s.w, p.pi_min, p.pi_max);
  m.mx = clamp(s.sx / s.s0, 0.0f, 1.0f);
  m.my = clamp(s.sy / s.s0, 0.0f, 1.0f);
  pg_floatw inv = 1.0f / s.s0;
  pg_floatw cxx = s.sxx * inv - m.mx * m.mx, cyy = s.syy * inv - m.my * m.my;
  pg_floatw cxy = s.sxy * inv - m.mx * m.my;
  pg_floatw prior = p.sigma_eps + p.sigma_prior / (s.k + 1.0f);
  pg_floatw sxx = clamp(cxx, 0.0f, 1.0f) + prior, syy = clamp(cyy, 0.0f, 1.0f) + prior;
  pg_floatw lim = p.max_correlation * sqrt(sxx * syy);
  pg_floatw sxy = clamp(cxy, -lim, lim);
  m.l11 = sqrt(sxx);
  m.l21 = sxy / m.l11;
  m.l22 = sqrt(fmax(syy - m.l21 * m.l21, 0.0f));
  m.valid = usable & (m.l22 > 0.0f) & isfinite(m.l21);
  m.pi = select((pg_floatw)(0.0f), m.pi, usable);
  m.mx = select((pg_floatw)(0.5f), m.mx, usable);
  m.my = select((pg_floatw)(0.5f), m.my, usable);
  m.l11 = select((pg_floatw)(1.0f), m.l11, usable);
  m.l21 = select((pg_floatw)(0.0f), m.l21, usable);
  m.l22 = select((pg_floatw)(1.0f), m.l22, usable);
  return m;
}

static inline pg_pmm_model_w pg_pmm_model_select_w(pg_pmm_model_w a, pg_pmm_model_w b,
                                                   pg_intw mask) {
  pg_pmm_model_w m;
  m.valid = select(a.valid, b.valid, mask);
  m.pi = select(a.pi, b.pi, mask);
  m.mx = select(a.mx, b.mx, mask);
  m.my = select(a.my, b.my, mask);
  m.l11 = select(a.l11, b.l11, mask);
  m.l21 = select(a.l21, b.l21, mask);
  m.l22 = select(a.l22, b.l22, mask);
  return m;
}

/* The Gaussian's density over the square at u, divided by 2 pi: over solid angle through M
 * (pg_pmm_gaussian_pdf times PG_INV_TWO_PI). */
static inline pg_floatw pg_pmm_gaussian_pdf_w(pg_pmm_model_w m, pg_floatw ux, pg_floatw uy) {
  pg_floatw z1 = (ux - m.mx) / m.l11;
  pg_floatw z2 = (uy - m.my - m.l21 * z1) / m.l22;
  pg_floatw q = z1 * z1 + z2 * z2;
  return exp(-0.5f * q) / (PG_TWO_PI * m.l11 * m.l22) * PG_INV_TWO_PI;
}

/* D(wi) for local directions (pg_pmm_pdf). any_model = 0 promises that no lane has a valid
 * model: the density is the BSDF's. */
static inline pg_floatw pg_pmm_pdf_w(pg_pmm_model_w m, pg_lobes_w l, pg_float3w wo, pg_float3w wi,
                                     int any_specular, int any_model) {
  pg_floatw bsdf = pg_bsdf_pdf_w(l, wo, wi, any_specular);
  if (!any_model) return bsdf;
  pg_floatw ux, uy;
  pg_hemisphere_to_square_w(wi, &ux, &uy);
  pg_floatw mixed = m.pi * pg_pmm_gaussian_pdf_w(m, ux, uy) + (1.0f - m.pi) * bsdf;
  mixed = select(mixed, (pg_floatw)(0.0f), wi.z <= 0.0f);
  return select(bsdf, mixed, m.valid);
}

/* pg_pmm_sample: xi < pi picks the Gaussian (Box-Muller, the Cholesky factor, then M), else the
 * BSDF with xi's position above pi as its lobe choice. *guided is the mask of lanes that took
 * the Gaussian, *pdf is D(wi), 0 where there is no sample (a Gaussian sample outside the square
 * or below the horizon, a BSDF sample with density 0). */
static inline pg_float3w pg_pmm_sample_w(pg_pmm_model_w m, pg_lobes_w l, pg_float3w wo,
                                         pg_floatw xi, pg_floatw u1, pg_floatw u2, int any_specular,
                                         int any_model, __private pg_intw* guided,
                                         __private pg_floatw* pdf) {
  pg_intw guide = m.valid & (xi < m.pi);
  pg_floatw u_lobe = select(xi, (xi - m.pi) / (1.0f - m.pi), m.valid);
  pg_floatw bsdf_pdf;
  pg_float3w wi =
      pg_bsdf_sample_w(l, wo, clamp(u_lobe, 0.0f, 0.99999994f), u1, u2, any_specular, &bsdf_pdf);
  pg_intw sampled = bsdf_pdf > 0.0f;
  wi = pg_select3w(pg_make_float3w(0.0f, 0.0f, 1.0f), wi, sampled);
  if (any(guide)) {
    pg_floatw r = sqrt(-2.0f * log(fmax(1.0f - u1, 1e-30f)));
    pg_floatw c, sn;
    pg_cos_sin_turn_w(u2, &c, &sn); /* phi = 2 pi u2 */
    pg_floatw z1 = r * c, z2 = r * sn;
    pg_floatw ux = m.mx + m.l11 * z1;
    pg_floatw uy = m.my + m.l21 * z1 + m.l22 * z2;
    pg_intw inside = (ux >= 0.0f) & (ux <= 1.0f) & (uy >= 0.0f) & (uy <= 1.0f);
    pg_float3w wg = pg_square_to_hemisphere_w(ux, uy);
    wg = pg_select3w(pg_make_float3w(0.0f, 0.0f, 1.0f), wg, inside);
    wi = pg_select3w(wi, wg, guide);
    sampled = select(sampled, inside & (wg.z > 0.0f), guide);
  }
  *guided = guide;
  *pdf = select((pg_floatw)(0.0f), pg_pmm_pdf_w(m, l, wo, wi, any_specular, any_model), sampled);
  return wi;
}

#endif

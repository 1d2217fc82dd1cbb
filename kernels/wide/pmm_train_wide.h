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
#include "wide/lanes.h"

/* What PG_LANES pixels know about themselves while training (pg_train_pixel per lane). */
typedef struct {
  pg_float3w x;       /* surface point */
  pg_float3w t, b, n; /* shading frame */
  pg_float3w wo;      /* local view direction */
  pg_float3w diffuse; /* pg_lobes */
  pg_float3w f0;
  pg_floatw alpha, p_specular;
} pg_train_pixels_w;

/* One VPL per lane (the three channels of include/rtpg/guiding_layout.h, split). */
typedef struct {
  pg_float3w position; /* or a direction, for a distant VPL */
  pg_floatw position_pdf;
  pg_float3w normal;
  pg_floatw mixture_pdf;
  pg_float3w radiance;
  pg_floatw info;
} pg_vpls_w;

/* A training sample per lane (pg_train_sample_from_vpl's float4, and whether it returned 1). */
typedef struct {
  pg_intw kept;
  pg_floatw a, ux, uy, bsdf_pdf;
} pg_train_samples_w;

/* Smith Lambda of GGX (pg_ggx_lambda). */
static inline pg_floatw pg_ggx_lambda_w(pg_floatw cos_theta, pg_floatw alpha) {
  pg_floatw c2 = cos_theta * cos_theta;
  pg_floatw t2 = fmax(1.0f - c2, 0.0f) / c2;
  pg_floatw lambda = 0.5f * (-1.0f + sqrt(1.0f + alpha * alpha * t2));
  return select(lambda, (pg_floatw)(0.0f), c2 <= 0.0f);
}

/* GGX D (pg_ggx_d) of a half vector with cosine h_z. */
static inline pg_floatw pg_ggx_d_w(pg_floatw h_z, pg_floatw alpha) {
  pg_floatw a2 = alpha * alpha;
  pg_floatw d = h_z * h_z * (a2 - 1.0f) + 1.0f;
  return a2 / (PG_PI * d * d);
}

/* f_r(wo, wi) and the BSDF sampling density of wi (pg_bsdf_eval, pg_bsdf_pdf) where wi.z > 0.
 * any_specular = 0 promises that no lane has a GGX lobe: the Lambert-only scene skips it. */
static inline pg_float3w pg_bsdf_eval_pdf_w(pg_train_pixels_w px, pg_float3w wi, int any_specular,
                                            __private pg_floatw* pdf) {
  pg_intw below = px.wo.z <= 0.0f;
  pg_float3w f = pg_scale3w(px.diffuse, (pg_floatw)(PG_INV_PI));
  *pdf = (1.0f - px.p_specular) * (fmax(wi.z, 0.0f) * PG_INV_PI);
  if (any_specular) {
    pg_intw coated = px.p_specular > 0.0f;
    pg_floatw a = 1.0f - 0.5f * wi.z, b = 1.0f - 0.5f * px.wo.z;
    pg_floatw ta = 1.0f - (a * a) * (a * a) * a, tb = 1.0f - (b * b) * (b * b) * b;
    pg_float3w fd = pg_scale3w(px.diffuse, (28.0f / 23.0f) * PG_INV_PI * ta * tb);
    pg_float3w h = pg_add3w(px.wo, wi);
    h = pg_scale3w(h, 1.0f / sqrt(pg_dot3w(h, h)));
    pg_floatw m = clamp(1.0f - pg_dot3w(wi, h), 0.0f, 1.0f);
    pg_floatw m5 = (m * m) * (m * m) * m;
    pg_float3w fresnel =
        pg_make_float3w(px.f0.x + (1.0f - px.f0.x) * m5, px.f0.y + (1.0f - px.f0.y) * m5,
                        px.f0.z + (1.0f - px.f0.z) * m5);
    pg_floatw d = pg_ggx_d_w(h.z, px.alpha);
    pg_floatw lambda_o = pg_ggx_lambda_w(px.wo.z, px.alpha);
    pg_floatw g2 = 1.0f / (1.0f + lambda_o + pg_ggx_lambda_w(wi.z, px.alpha));
    pg_floatw spec = d * g2 / (4.0f * px.wo.z * wi.z);
    f = pg_select3w(f, pg_add3w(fd, pg_scale3w(fresnel, spec)), coated);
    pg_floatw pdf_spec = 1.0f / (1.0f + lambda_o) * d / (4.0f * px.wo.z);
    *pdf = select(*pdf, *pdf + px.p_specular * pdf_spec, coated);
  }
  *pdf = select(*pdf, (pg_floatw)(0.0f), below);
  return pg_select3w(f, pg_make_float3w(0.0f, 0.0f, 0.0f), below);
}

/* M^-1 (pg_hemisphere_to_square with pg_disk_to_square) for wl.z >= 0. */
static inline void pg_hemisphere_to_square_w(pg_float3w w, __private pg_floatw* ux,
                                             __private pg_floatw* uy) {
  pg_floatw r2 = clamp(1.0f - w.z, 0.0f, 1.0f);
  pg_floatw xy = sqrt(w.x * w.x + w.y * w.y);
  pg_floatw scale = select((pg_floatw)(0.0f), sqrt(r2) / xy, xy > 0.0f);
  pg_floatw dx = w.x * scale, dy = w.y * scale;
  pg_floatw r = sqrt(dx * dx + dy * dy);
  /* The wedge |x| >= |y| takes its radius from x and its angle from y / x; the other wedge
   * swaps the roles (pg_disk_to_square). */
  pg_intw swap = fabs(dx) < fabs(dy);
  pg_floatw p = select(dx, dy, swap), q = select(dy, dx, swap);
  pg_floatw radius = select(-r, r, p > 0.0f);
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
  pg_intw centre = r == 0.0f;
  *ux = select(clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), (pg_floatw)(0.5f), centre);
  *uy = select(clamp(0.5f * (b + 1.0f), 0.0f, 1.0f), (pg_floatw)(0.5f), centre);
}

/* pg_train_sample_from_vpl for every lane whose mask `asked` is set. */
static inline pg_train_samples_w pg_train_samples_from_vpls_w(pg_train_pixels_w px, pg_vpls_w v,
                                                              pg_intw asked, pg_kernel_settings p,
                                                              int any_specular) {
  pg_uintw info = pg_convert_uintw(v.info);
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
  pg_float3w wl = pg_make_float3w(pg_dot3w(w, px.t), pg_dot3w(w, px.b), pg_dot3w(w, px.n));
  ok &= wl.z > 0.0f;
  pg_train_samples_w s;
  s.kept = ok;
  pg_floatw pdf;
  pg_float3w f = pg_scale3w(pg_bsdf_eval_pdf_w(px, wl, any_specular, &pdf), wl.z);
  pg_hemisphere_to_square_w(wl, &s.ux, &s.uy);
  s.a = pg_luminance3w(pg_mul3w(v.radiance, f)) / r;
  s.bsdf_pdf = pdf;
  /* A dark VPL: weight 0 at the square's centre. */
  pg_intw dark = pg_max3w(v.radiance) <= 0.0f;
  s.a = select(s.a, (pg_floatw)(0.0f), dark);
  s.ux = select(s.ux, (pg_floatw)(0.5f), dark);
  s.uy = select(s.uy, (pg_floatw)(0.5f), dark);
  s.bsdf_pdf = select(s.bsdf_pdf, (pg_floatw)(0.0f), dark);
  return s;
}

/* Mixture models of PG_LANES pixels (pg_pmm_model per lane). */
typedef struct {
  pg_intw valid;
  pg_floatw pi, mx, my, l11, l21, l22;
} pg_pmm_model_w;

/* E-step sums of PG_LANES pixels (pg_pmm_batch per lane). */
typedef struct {
  pg_floatw a, ag, agx, agy, agxx, agyy, agxy;
  pg_floatw ax, ay, axx, ayy, axy;
  pg_floatw count;
  pg_intw reseed;
} pg_pmm_batch_w;

static inline pg_pmm_batch_w pg_pmm_batch_empty_w(void) {
  pg_pmm_batch_w b;
  b.a = b.ag = b.agx = b.agy = b.agxx = b.agyy = b.agxy = (pg_floatw)(0.0f);
  b.ax = b.ay = b.axx = b.ayy = b.axy = (pg_floatw)(0.0f);
  b.count = (pg_floatw)(0.0f);
  b.reseed = (pg_intw)(0);
  return b;
}

/* pg_pmm_batch_add for the lanes whose sample is kept. */
static inline pg_pmm_batch_w pg_pmm_batch_add_w(pg_pmm_batch_w b, pg_pmm_model_w m,
                                                pg_kernel_settings p, pg_train_samples_w s,
                                                pg_floatw history_weight) {
  pg_floatw a = s.a;
  pg_intw ok = s.kept & (a >= 0.0f) & (a <= p.max_weight);
  if (p.weight_clamp > 0.0f) a = select(a, fmin(a, p.weight_clamp * history_weight), m.valid);
  pg_intw zero = a == 0.0f;
  pg_floatw z1 = (s.ux - m.mx) / m.l11;
  pg_floatw z2 = (s.uy - m.my - m.l21 * z1) / m.l22;
  pg_floatw q = z1 * z1 + z2 * z2;
  pg_floatw g = m.pi * exp(-0.5f * q) / (PG_TWO_PI * m.l11 * m.l22) * PG_INV_TWO_PI;
  pg_floatw d = g + (1.0f - m.pi) * s.bsdf_pdf;
  pg_floatw gamma_model = select((pg_floatw)(0.0f), g / d, d > 0.0f);
  pg_floatw gamma = select((pg_floatw)(p.pi_init), gamma_model, m.valid);
  pg_intw finite = ~m.valid | isfinite(gamma_model);
  pg_intw add = ok & ~zero & finite;
  b.count = select(b.count, b.count + 1.0f, ok & (zero | finite));
  b.reseed |= add & m.valid & (q > 25.0f) & (a > p.reseed_ratio * history_weight);
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

/* pg_pmm_update: the M-step of every lane; *updated is the mask of lanes whose state changed
 * (the others keep s). */
static inline pg_pmm_state_w pg_pmm_update_w(pg_pmm_state_w s, pg_pmm_batch_w b,
                                             pg_kernel_settings p, pg_floatw target_count,
                                             __private pg_intw* updated) {
  pg_floatw inv = 1.0f / b.count;
  pg_intw fresh = (s.k <= 0.0f) | b.reseed; /* a new model from the batch's plain moments */
  pg_floatw w = p.pi_init * inv;
  pg_pmm_state_w batch;
  batch.w = b.a * inv;
  batch.s0 = select(b.ag * inv, b.a * w, fresh);
  batch.sx = select(b.agx * inv, b.ax * w, fresh);
  batch.sy = select(b.agy * inv, b.ay * w, fresh);
  batch.sxx = select(b.agxx * inv, b.axx * w, fresh);
  batch.syy = select(b.agyy * inv, b.ayy * w, fresh);
  batch.sxy = select(b.agxy * inv, b.axy * w, fresh);
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
  /* Skip a batch that gives the Gaussian nothing: at eta = 1 it would zero S0. */
  *updated = (b.count > 0.0f) & (b.a > 0.0f) & (fresh | (b.ag > 0.0f)) &
             pg_pmm_state_finite_w(batch) & pg_pmm_state_finite_w(out) & (out.s0 > 0.0f);
  return pg_pmm_state_select_w(s, out, *updated);
}

#endif

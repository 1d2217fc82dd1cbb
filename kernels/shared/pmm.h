/* The per-pixel parametric mixture model of the paper (eq. 2):
 *   D(w) = pi * N(M^-1(w); mu, Sigma) / (2 pi) + (1 - pi) * p_bsdf(w)
 * its density, its sampler, the online (stepwise) EM step that trains it from VPLs
 * (paper 3.2; docs/design.md, "The guiding model") and the change of hemisphere frame used by
 * reprojection.
 *
 * State, 8 floats per pixel (paper 3.1; buffers: include/rtpg/guiding_layout.h): running averages
 * of the EM sufficient statistics s0 = (W, S0, Sx, Sy)   W = E[a], S0 = E[a gamma], (Sx, Sy) = E[a
 * gamma u] s1 = (Sxx, Syy, Sxy, k) second moments E[a gamma u u^T] and the epoch count k with a =
 * lum(L_i f_r cos) / r (importance weight of a training sample), gamma the Gaussian's
 * responsibility and u = M^-1(w) in the unit square. The model follows: pi = clamp(S0 / W), mu = S1
 * / S0, Sigma = S2 / S0 - mu mu^T + eps I. k = 0 means "no model": the pixel samples its BSDF only
 * (paper 3.1, invalid history). */
#ifndef RTPG_SHARED_PMM_H
#define RTPG_SHARED_PMM_H

#include "shared/bsdf.h"
#include "shared/compat.h"
#include "shared/mapping.h"
#include "shared/sincos.h"
#include "rtpg/guiding_layout.h"

PG_NAMESPACE_BEGIN

#ifndef __OPENCL_C_VERSION__
using ::rtpg::pg_kernel_settings; /* C++: the layout header's type, seen from rtpg::shared */
#endif

typedef struct {
  float4 s0; /* W, S0, Sx, Sy */
  float4 s1; /* Sxx, Syy, Sxy, k */
} pg_pmm_state;

typedef struct {
  int valid;           /* k > 0 and the statistics are usable */
  float pi;            /* mixing weight of the Gaussian */
  float mx, my;        /* mean in the square */
  float l11, l21, l22; /* Cholesky factor of Sigma */
} pg_pmm_model;

PG_FN pg_pmm_state pg_pmm_initial_state(void) {
  pg_pmm_state s;
  s.s0 = pg_make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  s.s1 = pg_make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  return s;
}

PG_FN int pg_pmm_state_finite(pg_pmm_state s) {
  return isfinite(s.s0.x) && isfinite(s.s0.y) && isfinite(s.s0.z) && isfinite(s.s0.w) &&
         isfinite(s.s1.x) && isfinite(s.s1.y) && isfinite(s.s1.z) && isfinite(s.s1.w);
}

/* Covariance of the statistics before regularisation: S2/S0 - mu mu^T. */
PG_FN float3 pg_pmm_raw_covariance(pg_pmm_state s, float mx, float my) {
  float inv = 1.0f / s.s0.y;
  return pg_make_float3(s.s1.x * inv - mx * mx, s.s1.y * inv - my * my, s.s1.z * inv - mx * my);
}

PG_FN pg_pmm_model pg_pmm_model_from_state(pg_pmm_state s, pg_kernel_settings p) {
  pg_pmm_model m;
  m.valid = 0;
  m.pi = 0.0f;
  m.mx = 0.5f;
  m.my = 0.5f;
  m.l11 = 1.0f;
  m.l21 = 0.0f;
  m.l22 = 1.0f;
  if (!(s.s1.w > 0.0f) || !(s.s0.x > 0.0f) || !(s.s0.y > 0.0f) || !pg_pmm_state_finite(s)) return m;
  m.pi = clamp(s.s0.y / s.s0.x, p.pi_min, p.pi_max);
  m.mx = clamp(s.s0.z / s.s0.y, 0.0f, 1.0f);
  m.my = clamp(s.s0.w / s.s0.y, 0.0f, 1.0f);
  float3 c = pg_pmm_raw_covariance(s, m.mx, m.my);
  /* Variances: non-negative, regularised, and no wider than the square needs. */
  /* A prior variance that fades as epochs accumulate keeps a model seeded from a few
   * samples from collapsing onto them (in the spirit of the MAP prior of Vorba et al.). */
  float prior = p.sigma_eps + p.sigma_prior / (s.s1.w + 1.0f);
  float sxx = clamp(c.x, 0.0f, 1.0f) + prior;
  float syy = clamp(c.y, 0.0f, 1.0f) + prior;
  float lim = p.max_correlation * sqrt(sxx * syy);
  float sxy = clamp(c.z, -lim, lim);
  m.l11 = sqrt(sxx);
  m.l21 = sxy / m.l11;
  m.l22 = pg_safe_sqrt(syy - m.l21 * m.l21);
  if (!(m.l22 > 0.0f) || !isfinite(m.l21)) return m;
  m.valid = 1;
  return m;
}

/* The model as the sample kernel hands it to the host (mixture_a, mixture_b of
 * include/rtpg/guiding_layout.h) and back: an invalid model is all zeros. */
PG_FN float4 pg_pmm_mixture_a(pg_pmm_model m) {
  return m.valid ? pg_make_float4(m.pi, m.mx, m.my, m.l11) : pg_make_float4(0.0f, 0.0f, 0.0f, 0.0f);
}

PG_FN float2 pg_pmm_mixture_b(pg_pmm_model m) {
  return m.valid ? pg_make_float2(m.l21, m.l22) : pg_make_float2(0.0f, 0.0f);
}

PG_FN pg_pmm_model pg_pmm_model_from_mixture(float4 a, float2 b) {
  pg_pmm_model m;
  m.valid = a.w > 0.0f && b.y > 0.0f;
  m.pi = a.x;
  m.mx = a.y;
  m.my = a.z;
  m.l11 = a.w;
  m.l21 = b.x;
  m.l22 = b.y;
  return m;
}

/* Squared Mahalanobis distance of u from the Gaussian's mean. */
PG_FN float pg_pmm_mahalanobis2(pg_pmm_model m, float2 u) {
  float z1 = (u.x - m.mx) / m.l11;
  float z2 = (u.y - m.my - m.l21 * z1) / m.l22;
  return z1 * z1 + z2 * z2;
}

/* Gaussian density over the unit square's plane at u (not renormalised to the square). */
PG_FN float pg_pmm_gaussian_pdf(pg_pmm_model m, float2 u) {
  float z1 = (u.x - m.mx) / m.l11;
  float z2 = (u.y - m.my - m.l21 * z1) / m.l22;
  float q = z1 * z1 + z2 * z2;
  return exp(-0.5f * q) / (PG_TWO_PI * m.l11 * m.l22);
}

/* D(w) for a local direction wi (z = shading normal). */
PG_FN float pg_pmm_pdf(pg_pmm_model m, pg_lobes lobes, float3 wo, float3 wi) {
  float bsdf = pg_bsdf_pdf(lobes, wo, wi);
  if (!m.valid) return bsdf;
  if (wi.z <= 0.0f) return 0.0f;
  float g = pg_pmm_gaussian_pdf(m, pg_hemisphere_to_square(wi)) * PG_INV_TWO_PI;
  return m.pi * g + (1.0f - m.pi) * bsdf;
}

typedef struct {
  float3 wi;     /* local direction */
  float pdf;     /* D(wi); 0 = no sample (a Gaussian sample outside the square) */
  uint strategy; /* PG_STRATEGY_* (include/rtpg/guiding_layout.h) */
} pg_pmm_sample_t;

/* A point of the square drawn from the model's Gaussian (Box-Muller, then the Cholesky factor);
 * *inside is 0 when it falls outside the square, where the mixture has no Gaussian mass: the
 * sample is lost (pdf 0), never moved. */
PG_FN float2 pg_pmm_sample_square(pg_pmm_model m, float u1, float u2, PG_PRIVATE int* inside) {
  float r = sqrt(-2.0f * log(fmax(1.0f - u1, 1e-30f)));
  float2 cs = pg_cos_sin_turn(u2); /* phi = 2 pi u2 */
  float z1 = r * cs.x, z2 = r * cs.y;
  float ux = m.mx + m.l11 * z1;
  float uy = m.my + m.l21 * z1 + m.l22 * z2;
  *inside = ux >= 0.0f && ux <= 1.0f && uy >= 0.0f && uy <= 1.0f;
  return pg_make_float2(ux, uy);
}

/* One-sample MIS over the two components (paper 3.1): xi < pi picks the Gaussian (Box-Muller
 * then the Cholesky factor, then M), else the BSDF. Either way the sample's weight is
 * f cos / D(w) with the full mixture density. */
PG_FN pg_pmm_sample_t pg_pmm_sample(pg_pmm_model m, pg_lobes lobes, float3 wo, float xi, float u1,
                                    float u2) {
  pg_pmm_sample_t s;
  s.wi = pg_make_float3(0.0f, 0.0f, 1.0f);
  s.pdf = 0.0f;
  s.strategy = PG_STRATEGY_NONE;
  if (m.valid && xi < m.pi) {
    s.strategy = PG_STRATEGY_GUIDE;
    int inside = 0;
    float2 u = pg_pmm_sample_square(m, u1, u2, &inside);
    if (!inside) return s; /* left the square */
    s.wi = pg_square_to_hemisphere(u);
    if (s.wi.z <= 0.0f) return s;
  } else {
    s.strategy = PG_STRATEGY_BSDF;
    /* Reuse xi's position above pi as the lobe choice: one fewer random number. */
    float u_lobe = m.valid ? (xi - m.pi) / (1.0f - m.pi) : xi;
    pg_bsdf_sample_t b = pg_bsdf_sample(lobes, wo, clamp(u_lobe, 0.0f, 0.99999994f), u1, u2);
    if (b.pdf <= 0.0f) return s;
    s.wi = b.wi;
  }
  s.pdf = pg_pmm_pdf(m, lobes, wo, s.wi);
  return s;
}

/* Sums over one frame's training samples (mergeable: add fields). */
typedef struct {
  float a, ag, agx, agy, agxx, agyy, agxy; /* E-step weighted sums */
  float ax, ay, axx, ayy, axy;             /* plain weighted moments (to seed a model) */
  float count;
  int reseed; /* samples far brighter than the model's history that fell outside its lobe */
  /* The variance-aware mixing weight (pi_learning; docs/guiding.md, "A mixing weight that
   * minimises the variance"): the first two derivatives in pi of the first bounce's second
   * moment M(pi) = sum a^2 r / D(pi) at the E-step's model, v1 = -M' = sum a^2 r (G - B) / D^2
   * and v2 = M'' / 2 = sum a^2 r (G - B)^2 / D^3 (G the Gaussian's density, B the BSDF's, r the
   * density the sample was drawn with), and that model's pi. */
  float v1, v2, model_pi;
} pg_pmm_batch;

/* Whether a batch re-seeds its model: reseed_samples of its samples called for it. */
PG_FN int pg_pmm_batch_reseeds(pg_pmm_batch b, pg_kernel_settings p) {
  return b.reseed >= p.reseed_samples;
}

PG_FN pg_pmm_batch pg_pmm_batch_empty(void) {
  pg_pmm_batch b;
  b.a = b.ag = b.agx = b.agy = b.agxx = b.agyy = b.agxy = 0.0f;
  b.ax = b.ay = b.axx = b.ayy = b.axy = 0.0f;
  b.count = 0.0f;
  b.reseed = 0;
  b.v1 = b.v2 = b.model_pi = 0.0f;
  return b;
}

/* What the E-step needs of a model, computed once per pass instead of once per sample: the
 * Cholesky factor's reciprocals and the Gaussian's normalisation over solid angle, so that a
 * sample's responsibility takes one division (g / D) where it took four, in a chain that bounds
 * the train kernel's time (docs/guiding.md, "One division per E-step sample"). */
typedef struct {
  float inv_l11, inv_l22; /* 1 / l11, 1 / l22 */
  float norm;             /* pi / (2 pi l11 l22) / (2 pi): G(u) = norm exp(-q / 2) */
} pg_pmm_e_terms;

PG_FN pg_pmm_e_terms pg_pmm_e_terms_of(pg_pmm_model m) {
  pg_pmm_e_terms t;
  t.inv_l11 = 1.0f / m.l11;
  t.inv_l22 = 1.0f / m.l22;
  t.norm = m.pi / (PG_TWO_PI * m.l11 * m.l22) * PG_INV_TWO_PI;
  return t;
}

/* E-step for one sample: weight a (>= 0), square point u, direction wi, BSDF density of wi,
 * and the density the sample was drawn with (0 if unknown: it then adds nothing to v1, v2).
 * A model that does not exist yet takes every sample at the initial weight (so its first
 * M-step gives the weighted moments and pi = pi_init). terms = pg_pmm_e_terms_of(m). */
PG_FN pg_pmm_batch pg_pmm_batch_add_terms(pg_pmm_batch b, pg_pmm_model m, pg_pmm_e_terms terms,
                                          pg_kernel_settings p, float a, float2 u, float bsdf_pdf,
                                          float density, float history_weight) {
  if (!(a >= 0.0f) || !(a <= p.max_weight)) return b; /* NaN, negative or absurd: dropped */
  /* VPL radiance is a one-path estimate with a heavy tail: a single firefly would drag the
   * lobe to a random direction. Training (not rendering) clamps weights to a multiple of the
   * running mean once a model exists. */
  if (m.valid && p.weight_clamp > 0.0f) a = fmin(a, p.weight_clamp * history_weight);
  if (a == 0.0f) { /* adds nothing but its count: skip the arithmetic (most samples, often) */
    b.count += 1.0f;
    return b;
  }
  float gamma = p.pi_init;
  if (m.valid) {
    float z1 = (u.x - m.mx) * terms.inv_l11;
    float z2 = (u.y - m.my - m.l21 * z1) * terms.inv_l22;
    float q = z1 * z1 + z2 * z2;
    float g = terms.norm * exp(-0.5f * q);
    float d = g + (1.0f - m.pi) * bsdf_pdf;
    gamma = d > 0.0f ? g / d : 0.0f;
    if (!isfinite(gamma)) return b;
    /* A narrow lobe gives far-away evidence gamma ~ 0 (G underflows), so EM alone could
     * never move it: a sample far outside the lobe (beyond 5 standard deviations, where
     * gamma is negligible) and much brighter than the history re-seeds the model. Samples
     * nearer than that move the lobe through the ordinary M-step. One such sample may be a
     * firefly of the one-path VPL radiance; reseed_samples asks for more of them. */
    if (q > 25.0f && a > p.reseed_ratio * history_weight) b.reseed += 1;
    if (p.pi_learning && density > 0.0f && d > 0.0f) {
      float inv_d = 1.0f / d;
      float t = (g / m.pi - bsdf_pdf) * inv_d; /* (dD/dpi) / D */
      float e = a * a * density * inv_d;       /* a^2 r / D */
      b.v1 += e * t;
      b.v2 += e * t * t;
      b.model_pi = m.pi;
    }
  }
  b.ax += a * u.x;
  b.ay += a * u.y;
  b.axx += a * u.x * u.x;
  b.ayy += a * u.y * u.y;
  b.axy += a * u.x * u.y;
  float ag = a * gamma;
  b.a += a;
  b.ag += ag;
  b.agx += ag * u.x;
  b.agy += ag * u.y;
  b.agxx += ag * u.x * u.x;
  b.agyy += ag * u.y * u.y;
  b.agxy += ag * u.x * u.y;
  b.count += 1.0f;
  return b;
}

/* Number of neighbour VPLs a pixel trains on at epoch k (paper 4.2). */
PG_FN int pg_pmm_neighbour_count(float k, pg_kernel_settings p) {
  float t = clamp(1.0f - k / p.k_max, 0.0f, 1.0f);
  return (int)(t * (p.n_max - p.n_min) + p.n_min + 0.5f);
}

/* M-step: blend this frame's statistics into the running ones (stepwise EM, Cappe and
 * Moulines 2009). target_count is the number of samples asked for: fewer kept samples make
 * a proportionally smaller step, so a starved frame cannot overwrite the history.
 * *updated is set to 1 when the state changed. */
PG_FN pg_pmm_state pg_pmm_update(pg_pmm_state s, pg_pmm_batch b, pg_kernel_settings p,
                                 float target_count, PG_PRIVATE int* updated) {
  *updated = 0;
  if (!(b.count > 0.0f) || !(b.a > 0.0f)) return s;
  float inv = 1.0f / b.count;
  float k = s.s1.w;
  pg_pmm_state batch;
  if (k <= 0.0f || pg_pmm_batch_reseeds(b, p)) {
    /* A new model: the plain weighted moments of the batch at weight pi_init. */
    float w = p.pi_init * inv;
    batch.s0 = pg_make_float4(b.a * inv, b.a * w, b.ax * w, b.ay * w);
    batch.s1 = pg_make_float4(b.axx * w, b.ayy * w, b.axy * w, 0.0f);
    k = 0.0f;
  } else {
    /* A batch that gives the Gaussian nothing (every lit sample far from the lobe: its density
     * underflows to 0 beyond about 0.6 of the square for a mature lobe) is still a step: S0 and
     * the Gaussian's moments shrink together by 1 - eta, so the mean and the covariance stay,
     * while W moves to the batch and pi falls, as stepwise EM does. (Skipping it froze the whole
     * model, pi included, on a lobe that no longer saw any light: docs/guiding.md, "A batch that
     * gives the Gaussian nothing".) eta < 1 here (k > 0), and a step that would zero S0 is
     * refused below.
     * With pi_learning the batch's mixing weight is not EM's ag / a but one Newton step on the
     * convex M(pi) from the E-step's pi: its Gaussian statistics are scaled to that weight, so
     * the running pi follows the variance-optimal one at the EM step size while the lobe's
     * mean and covariance (ratios of these statistics) stay EM's; with ag = 0 there is nothing
     * to scale. */
    float scale = 1.0f;
    if (p.pi_learning && b.ag > 0.0f && b.v2 > 0.0f && isfinite(b.v1) && isfinite(b.v2))
      scale = clamp(b.model_pi + 0.5f * b.v1 / b.v2, p.pi_min, p.pi_max) * b.a / b.ag;
    float ag = b.ag * scale * inv;
    batch.s0 = pg_make_float4(b.a * inv, ag, b.agx * scale * inv, b.agy * scale * inv);
    batch.s1 =
        pg_make_float4(b.agxx * scale * inv, b.agyy * scale * inv, b.agxy * scale * inv, 0.0f);
  }
  if (!pg_pmm_state_finite(batch)) return s;
  float eta = 1.0f;
  if (k > 0.0f) {
    eta = fmax(exp(-p.step_alpha * log(k + 1.0f)), 1.0f / (p.k_max + 1.0f));
    eta *= clamp(b.count / fmax(target_count, 1.0f), 0.0f, 1.0f);
  }
  pg_pmm_state out;
  out.s0 = s.s0 + (batch.s0 - s.s0) * eta;
  out.s1 = s.s1 + (batch.s1 - s.s1) * eta;
  out.s1.w = fmin(k + 1.0f, p.k_max);
  if (!pg_pmm_state_finite(out) || !(out.s0.y > 0.0f)) return s;
  *updated = 1;
  return out;
}

/* One frame's training of one pixel from its n samples (x = weight a, y/z = square point u,
 * w = BSDF density; densities[j] = the density sample j was drawn with), with `passes` E-step
 * passes: each pass re-evaluates the responsibilities under the model the previous pass's M-step
 * would give, so a lobe that sits off its target moves there within the frame instead of over many
 * frames (a single pass converges slowly: docs/guiding.md, "Training"). Only the last pass's
 * statistics enter the state. */
PG_FN pg_pmm_state pg_pmm_train(pg_pmm_state s, PG_PRIVATE const float4* samples,
                                PG_PRIVATE const float* densities, int n, pg_kernel_settings p,
                                float target_count, int passes, PG_PRIVATE int* updated) {
  pg_pmm_model m = pg_pmm_model_from_state(s, p);
  pg_pmm_state base = s, out = s;
  /* The running mean weight W of the state that m comes from: the weight clamp and the
   * re-seed test compare a sample with it. A later pass's model is the previous pass's
   * M-step, so its W is that state's, not the frame's first: a new model's W is 0 until its
   * first M-step (docs/guiding.md, "The history weight of later E-step passes"). */
  float history_weight = s.s0.x;
  *updated = 0;
  /* Extra passes move a young lobe onto its target; once k is a quarter of the way to k_max the
   * lobe sits there and one pass does (measured: relMSE ratio on cornell-indirect 0.42 -> 0.44,
   * cornell-box unchanged; the train kernel 33% faster at 720p). */
  if (s.s1.w >= 0.25f * p.k_max) passes = 1;
  /* A new model (k = 0) is the batch's plain weighted moments (pg_pmm_update), which the
   * responsibilities of later passes do not change: one pass (docs/guiding.md, "The history
   * weight of later E-step passes"). */
  if (s.s1.w <= 0.0f) passes = 1;
  for (int pass = 0; pass < passes; ++pass) {
    pg_pmm_batch b = pg_pmm_batch_empty();
    pg_pmm_e_terms terms = pg_pmm_e_terms_of(m);
    for (int j = 0; j < n; ++j)
      b = pg_pmm_batch_add_terms(b, m, terms, p, samples[j].x,
                                 pg_make_float2(samples[j].y, samples[j].z), samples[j].w,
                                 densities[j], history_weight);
    /* A re-seed replaces the history with a new model, the batch's plain moments, which later
     * passes' responsibilities do not change: they give the same state again (spent work, at
     * most em_passes - 1 passes of a re-seeding pixel). */
    if (pg_pmm_batch_reseeds(b, p)) base = pg_pmm_initial_state();
    out = pg_pmm_update(base, b, p, target_count, updated);
    if (!*updated) return s;
    m = pg_pmm_model_from_state(out, p);
    history_weight = out.s0.x;
    if (!m.valid) return out;
  }
  return out;
}

/* Hemisphere frames this close (normals and tangents within about 1.8 degrees: jitter across a
 * bump map, say) keep a reprojected lobe as is: the error is below a lobe's width, and a change
 * of frame costs three mappings. */
#define PG_REFRAME_MIN_COS 0.9995f

/* Whether a state reprojected from frame `from` to frame `to` must be carried over by
 * pg_pmm_reframe. Whole frames are compared, not only normals: the tangent of
 * pg_frame_from_normal turns abruptly where the normal crosses the z = 0 plane. */
PG_FN int pg_pmm_needs_reframe(pg_frame from, pg_frame to) {
  return dot(from.n, to.n) < PG_REFRAME_MIN_COS || dot(from.t, to.t) < PG_REFRAME_MIN_COS;
}

/* Carries a state from the hemisphere frame `from` to the frame `to` (reprojection onto a
 * pixel whose normal differs): the mean moves with its direction, the covariance with the
 * Jacobian of the change of frame at the mean (in closed form; by differences where the maps
 * have no derivative: docs/guiding.md, "The reframe's Jacobian in closed form"). A mean that
 * ends up below the new horizon cannot be carried: the initial state is returned. */
PG_FN float2 pg_pmm_reframe_point(float2 u, pg_frame from, pg_frame to, PG_PRIVATE int* ok) {
  float3 w = pg_to_local(to, pg_to_world(from, pg_square_to_hemisphere(u)));
  if (w.z <= 1e-4f) *ok = 0;
  return pg_hemisphere_to_square(w);
}

/* The age k of a model carried to a pixel whose view of the surface turned from prev_view to
 * view (unit directions towards the camera; issue 9, lever 4; docs/guiding.md, "Glossy history
 * under a moving camera"). The model learnt the product of the incident light and the BSDF seen
 * from the old view; where the BSDF has a glossy lobe that product moves with the view, so k
 * falls by 1/e for every view_memory * alpha radians the view turns (alpha = GGX roughness^2,
 * about the lobe's angular width), and the next EM steps weigh the new view's samples more. A
 * BSDF without a specular lobe (f0 = 0) is view-independent: k is kept. view_memory 0: off. */
PG_FN float pg_pmm_view_aged_k(float k, float3 view, float3 prev_view, pg_material m,
                               float view_memory) {
  if (!(view_memory > 0.0f) || !(k > 0.0f)) return k;
  pg_lobes lobes = pg_make_lobes(m, pg_make_float3(0.0f, 0.0f, 1.0f)); /* f0 and alpha only */
  if (!(pg_max3(lobes.f0) > 0.0f)) return k;
  /* The angle between the unit views as 2 atan2(|a - b|, |a + b|), not acos of their dot
   * product, which near 1 loses half the digits: acos(1 - 1 ulp) = 3.5e-4 rad, a third of the
   * sharpest lobe's memory M alpha at M = 2, so a still-looking turn aged k by a factor of up to
   * 1.5 or not at all depending on rounding (docs/design.md, "Floating point on other devices"). */
  float turned = 2.0f * atan2(length(view - prev_view), length(view + prev_view));
  return k * exp(-turned / (view_memory * lobes.alpha));
}

PG_FN pg_pmm_state pg_pmm_reframe(pg_pmm_state s, pg_frame from, pg_frame to) {
  if (!(s.s1.w > 0.0f) || !(s.s0.y > 0.0f)) return s;
  float mx = clamp(s.s0.z / s.s0.y, 0.0f, 1.0f), my = clamp(s.s0.w / s.s0.y, 0.0f, 1.0f);
  float3 c = pg_pmm_raw_covariance(s, mx, my);
  /* The mean through the change of frame, and the Jacobian there: in closed form (the maps'
   * derivatives, pg_square_to_hemisphere_d and pg_hemisphere_to_square_d, chained through the
   * rotation, which carries tangent vectors as it carries points), or by differences where a
   * map has none (the square's centre, the pole). */
  float3 w, w_dx, w_dy;
  int smooth = pg_square_to_hemisphere_d(pg_make_float2(mx, my), &w, &w_dx, &w_dy);
  w = pg_to_local(to, pg_to_world(from, w));
  if (w.z <= 1e-4f) return pg_pmm_initial_state();
  float2 m2;
  float3 gx, gy;
  smooth &= pg_hemisphere_to_square_d(w, 1e-2f, &m2, &gx, &gy);
  float j11 = 1.0f, j12 = 0.0f, j21 = 0.0f, j22 = 1.0f;
  if (smooth) {
    w_dx = pg_to_local(to, pg_to_world(from, w_dx));
    w_dy = pg_to_local(to, pg_to_world(from, w_dy));
    j11 = dot(gx, w_dx);
    j12 = dot(gx, w_dy);
    j21 = dot(gy, w_dx);
    j22 = dot(gy, w_dy);
  } else {
    /* Probe inside the square, on the side away from its border. */
    float h = 1e-3f;
    float hx = mx < 0.5f ? h : -h, hy = my < 0.5f ? h : -h;
    int okx = 1, oky = 1;
    float2 px = pg_pmm_reframe_point(pg_make_float2(mx + hx, my), from, to, &okx);
    float2 py = pg_pmm_reframe_point(pg_make_float2(mx, my + hy), from, to, &oky);
    if (okx && oky) {
      j11 = (px.x - m2.x) / hx;
      j21 = (px.y - m2.y) / hx;
      j12 = (py.x - m2.x) / hy;
      j22 = (py.y - m2.y) / hy;
    }
  }
  /* Sigma' = J Sigma J^T */
  float a = c.x, b = c.z, d = c.y;
  float nxx = j11 * (j11 * a + j12 * b) + j12 * (j11 * b + j12 * d);
  float nxy = j21 * (j11 * a + j12 * b) + j22 * (j11 * b + j12 * d);
  float nyy = j21 * (j21 * a + j22 * b) + j22 * (j21 * b + j22 * d);
  pg_pmm_state out = s;
  float s0 = s.s0.y;
  out.s0.z = m2.x * s0;
  out.s0.w = m2.y * s0;
  out.s1.x = (nxx + m2.x * m2.x) * s0;
  out.s1.y = (nyy + m2.y * m2.y) * s0;
  out.s1.z = (nxy + m2.x * m2.y) * s0;
  if (!pg_pmm_state_finite(out)) return pg_pmm_initial_state();
  return out;
}

PG_NAMESPACE_END

#endif

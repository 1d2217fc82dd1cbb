/* The material model of kernels/shared/bsdf.h for PG_LANES pixels at once (kernels/wide/
 * lanes.h): the lobes, f_r and the sampling density, and the sampler. Lane by lane the same
 * operations in the same order as the scalar functions named on each, so the wide kernels equal
 * their host references within rounding (tests/guiding/test_guiding_kernels.cpp). Branches of
 * the scalar code are selects; the caller says when no lane has a GGX lobe (any_specular = 0)
 * so that a Lambert-only work-item skips its code. OpenCL C only. */
#ifndef RTPG_WIDE_BSDF_WIDE_H
#define RTPG_WIDE_BSDF_WIDE_H

#include "shared/compat.h"
#include "wide/lanes.h"
#include "wide/mapping_wide.h"
#include "wide/sincos_wide.h"

/* pg_lobes per lane. */
typedef struct {
  pg_float3w diffuse, f0;
  pg_floatw alpha, p_specular;
} pg_lobes_w;

/* pg_make_lobes for the material (base colour, perceptual roughness, metallic, dielectric F0)
 * seen from the local direction wo. */
static inline pg_lobes_w pg_make_lobes_w(pg_float3w base_color, pg_floatw roughness,
                                         pg_floatw metallic, pg_floatw specular, pg_float3w wo) {
  pg_lobes_w l;
  pg_floatw m = clamp(metallic, 0.0f, 1.0f), spec = clamp(specular, 0.0f, 1.0f);
  l.f0 = pg_make_float3w(mix(spec, base_color.x, m), mix(spec, base_color.y, m),
                         mix(spec, base_color.z, m));
  l.diffuse = pg_scale3w(base_color, (1.0f - m) * (1.0f - spec));
  pg_floatw r = fmax(roughness, PG_MIN_ROUGHNESS);
  l.alpha = r * r;
  pg_floatw c = clamp(1.0f - fmax(wo.z, 0.0f), 0.0f, 1.0f);
  pg_floatw c5 = (c * c) * (c * c) * c;
  pg_floatw w_spec = pg_luminance3w(pg_make_float3w(
      l.f0.x + (1.0f - l.f0.x) * c5, l.f0.y + (1.0f - l.f0.y) * c5, l.f0.z + (1.0f - l.f0.z) * c5));
  pg_floatw w_diff = pg_luminance3w(l.diffuse);
  pg_intw has_spec = pg_max3w(l.f0) > 0.0f;
  /* 1, not w / w, without a diffuse layer (pg_make_lobes). */
  pg_floatw p = select((pg_floatw)(1.0f), w_spec / (w_spec + w_diff), w_diff > 0.0f);
  /* Keep both strategies alive so neither lobe is undersampled. */
  p = select(p, clamp(p, 0.1f, 0.9f), has_spec & (w_diff > 0.0f));
  l.p_specular = select((pg_floatw)(0.0f), p, has_spec);
  return l;
}

/* Smith Lambda of GGX (pg_ggx_lambda). */
static inline pg_floatw pg_ggx_lambda_w(pg_floatw cos_theta, pg_floatw alpha) {
  pg_floatw c2 = cos_theta * cos_theta;
  pg_floatw t2 = fmax(1.0f - c2, 0.0f) / c2;
  pg_floatw lambda = 0.5f * (-1.0f + sqrt(1.0f + alpha * alpha * t2));
  return select(lambda, (pg_floatw)(0.0f), c2 <= 0.0f);
}

/* GGX D (pg_ggx_d) of the unit half vector h. */
static inline pg_floatw pg_ggx_d_w(pg_float3w h, pg_floatw alpha) {
  pg_floatw a2 = alpha * alpha;
  pg_floatw d = (h.x * h.x + h.y * h.y) + a2 * (h.z * h.z);
  return a2 / (PG_PI * d * d);
}

/* f_r(wo, wi) and the BSDF sampling density of wi (pg_bsdf_eval, pg_bsdf_pdf) where wi.z > 0. */
static inline pg_float3w pg_bsdf_eval_pdf_w(pg_lobes_w l, pg_float3w wo, pg_float3w wi,
                                            int any_specular, __private pg_floatw* pdf) {
  pg_intw below = wo.z <= 0.0f;
  pg_float3w f = pg_scale3w(l.diffuse, (pg_floatw)(PG_INV_PI));
  *pdf = (1.0f - l.p_specular) * (fmax(wi.z, 0.0f) * PG_INV_PI);
  if (any_specular) {
    pg_intw coated = l.p_specular > 0.0f;
    pg_floatw a = 1.0f - 0.5f * wi.z, b = 1.0f - 0.5f * wo.z;
    pg_floatw ta = 1.0f - (a * a) * (a * a) * a, tb = 1.0f - (b * b) * (b * b) * b;
    pg_float3w fd = pg_scale3w(l.diffuse, (28.0f / 23.0f) * PG_INV_PI * ta * tb);
    pg_float3w h = pg_add3w(wo, wi);
    h = pg_scale3w(h, 1.0f / sqrt(pg_dot3w(h, h)));
    pg_floatw m = clamp(1.0f - pg_dot3w(wi, h), 0.0f, 1.0f);
    pg_floatw m5 = (m * m) * (m * m) * m;
    pg_float3w fresnel =
        pg_make_float3w(l.f0.x + (1.0f - l.f0.x) * m5, l.f0.y + (1.0f - l.f0.y) * m5,
                        l.f0.z + (1.0f - l.f0.z) * m5);
    pg_floatw d = pg_ggx_d_w(h, l.alpha);
    pg_floatw lambda_o = pg_ggx_lambda_w(wo.z, l.alpha);
    pg_floatw g2 = 1.0f / (1.0f + lambda_o + pg_ggx_lambda_w(wi.z, l.alpha));
    pg_floatw spec = d * g2 / (4.0f * wo.z * wi.z);
    f = pg_select3w(f, pg_add3w(fd, pg_scale3w(fresnel, spec)), coated);
    pg_floatw pdf_spec = 1.0f / (1.0f + lambda_o) * d / (4.0f * wo.z);
    *pdf = select(*pdf, *pdf + l.p_specular * pdf_spec, coated);
  }
  *pdf = select(*pdf, (pg_floatw)(0.0f), below);
  return pg_select3w(f, pg_make_float3w(0.0f, 0.0f, 0.0f), below);
}

/* pg_bsdf_pdf: the density of pg_bsdf_sample_w over solid angle (0 below either horizon). */
static inline pg_floatw pg_bsdf_pdf_w(pg_lobes_w l, pg_float3w wo, pg_float3w wi,
                                      int any_specular) {
  pg_floatw pdf = (1.0f - l.p_specular) * (fmax(wi.z, 0.0f) * PG_INV_PI);
  if (any_specular) {
    pg_float3w h = pg_add3w(wo, wi);
    h = pg_scale3w(h, 1.0f / sqrt(pg_dot3w(h, h)));
    pg_floatw g1 = 1.0f / (1.0f + pg_ggx_lambda_w(wo.z, l.alpha));
    pg_floatw pdf_spec = g1 * pg_ggx_d_w(h, l.alpha) / (4.0f * wo.z);
    pdf = select(pdf, pdf + l.p_specular * pdf_spec, l.p_specular > 0.0f);
  }
  return select(pdf, (pg_floatw)(0.0f), (wo.z <= 0.0f) | (wi.z <= 0.0f));
}

/* pg_ggx_sample_visible_normal (Heitz 2018). */
static inline pg_float3w pg_ggx_sample_visible_normal_w(pg_float3w wo, pg_floatw alpha,
                                                        pg_floatw u1, pg_floatw u2) {
  pg_float3w vh = pg_normalize3w(pg_make_float3w(alpha * wo.x, alpha * wo.y, wo.z));
  pg_floatw lensq = vh.x * vh.x + vh.y * vh.y;
  pg_intw tilted = lensq > 0.0f;
  pg_floatw inv = 1.0f / sqrt(lensq);
  pg_float3w t1 = pg_make_float3w(select((pg_floatw)(1.0f), -vh.y * inv, tilted),
                                  select((pg_floatw)(0.0f), vh.x * inv, tilted), (pg_floatw)(0.0f));
  pg_float3w t2 = pg_cross3w(vh, t1);
  pg_floatw r = sqrt(u1);
  pg_floatw c, sn;
  pg_cos_sin_turn_w(u2, &c, &sn); /* phi = 2 pi u2 */
  pg_floatw p1 = r * c;
  pg_floatw p2 = r * sn;
  pg_floatw s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * sqrt(fmax(1.0f - p1 * p1, 0.0f)) + s * p2;
  pg_float3w nh = pg_add3w(pg_add3w(pg_scale3w(t1, p1), pg_scale3w(t2, p2)),
                           pg_scale3w(vh, sqrt(fmax(1.0f - p1 * p1 - p2 * p2, 0.0f))));
  return pg_normalize3w(pg_make_float3w(alpha * nh.x, alpha * nh.y, fmax(nh.z, 1e-6f)));
}

/* pg_bsdf_sample: u_lobe picks the lobe, (u1, u2) the direction; *pdf is 0 where there is no
 * sample (then the direction is whatever the lobe produced, as in the scalar code). */
static inline pg_float3w pg_bsdf_sample_w(pg_lobes_w l, pg_float3w wo, pg_floatw u_lobe,
                                          pg_floatw u1, pg_floatw u2, int any_specular,
                                          __private pg_floatw* pdf) {
  pg_float3w wi = pg_sample_cosine_hemisphere_w(u1, u2);
  if (any_specular) {
    pg_float3w h = pg_ggx_sample_visible_normal_w(wo, l.alpha, u1, u2);
    pg_float3w reflected = pg_sub3w(pg_scale3w(h, 2.0f * pg_dot3w(wo, h)), wo);
    wi = pg_select3w(wi, reflected, u_lobe < l.p_specular);
  }
  *pdf = pg_bsdf_pdf_w(l, wo, wi, any_specular);
  return wi;
}

#endif

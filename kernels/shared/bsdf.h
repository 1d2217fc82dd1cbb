/* The material model: Lambert diffuse plus a GGX microfacet reflection lobe with the
 * metallic/roughness parameterisation of glTF, evaluated, sampled and given a density in
 * the local shading frame (z = shading normal). Used by the host path tracer, the device
 * sampler and trainer of the guiding mixture (paper, eq. 2: the f_r component), and tests.
 *
 * References: Walter et al. 2007 (GGX), Heitz 2014 (height-correlated Smith), Heitz 2018
 * (sampling the distribution of visible normals), Schlick's Fresnel approximation. */
#ifndef RTPG_SHARED_BSDF_H
#define RTPG_SHARED_BSDF_H

#include "shared/compat.h"
#include "shared/mapping.h"
#include "shared/sincos.h"

PG_NAMESPACE_BEGIN

typedef struct {
  float3 base_color;
  float roughness; /* perceptual; alpha = roughness^2 */
  float metallic;
  float specular; /* dielectric F0; 0 = no GGX lobe (pure Lambert) */
} pg_material;

/* Roughness below this is treated as this: keeps D finite in float32. */
#define PG_MIN_ROUGHNESS 0.02f

typedef struct {
  float3 diffuse;   /* Lambert albedo (already scaled by 1 - metallic and 1 - F0) */
  float3 f0;        /* Fresnel reflectance at normal incidence */
  float alpha;      /* GGX alpha */
  float p_specular; /* probability of sampling the GGX lobe, for outgoing direction wo */
} pg_lobes;

PG_FN float3 pg_fresnel_schlick(float3 f0, float cos_theta) {
  float m = clamp(1.0f - cos_theta, 0.0f, 1.0f);
  float m5 = (m * m) * (m * m) * m;
  return f0 + (pg_make_float3(1.0f, 1.0f, 1.0f) - f0) * m5;
}

PG_FN pg_lobes pg_make_lobes(pg_material m, float3 wo) {
  pg_lobes l;
  float metallic = clamp(m.metallic, 0.0f, 1.0f);
  float spec = clamp(m.specular, 0.0f, 1.0f);
  float3 dielectric_f0 = pg_make_float3(spec, spec, spec);
  l.f0 = mix(dielectric_f0, m.base_color, metallic);
  /* The diffuse layer sees what the dielectric coating does not reflect (see pg_bsdf_eval). */
  l.diffuse = m.base_color * ((1.0f - metallic) * (1.0f - spec));
  float r = fmax(m.roughness, PG_MIN_ROUGHNESS);
  l.alpha = r * r;
  float w_spec = pg_luminance(pg_fresnel_schlick(l.f0, fmax(wo.z, 0.0f)));
  float w_diff = pg_luminance(l.diffuse);
  float has_spec = pg_max3(l.f0) > 0.0f ? 1.0f : 0.0f;
  /* Without a diffuse layer (a metal) the specular lobe's share is 1 by definition, not w / w:
   * a device's division may be 2.5 ulp off (docs/design.md, "Floating point on other devices"),
   * and a share of 1 - 2^-24 gave the cosine lobe a density that is 1.5e-3 of a sharp metal's
   * far from its peak on an H200. */
  l.p_specular = has_spec * (w_diff > 0.0f ? w_spec / (w_spec + w_diff) : 1.0f);
  /* Keep both strategies alive so neither lobe is undersampled. */
  if (has_spec > 0.0f && w_diff > 0.0f) l.p_specular = clamp(l.p_specular, 0.1f, 0.9f);
  return l;
}

/* D(h) = a2 / (pi d^2) with d = 1 - cos^2 (1 - a2) = sin^2 + a2 cos^2 for a unit h. The second
 * form, with sin^2 = h.x^2 + h.y^2, has no cancellation: near the peak of a sharp lobe d is of
 * the order of a2 (1.6e-7 at the smallest roughness), which the first form got as the difference
 * of two numbers near 1 whose rounding (and a compiler's freedom to contract it into an fma) is
 * of the same size, so D was known only to a factor of several there (docs/design.md,
 * "Floating point on other devices"). */
PG_FN float pg_ggx_d(float3 h, float alpha) {
  float a2 = alpha * alpha;
  float d = (h.x * h.x + h.y * h.y) + a2 * (h.z * h.z);
  return a2 / (PG_PI * d * d);
}

/* Smith Lambda for GGX. */
PG_FN float pg_ggx_lambda(float3 w, float alpha) {
  float c2 = w.z * w.z;
  if (c2 <= 0.0f) return 0.0f;
  float t2 = fmax(1.0f - c2, 0.0f) / c2;
  return 0.5f * (-1.0f + sqrt(1.0f + alpha * alpha * t2));
}

PG_FN float pg_ggx_g1(float3 w, float alpha) {
  return 1.0f / (1.0f + pg_ggx_lambda(w, alpha));
}

PG_FN float pg_ggx_g2(float3 wo, float3 wi, float alpha) {
  return 1.0f / (1.0f + pg_ggx_lambda(wo, alpha) + pg_ggx_lambda(wi, alpha));
}

/* f_r(wo, wi) (reflection only; both directions in the upper local hemisphere). */
PG_FN float3 pg_bsdf_eval(pg_lobes l, float3 wo, float3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return pg_make_float3(0.0f, 0.0f, 0.0f);
  float3 f = l.diffuse * PG_INV_PI;
  if (l.p_specular > 0.0f) {
    /* Under a specular coating the diffuse layer gets what the coating transmits, both ways:
     * Ashikhmin and Shirley 2000, eq. 5 (energy conserving and reciprocal). Without a
     * coating the lobe stays exactly Lambertian. */
    float a = 1.0f - 0.5f * wi.z, b = 1.0f - 0.5f * wo.z;
    float ta = 1.0f - (a * a) * (a * a) * a, tb = 1.0f - (b * b) * (b * b) * b;
    f = l.diffuse * ((28.0f / 23.0f) * PG_INV_PI * ta * tb);
    float3 h = normalize(wo + wi);
    float3 F = pg_fresnel_schlick(l.f0, dot(wi, h));
    float spec = pg_ggx_d(h, l.alpha) * pg_ggx_g2(wo, wi, l.alpha) / (4.0f * wo.z * wi.z);
    f = f + F * spec;
  }
  return f;
}

/* Density of pg_bsdf_sample over solid angle. */
PG_FN float pg_bsdf_pdf(pg_lobes l, float3 wo, float3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  float pdf = (1.0f - l.p_specular) * pg_cosine_hemisphere_pdf(wi.z);
  if (l.p_specular > 0.0f) {
    float3 h = normalize(wo + wi);
    /* Visible-normal density D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z, times the
     * reflection Jacobian 1 / (4 wo.h). */
    float pdf_spec = pg_ggx_g1(wo, l.alpha) * pg_ggx_d(h, l.alpha) / (4.0f * wo.z);
    pdf += l.p_specular * pdf_spec;
  }
  return pdf;
}

/* Heitz 2018: a microfacet normal from the distribution of normals visible from wo. */
PG_FN float3 pg_ggx_sample_visible_normal(float3 wo, float alpha, float u1, float u2) {
  float3 vh = normalize(pg_make_float3(alpha * wo.x, alpha * wo.y, wo.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  float3 t1 = lensq > 0.0f ? pg_make_float3(-vh.y, vh.x, 0.0f) * (1.0f / sqrt(lensq))
                           : pg_make_float3(1.0f, 0.0f, 0.0f);
  float3 t2 = cross(vh, t1);
  float r = sqrt(u1);
  float2 cs = pg_cos_sin_turn(u2); /* phi = 2 pi u2 */
  float p1 = r * cs.x;
  float p2 = r * cs.y;
  float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * pg_safe_sqrt(1.0f - p1 * p1) + s * p2;
  float3 nh = t1 * p1 + t2 * p2 + vh * pg_safe_sqrt(1.0f - p1 * p1 - p2 * p2);
  return normalize(pg_make_float3(alpha * nh.x, alpha * nh.y, fmax(nh.z, 1e-6f)));
}

typedef struct {
  float3 wi;
  float pdf; /* pg_bsdf_pdf(wo, wi); 0 = no sample */
} pg_bsdf_sample_t;

/* One direction from the lobe mixture; u_lobe picks the lobe, (u1, u2) the direction. */
PG_FN pg_bsdf_sample_t pg_bsdf_sample(pg_lobes l, float3 wo, float u_lobe, float u1, float u2) {
  pg_bsdf_sample_t s;
  s.wi = pg_make_float3(0.0f, 0.0f, 1.0f);
  s.pdf = 0.0f;
  if (wo.z <= 0.0f) return s;
  if (u_lobe < l.p_specular) {
    float3 h = pg_ggx_sample_visible_normal(wo, l.alpha, u1, u2);
    s.wi = h * (2.0f * dot(wo, h)) - wo;
    if (s.wi.z <= 0.0f) return s;
  } else {
    s.wi = pg_sample_cosine_hemisphere(pg_make_float2(u1, u2));
    if (s.wi.z <= 0.0f) return s;
  }
  s.pdf = pg_bsdf_pdf(l, wo, s.wi);
  return s;
}

PG_NAMESPACE_END

#endif

/* Spatiotemporal variance-guided filtering (Schied et al., HPG 2017, "SVGF"; docs/denoising.md):
 * the per-pixel math of kernels/svgf_*.cl, shared with the host reference
 * (host/denoise/svgf_reference.cpp) so that tests compare the two pixel by pixel.
 *
 * The denoiser's buffers, the one description of their layout (row-major, pixel i = y * width +
 * x, n = width * height pixels). Its own float4 images are planar: channel c (0..3, x..w) of
 * pixel i at float [c * n + i] (kernels/shared/planar.h), so that a work-item filtering several
 * consecutive pixels loads each channel of them as one vector (svgf_atrous_wide.cl) and
 * neighbouring work-items of a GPU read neighbouring floats:
 *   surface       planar  xyz shading normal, w linear depth of the primary hit (0: no surface)
 *   depth_slope   float   max(|dz/dx|, |dz/dy|) in depth units per pixel (pg_svgf_depth_slope)
 *   integrated    planar  rgb demodulated illumination after temporal accumulation, w 0
 *   moments       planar  x first, y second moment of its luminance (temporal), z history
 *                         length in frames (0: no surface), w 0
 *   illumination  planar  rgb demodulated illumination, w its variance (the a-trous ping-pong)
 *   history       planar  rgb the filtered illumination kept for the next frame (the output of
 *                         a-trous iteration `history_iteration`), w its variance (not read)
 * The inputs are the noisy colour (float4, rgb) and the G-buffer channels of
 * include/rtpg/guiding_layout.h (position_depth, shading_normal, base_color_roughness, flags,
 * material, motion) with the primary hit's emission (float4, rgb), one float4 per pixel, as is
 * the denoised colour: colour = albedo * illumination + emission, so the filter never blurs
 * texture or emitters. */
#ifndef RTPG_SHARED_SVGF_H
#define RTPG_SHARED_SVGF_H

#include "rtpg/guiding_layout.h"
#include "shared/compat.h"
#include "shared/same_surface.h"

PG_NAMESPACE_BEGIN

/* Every tunable of the SVGF kernels, passed by value (plain 4-byte fields). The host builds it
 * from rtpg::SvgfSettings (host/denoise/svgf_settings.h), which documents each. */
typedef struct pg_svgf_settings {
  float alpha_colour;           /* temporal blend weight of the new illumination (paper: 0.2) */
  float alpha_moments;          /* ... of the new luminance moments (paper: 0.2) */
  float max_history;            /* history length cap, frames */
  float min_history;            /* below this many frames variance is estimated spatially (4) */
  float phi_depth;              /* sigma_z of the depth edge-stopping function (paper: 1) */
  uint phi_normal;              /* sigma_n, the normal weight's exponent (paper: 128) */
  float phi_luminance;          /* sigma_l, scales the luminance weight by the std. dev. (4) */
  float reproject_position;     /* history test (shared/same_surface.h): relative distance */
  float reproject_normal;       /* ... and normal cosine */
  float albedo_floor;           /* demodulation divides by max(albedo, albedo_floor) */
  uint history_fallback;        /* 1: the 3x3 neighbourhood where no bilinear tap keeps history */
  uint depth_slope_from_normal; /* 1: pg_svgf_plane_slope; 0: the neighbours' depths */
} pg_svgf_settings;

/* The camera as the depth slope of pg_svgf_plane_slope needs it: its position, its right and up
 * axes (unit), and pixel_size = 2 tan(fov_y / 2) / height, how far the view ray at unit depth
 * moves from one pixel to the next, along either axis. */
typedef struct pg_svgf_view {
  float position_x, position_y, position_z;
  float right_x, right_y, right_z;
  float up_x, up_y, up_z;
  float pixel_size;
} pg_svgf_view;

/* Below this a depth slope counts as flat: keeps phi_z above 0 for surfaces facing the camera,
 * relative to the depth so that no absolute length enters. */
#define PG_SVGF_DEPTH_EPSILON 1.0e-3f
/* Added to the luminance weight's scale, phi_luminance * standard deviation, so that a pixel of
 * zero variance divides by a number (SVGF adds 1e-10 to the variance). The smallest normal
 * float: any absolute radiance would change the weights of scenes lit in small units (radiance
 * 1e-12 has a standard deviation near 1e-12), and this one is below half an ulp of every scale
 * above 2^-102 (docs/robustness.md, "Radiance scale"). */
#define PG_SVGF_LUMINANCE_EPSILON 1.17549435e-38f
/* Illumination is clamped to this magnitude, so that its square and sums of squares over a
 * filter window stay finite in float. */
#define PG_SVGF_MAX_ILLUMINATION 1.0e17f
/* Reprojection keeps history only where the valid bilinear taps carry this much weight. */
#define PG_SVGF_MIN_TAP_WEIGHT 0.01f

PG_FN int pg_svgf_has_surface(uint flags) {
  return (flags & PG_GBUF_SKY) == 0u;
}

/* The albedo the illumination is demodulated by: the primary hit's base colour, each channel at
 * least the floor so that black surfaces do not divide by zero (remodulation multiplies by the
 * same value, so the floor changes only what is filtered, not the identity). */
PG_FN float3 pg_svgf_albedo(float4 base_color_roughness, float albedo_floor) {
  return pg_make_float3(fmax(base_color_roughness.x, albedo_floor),
                        fmax(base_color_roughness.y, albedo_floor),
                        fmax(base_color_roughness.z, albedo_floor));
}

/* Illumination = (colour - emission) / albedo, clamped to +-PG_SVGF_MAX_ILLUMINATION; a
 * non-finite result counts as no light. */
PG_FN float3 pg_svgf_demodulate(float3 colour, float3 emission, float3 albedo) {
  float3 r = pg_make_float3((colour.x - emission.x) / albedo.x, (colour.y - emission.y) / albedo.y,
                            (colour.z - emission.z) / albedo.z);
  if (!pg_all_finite3(r)) return pg_make_float3(0.0f, 0.0f, 0.0f);
  return pg_make_float3(clamp(r.x, -PG_SVGF_MAX_ILLUMINATION, PG_SVGF_MAX_ILLUMINATION),
                        clamp(r.y, -PG_SVGF_MAX_ILLUMINATION, PG_SVGF_MAX_ILLUMINATION),
                        clamp(r.z, -PG_SVGF_MAX_ILLUMINATION, PG_SVGF_MAX_ILLUMINATION));
}

PG_FN float3 pg_svgf_remodulate(float3 illumination, float3 emission, float3 albedo) {
  return pg_make_float3(illumination.x * albedo.x + emission.x,
                        illumination.y * albedo.y + emission.y,
                        illumination.z * albedo.z + emission.z);
}

/* The smaller of the two one-sided differences (centre - before, after - centre), so that a
 * depth edge on one side does not make a flat surface look steep; a neighbour without a surface
 * (depth 0) gives no difference. */
PG_FN float pg_svgf_one_axis_slope(float z, float z_before, float z_after) {
  float a = z_before > 0.0f ? fabs(z - z_before) : PG_FLOAT_MAX;
  float b = z_after > 0.0f ? fabs(z_after - z) : PG_FLOAT_MAX;
  float s = fmin(a, b);
  return s < PG_FLOAT_MAX ? s : 0.0f;
}

/* max(|dz/dx|, |dz/dy|) of the plane through a pixel's surface point p (camera depth z > 0) with
 * its normal n: along the view ray D = (p - camera) / z (unit depth), a pixel's step moves D by
 * pixel_size along right or up, and the plane's depth z = const / (n . D) changes by
 * z pixel_size |n . axis| / |n . D|. Independent of the neighbours' depths, which under the
 * camera's per-pixel jitter lie 0 to 2 pixels apart and make the differences below
 * underestimate the slope (docs/denoising.md, "Where we deviate"). |n . D| is bounded below by
 * 1e-3 (a surface seen edge-on: a large slope, so the depth term stops little there and the
 * normal term decides). */
PG_FN float pg_svgf_plane_slope(float3 n, float3 p, float z, pg_svgf_view v) {
  float3 d = (p - pg_make_float3(v.position_x, v.position_y, v.position_z)) / z;
  float nd = fmax(fabs(dot(n, d)), 1e-3f);
  float nr = fabs(dot(n, pg_make_float3(v.right_x, v.right_y, v.right_z)));
  float nu = fabs(dot(n, pg_make_float3(v.up_x, v.up_y, v.up_z)));
  return z * v.pixel_size * fmax(nr, nu) / nd;
}

/* max(|dz/dx|, |dz/dy|) at a pixel with depth z from its four neighbours' depths (0 outside the
 * image or on sky): the screen-space depth gradient the depth weight is scaled by (SVGF 4.2). */
PG_FN float pg_svgf_depth_slope(float z, float z_left, float z_right, float z_down, float z_up) {
  return fmax(pg_svgf_one_axis_slope(z, z_left, z_right), pg_svgf_one_axis_slope(z, z_down, z_up));
}

/* Bilinear tap t (0..3) of a back-projected position (in pixel indices, centres at integers):
 * writes the tap's pixel and returns its bilinear weight. */
PG_FN float pg_svgf_bilinear_tap(float2 position, int t, PG_PRIVATE int* px, PG_PRIVATE int* py) {
  float fx = floor(position.x), fy = floor(position.y);
  float ax = position.x - fx, ay = position.y - fy;
  int dx = t & 1, dy = t >> 1;
  *px = (int)fx + dx;
  *py = (int)fy + dy;
  return (dx != 0 ? ax : 1.0f - ax) * (dy != 0 ? ay : 1.0f - ay);
}

/* Where no bilinear tap shows this pixel's surface, SVGF's reference implementation filters the
 * 3x3 pixels around the back-projected position instead, each same-surface one with weight 1:
 * under the camera's sub-pixel jitter a pixel on a silhouette or crease sees the other surface
 * at its bilinear taps in about half the frames, and would restart its history each time
 * (docs/denoising.md, "History from the neighbourhood"). Tap t (0 .. PG_HISTORY_CANDIDATES - 1,
 * the order of guiding's reprojection) around the nearest pixel. */
PG_FN void pg_svgf_neighbourhood_tap(float2 position, int t, PG_PRIVATE int* px,
                                     PG_PRIVATE int* py) {
  int dx = 0, dy = 0;
  pg_history_candidate(t, &dx, &dy);
  *px = (int)floor(position.x + 0.5f) + dx;
  *py = (int)floor(position.y + 0.5f) + dy;
}

/* The temporal pass's two sets of history taps: pass 0 the bilinear ones, pass 1 (only where
 * pass 0 kept less than PG_SVGF_MIN_TAP_WEIGHT and history_fallback is on) the neighbourhood,
 * each with weight 1. Writes tap t's pixel and returns its weight. */
PG_FN int pg_svgf_history_taps(int pass) {
  return pass == 0 ? 4 : PG_HISTORY_CANDIDATES;
}
PG_FN float pg_svgf_history_tap(float2 position, int pass, int t, PG_PRIVATE int* px,
                                PG_PRIVATE int* py) {
  if (pass == 0) return pg_svgf_bilinear_tap(position, t, px, py);
  pg_svgf_neighbourhood_tap(position, t, px, py);
  return 1.0f;
}

/* The blend weight of the new frame: the running mean while the history is short (1 / length),
 * then alpha (SVGF 4.1). length counts the new frame. */
PG_FN float pg_svgf_blend_weight(float alpha, float length) {
  return fmax(alpha, 1.0f / length);
}

/* Written out rather than mix() so that host and device do the same roundings (the kernels turn
 * off FP contraction). */
PG_FN float3 pg_svgf_blend3(float3 history, float3 current, float weight_new) {
  return history + (current - history) * weight_new;
}
PG_FN float pg_svgf_blend(float history, float current, float weight_new) {
  return history + (current - history) * weight_new;
}

/* The 1D weights of the a-trous kernel of radius 2, the paper's 5x5 B3 spline (SVGF 4.3: 1/16,
 * 1/4, 3/8, 1/4, 1/16 at offsets -2..2), or of radius 1, a 3x3 kernel with the linear B-spline's
 * 1/4, 1/2, 1/4 (SvgfSettings::atrous_radius; docs/denoising.md, "A 3x3 a-trous kernel"). */
PG_FN float pg_svgf_atrous_weight(int offset, int radius) {
  int a = offset < 0 ? -offset : offset;
  if (radius == 1) return a == 0 ? 0.5f : 0.25f;
  return a == 0 ? 0.375f : (a == 1 ? 0.25f : 0.0625f);
}

/* The 3x3 Gaussian the variance is prefiltered with before it scales the luminance weight
 * (SVGF 4.3): 1/4 at the centre, 1/8 at the edges, 1/16 at the corners. */
PG_FN float pg_svgf_gauss3(int dx, int dy) {
  int a = (dx != 0) + (dy != 0);
  return a == 0 ? 0.25f : (a == 1 ? 0.125f : 0.0625f);
}

/* 1 / (sigma_l * std_dev + eps): the luminance weight's scale at a centre pixel. */
PG_FN float pg_svgf_inverse_phi_luminance(float std_dev, pg_svgf_settings s) {
  return 1.0f / (s.phi_luminance * std_dev + PG_SVGF_LUMINANCE_EPSILON);
}

/* x^n for an integer n >= 0 by repeated squaring: a loop whose trip count is the same for every
 * pixel (vectorises, unlike pow's log and exp). */
PG_FN float pg_svgf_power(float x, uint n) {
  float r = 1.0f;
  for (; n != 0u; n >>= 1) {
    if ((n & 1u) != 0u) r *= x;
    x *= x;
  }
  return r;
}

/* The filter kernels are built with sigma_n as PG_SVGF_PHI_NORMAL (SvgfDenoiser), and
 * PG_SVGF_CONSTANT_POWER(r, x) turns r = 1 into x^PG_SVGF_PHI_NORMAL in straight-line code: the
 * products of pg_svgf_power's loop in the same order, so the same bits. As a loop over a kernel
 * argument's bits (which the compiler did not unroll) its control was a tenth of the wide a-trous
 * pass on PoCL's CPU device (docs/denoising.md, "The normal weight's exponent built in"). Any
 * float type; 13 bits, as SvgfSettings caps sigma_n at 4096. */
#ifdef PG_SVGF_PHI_NORMAL
#if PG_SVGF_PHI_NORMAL < 0 || PG_SVGF_PHI_NORMAL >= 8192
#error "PG_SVGF_PHI_NORMAL must lie in [0, 8192)"
#endif
#define PG_SVGF_POWER_BIT(r, x, b)                          \
  do {                                                      \
    if (((PG_SVGF_PHI_NORMAL >> (b)) & 1) != 0) (r) *= (x); \
    if ((PG_SVGF_PHI_NORMAL >> ((b) + 1)) != 0) (x) *= (x); \
  } while (0)
#define PG_SVGF_CONSTANT_POWER(r, x) \
  PG_SVGF_POWER_BIT(r, x, 0);        \
  PG_SVGF_POWER_BIT(r, x, 1);        \
  PG_SVGF_POWER_BIT(r, x, 2);        \
  PG_SVGF_POWER_BIT(r, x, 3);        \
  PG_SVGF_POWER_BIT(r, x, 4);        \
  PG_SVGF_POWER_BIT(r, x, 5);        \
  PG_SVGF_POWER_BIT(r, x, 6);        \
  PG_SVGF_POWER_BIT(r, x, 7);        \
  PG_SVGF_POWER_BIT(r, x, 8);        \
  PG_SVGF_POWER_BIT(r, x, 9);        \
  PG_SVGF_POWER_BIT(r, x, 10);       \
  PG_SVGF_POWER_BIT(r, x, 11);       \
  PG_SVGF_POWER_BIT(r, x, 12)
#elif defined(__OPENCL_VERSION__)
#error "the SVGF kernels need the build option PG_SVGF_PHI_NORMAL (SvgfDenoiser passes sigma_n)"
#endif

/* The normal weight's power x^sigma_n: the build option in a kernel, the setting on the host. */
PG_FN float pg_svgf_normal_power(float x, pg_svgf_settings s) {
#ifdef PG_SVGF_PHI_NORMAL
  (void)s;
  float r = 1.0f;
  PG_SVGF_CONSTANT_POWER(r, x);
  return r;
#else
  return pg_svgf_power(x, s.phi_normal);
#endif
}

/* 1 / phi_z, the depth weight's scale between the centre pixel (depth depth_c, depth slope
 * slope_c) and a tap `distance` pixels away (SVGF eq. 3): phi_z = sigma_z * slope_c * distance +
 * eps * depth_c. The filters take it once per pixel for each squared tap distance
 * (pg_svgf_squared_distance) instead of dividing at every tap: the division was a sixth of the
 * a-trous pass's time (docs/denoising.md, "One division per tap distance"). */
PG_FN float pg_svgf_inverse_phi_depth(float slope_c, float depth_c, float distance,
                                      pg_svgf_settings s) {
  return 1.0f / (s.phi_depth * slope_c * distance + PG_SVGF_DEPTH_EPSILON * depth_c);
}

/* A tap (dx, dy)'s squared distance from its centre: the index of its 1 / phi_z in the per-pixel
 * table of a filter of radius r (2 for the a-trous 5x5 kernel, 3 for the variance pass's 7x7
 * neighbourhood), PG_SVGF_SQUARED_DISTANCES(r) entries, filled where some tap lies
 * (pg_svgf_is_tap_squared_distance: 6 of 9 entries for the 5x5 kernel, 10 of 19 for the 7x7). */
#define PG_SVGF_SQUARED_DISTANCES(radius) (2 * (radius) * (radius) + 1)
PG_FN int pg_svgf_squared_distance(int dx, int dy) {
  return dx * dx + dy * dy;
}
/* Whether a tap (dx, dy), |dx|, |dy| <= radius, lies at that squared distance. For the filters'
 * radii (1 and 2 of the a-trous kernels, 3 of the variance's 7x7) a bit of a constant: the search
 * kept the kernels' table in a loop of branches, 4-5% of either filter on PoCL's CPU device
 * (docs/denoising.md, "The normal weight's exponent built in"). */
PG_FN int pg_svgf_is_tap_squared_distance(int squared_distance, int radius) {
  if (radius >= 1 && radius <= 3) {
    /* bits {0, 1, 2}, then also {4, 5, 8}, then also {9, 10, 13, 18} */
    const uint taps = radius == 1 ? 0x7u : radius == 2 ? 0x137u : 0x42737u;
    return squared_distance >= 0 && squared_distance < 32
               ? (int)((taps >> (uint)squared_distance) & 1u)
               : 0;
  }
  for (int a = 0; a <= radius; ++a)
    for (int b = a; b <= radius; ++b)
      if (a * a + b * b == squared_distance) return 1;
  return 0;
}

/* table[d2] = 1 / phi_z at the distance step * sqrt(d2) for every squared tap distance d2 of a
 * filter of that radius, 0 in the entries no tap reads; step is the filter's tap spacing in
 * pixels (the a-trous iteration's step, 1 for the variance pass). */
PG_FN void pg_svgf_inverse_phi_depth_table(float slope_c, float depth_c, float step, int radius,
                                           pg_svgf_settings s, float* table) {
  for (int d2 = 0; d2 < PG_SVGF_SQUARED_DISTANCES(radius); ++d2)
    table[d2] = pg_svgf_is_tap_squared_distance(d2, radius)
                    ? pg_svgf_inverse_phi_depth(slope_c, depth_c, step * sqrt((float)d2), s)
                    : 0.0f;
}

/* The edge-stopping weight between the centre pixel c and a tap q (SVGF eq. 3-5):
 *   depth      exp(-|z_c - z_q| * inverse_phi_z), from pg_svgf_inverse_phi_depth at the tap's
 *              distance;
 *   normal     max(0, n_c . n_q)^sigma_n (sigma_n an integer, pg_svgf_normal_power);
 *   luminance  exp(-|l_c - l_q| * inverse_phi_l), inverse_phi_l from
 *              pg_svgf_inverse_phi_luminance (0: no luminance term).
 * One exp for depth and luminance. A tap without a surface (depth 0) gets 0. */
PG_FN float pg_svgf_edge_weight(float4 surface_c, float luminance_c, float4 surface_q,
                                float luminance_q, float inverse_phi_z, float inverse_phi_l,
                                pg_svgf_settings s) {
  float cos_n = fmin(fmax(dot(pg_float4_xyz(surface_c), pg_float4_xyz(surface_q)), 0.0f), 1.0f);
  float e = fabs(surface_c.w - surface_q.w) * inverse_phi_z +
            fabs(luminance_c - luminance_q) * inverse_phi_l;
  float w = pg_svgf_normal_power(cos_n, s) * exp(-e);
  return surface_q.w > 0.0f ? w : 0.0f;
}

/* Variance from temporal moments; a short history boosts it (SVGF 4.2: 4 / length) since
 * few frames underestimate it. */
PG_FN float pg_svgf_variance(float m1, float m2, float length, float min_history) {
  /* The square rounded on its own, never fused into the subtraction (the variance pass allows
   * multiply-adds): where the luminance has been one value l, m2 is l*l rounded, and only the
   * rounded square cancels it to 0; fused, 2^-24 l^2 of variance would be left. */
  float square = m1 * m1;
  float v = fmax(m2 - square, 0.0f);
  return length < min_history ? v * (min_history / fmax(length, 1.0f)) : v;
}

PG_NAMESPACE_END

#endif

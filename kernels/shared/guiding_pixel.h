/* What the three guiding kernels read of one G-buffer pixel (layout: include/rtpg/
 * guiding_layout.h): the rule for which pixels guiding skips (paper, section 5: sky,
 * emitters, transmission, roughness near zero) and the pixel's material; the history test
 * of reprojection is shared/same_surface.h. */
#ifndef RTPG_SHARED_GUIDING_PIXEL_H
#define RTPG_SHARED_GUIDING_PIXEL_H

#include "rtpg/guiding_layout.h"
#include "shared/bsdf.h"
#include "shared/compat.h"
#include "shared/pmm.h"
#include "shared/same_surface.h"

PG_NAMESPACE_BEGIN

PG_FN int pg_guiding_applies(uint flags, float roughness, pg_kernel_settings p) {
  if ((flags & (PG_GBUF_SKY | PG_GBUF_EMITTER | PG_GBUF_DELTA | PG_GBUF_TRANSMISSIVE)) != 0u)
    return 0;
  return roughness > p.roughness_skip;
}

/* Models shared by rows (docs/guiding.md, "Models shared by rows"): with rows_per_model R, a
 * pixel of row y may sample with the model of the pixel above it in row pg_model_row(y), the
 * first of its group of R rows, and then trains none of its own. */
PG_FN int pg_model_row(int y, pg_kernel_settings p) {
  return y - y % p.rows_per_model;
}

/* Whether a pixel's model may serve a neighbour's, or the neighbour use it: guided, and without
 * a narrow glossy lobe, whose direction moves from pixel to pixel with the normal and the view
 * (Lambert, or a roughness of at least PG_SHARED_MODEL_MIN_ROUGHNESS: sharing under
 * cornell-glossy's 0.218 cost 2.5% of its error, the sunlit room's 0.5 nothing). */
#define PG_SHARED_MODEL_MIN_ROUGHNESS 0.4f
PG_FN int pg_model_sharable(uint flags, float4 base_color_roughness, float4 metallic_specular,
                            pg_kernel_settings p) {
  if (!pg_guiding_applies(flags, base_color_roughness.w, p)) return 0;
  return (metallic_specular.x <= 0.0f && metallic_specular.y <= 0.0f) ||
         base_color_roughness.w >= PG_SHARED_MODEL_MIN_ROUGHNESS;
}

/* What pg_shares_model reads of a G-buffer pixel. */
typedef struct {
  uint flags, material;
  float4 base_color_roughness, metallic_specular, position_depth;
  float3 normal;
} pg_sharing_pixel;

/* Whether pixel a samples with the model of pixel m, the first of its group's rows: both
 * sharable, the same surface by reprojection's test (pg_same_surface), and shading normals
 * within about 1.1 degrees: the model is used in a's frame as it is, and a bump map's normals
 * vary from pixel to pixel (Sponza at 960x540, rows in pairs: 25 degrees +4.8% error, 8
 * degrees +2.4%, 1.1 degrees +0.8%). Close normals give close frames only on one side of the
 * z = 0 plane: pg_frame_from_normal's tangent turns half a turn about the normal where n.z
 * changes sign (pmm.h, pg_pmm_needs_reframe), so on a wall facing x or y a lobe used across it
 * would point the other way; the two normals' z must have one sign. Where it holds, the sample
 * kernel also writes m's state as a's own, which train then leaves alone: a pixel that stops
 * sharing (its jittered normal or position moves, the camera moves) starts from its neighbour's
 * model instead of from the untrained state it would otherwise have kept (docs/guiding.md, "Models
 * shared by rows"). */
#define PG_SHARED_MODEL_MIN_NORMAL_COS 0.9998f
PG_FN int pg_shares_model(pg_sharing_pixel a, pg_sharing_pixel m, pg_kernel_settings p) {
  return pg_model_sharable(a.flags, a.base_color_roughness, a.metallic_specular, p) &&
         pg_model_sharable(m.flags, m.base_color_roughness, m.metallic_specular, p) &&
         pg_same_surface(a.position_depth, a.normal, a.material, m.position_depth, m.normal,
                         m.material, p.reproject_position,
                         fmax(p.reproject_normal, PG_SHARED_MODEL_MIN_NORMAL_COS)) &&
         copysign(1.0f, a.normal.z) == copysign(1.0f, m.normal.z);
}

#ifdef __OPENCL_C_VERSION__
#include "shared/kernel_args.h"

static inline pg_sharing_pixel pg_sharing_pixel_at(PG_ARGS_GBUFFER uint i) {
  pg_sharing_pixel s;
  s.flags = flags[i];
  s.material = material[i];
  s.base_color_roughness = base_color_roughness[i];
  s.metallic_specular = metallic_specular[i];
  s.position_depth = position_depth[i];
  s.normal = shading_normal[i].xyz;
  return s;
}

/* The pixel whose model pixel (x, y) samples with: the one above it in row pg_model_row(y)
 * where pg_shares_model holds, else (x, y) itself. */
static inline uint pg_model_pixel(PG_ARGS_GBUFFER uint x, uint y, uint width,
                                  pg_kernel_settings p) {
  uint i = y * width + x;
  int model_y = pg_model_row((int)y, p);
  if (model_y == (int)y) return i;
  uint m = (uint)model_y * width + x;
  return pg_shares_model(pg_sharing_pixel_at(PG_PASS_GBUFFER i),
                         pg_sharing_pixel_at(PG_PASS_GBUFFER m), p)
             ? m
             : i;
}

/* pg_model_pixel where the frame's decision may already be made (include/rtpg/guiding_layout.h,
 * "Shared models"): read from shares_model where `decided`, else made here and, where `record`,
 * written there for the frame's later kernels. */
static inline uint pg_frame_model_pixel(PG_ARGS_GBUFFER __global uchar* shares_model, uint decided,
                                        int record, uint x, uint y, uint width,
                                        pg_kernel_settings p) {
  uint i = y * width + x;
  if (p.rows_per_model <= 1) return i;
  if (decided) return shares_model[i] != 0 ? (uint)pg_model_row((int)y, p) * width + x : i;
  uint m = pg_model_pixel(PG_PASS_GBUFFER x, y, width, p);
  if (record) shares_model[i] = (uchar)(m != i);
  return m;
}
#endif

PG_FN pg_material pg_material_from_gbuffer(float4 base_color_roughness, float4 metallic_specular) {
  pg_material m;
  m.base_color = pg_float4_xyz(base_color_roughness);
  m.roughness = base_color_roughness.w;
  m.metallic = metallic_specular.x;
  m.specular = metallic_specular.y;
  return m;
}

PG_NAMESPACE_END

#endif

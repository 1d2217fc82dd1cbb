/* The G-buffer as it crosses the bus to a device with memory of its own (include/rtpg/
 * guiding_layout.h, "Packed G-buffer"): the host packs each pixel into 48 bytes instead of the
 * layout's 96 and the device's unpack_gbuffer kernel (kernels/unpack_gbuffer.cl) writes the
 * layout's channels back, so the guiding and SVGF kernels read the one layout they always read.
 *
 * What rounds, and why that keeps the renderer unbiased (docs/design.md, "What crosses the
 * bus"): positions, depths, motion vectors, flags and material ids travel exactly; the shading
 * normal and the view direction as octahedral unit vectors (within PG_OCTAHEDRAL_MAX_ANGLE);
 * base colour, roughness, metallic and specular as half floats (relative error at most 2^-11).
 * The device samples the first bounce with its rounded BSDF and frame and returns the density of
 * what it did, which is all the host's estimate f / pdf needs; the host's MIS weights, its BSDF
 * and its VPLs use its own exact G-buffer. */
#ifndef RTPG_SHARED_GBUFFER_PACKING_H
#define RTPG_SHARED_GBUFFER_PACKING_H

#include "shared/bit_packing.h"

PG_NAMESPACE_BEGIN

/* Material ids above this do not fit beside the flags (pg_pack_gbuffer_shading). */
#define PG_PACKED_MATERIAL_MAX 0xffffffu

/* surface: position (exact) and the shading normal. */
PG_FN uint4 pg_pack_gbuffer_surface(float4 position_depth, float4 shading_normal) {
  return pg_make_uint4(as_uint(position_depth.x), as_uint(position_depth.y),
                       as_uint(position_depth.z),
                       pg_pack_unit_vector(pg_float4_xyz(shading_normal)));
}
/* view_material: depth (exact), the view direction, base colour and roughness. */
PG_FN uint4 pg_pack_gbuffer_view_material(float4 position_depth, float4 view_dir,
                                          float4 base_color_roughness) {
  return pg_make_uint4(as_uint(position_depth.w), pg_pack_unit_vector(pg_float4_xyz(view_dir)),
                       pg_pack_half2(base_color_roughness.x, base_color_roughness.y),
                       pg_pack_half2(base_color_roughness.z, base_color_roughness.w));
}
/* shading: metallic and specular, then the flags (PG_GBUF_* fit in 8 bits) and the material id
 * (at most PG_PACKED_MATERIAL_MAX; the host packer refuses larger ids). */
PG_FN uint2 pg_pack_gbuffer_shading(float4 metallic_specular, uint flags, uint material) {
  return pg_make_uint2(pg_pack_half2(metallic_specular.x, metallic_specular.y),
                       (flags & 0xffu) | (material << 8));
}

PG_FN float4 pg_unpack_gbuffer_position_depth(uint4 surface, uint4 view_material) {
  return pg_make_float4(as_float(surface.x), as_float(surface.y), as_float(surface.z),
                        as_float(view_material.x));
}
PG_FN float4 pg_unpack_gbuffer_shading_normal(uint4 surface) {
  float3 n = pg_unpack_unit_vector(surface.w);
  return pg_make_float4(n.x, n.y, n.z, 0.0f);
}
PG_FN float4 pg_unpack_gbuffer_view_dir(uint4 view_material) {
  float3 v = pg_unpack_unit_vector(view_material.y);
  return pg_make_float4(v.x, v.y, v.z, 0.0f);
}
PG_FN float4 pg_unpack_gbuffer_base_color_roughness(uint4 view_material) {
  return pg_make_float4(pg_float_of_half(view_material.z), pg_float_of_half(view_material.z >> 16),
                        pg_float_of_half(view_material.w), pg_float_of_half(view_material.w >> 16));
}
PG_FN float4 pg_unpack_gbuffer_metallic_specular(uint2 shading) {
  return pg_make_float4(pg_float_of_half(shading.x), pg_float_of_half(shading.x >> 16), 0.0f, 0.0f);
}
PG_FN uint pg_unpack_gbuffer_flags(uint2 shading) {
  return shading.y & 0xffu;
}
PG_FN uint pg_unpack_gbuffer_material(uint2 shading) {
  return shading.y >> 8;
}

PG_NAMESPACE_END

#endif

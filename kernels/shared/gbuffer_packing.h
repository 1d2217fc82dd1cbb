/* The G-buffer as it crosses the bus to a device with memory of its own (include/rtpg/
 * guiding_layout.h, "Packed G-buffer"): the host packs each pixel into 32 bytes instead of the
 * layout's 96 and the device's unpack_gbuffer kernel (kernels/unpack_gbuffer.cl) writes the
 * layout's channels back, so the guiding and SVGF kernels read the one layout they always read.
 *
 * What rounds, and why that keeps the renderer unbiased (docs/design.md, "What crosses the
 * bus"): positions, flags and material ids travel exactly; the shading normal as an octahedral
 * unit vector (within PG_OCTAHEDRAL_MAX_ANGLE); base colour, roughness, metallic and specular as
 * half floats (relative error at most 2^-11). The depth, the view direction and the motion
 * vector do not travel: the device computes them from the exact position and the frame's two
 * pinhole cameras with the host's formulas (pg_gbuffer_depth, pg_gbuffer_view_dir,
 * pg_gbuffer_motion), which agree with the host's own to rounding (the host's view direction is
 * its camera ray's, the same line). The device samples the first bounce with its rounded BSDF
 * and frame and returns the density of what it did, which is all the host's estimate f / pdf
 * needs; the host's MIS weights, its BSDF and its VPLs use its own exact G-buffer. */
#ifndef RTPG_SHARED_GBUFFER_PACKING_H
#define RTPG_SHARED_GBUFFER_PACKING_H

#include "rtpg/guiding_layout.h"
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
/* shading: base colour, roughness, metallic and specular, then the flags (PG_GBUF_* fit in 8
 * bits) and the material id (at most PG_PACKED_MATERIAL_MAX; the host packer refuses larger
 * ids). */
PG_FN uint4 pg_pack_gbuffer_shading(float4 base_color_roughness, float4 metallic_specular,
                                    uint flags, uint material) {
  return pg_make_uint4(pg_pack_half2(base_color_roughness.x, base_color_roughness.y),
                       pg_pack_half2(base_color_roughness.z, base_color_roughness.w),
                       pg_pack_half2(metallic_specular.x, metallic_specular.y),
                       (flags & 0xffu) | (material << 8));
}

PG_FN float3 pg_unpack_gbuffer_position(uint4 surface) {
  return pg_make_float3(as_float(surface.x), as_float(surface.y), as_float(surface.z));
}
PG_FN float4 pg_unpack_gbuffer_shading_normal(uint4 surface) {
  float3 n = pg_unpack_unit_vector(surface.w);
  return pg_make_float4(n.x, n.y, n.z, 0.0f);
}
PG_FN float4 pg_unpack_gbuffer_base_color_roughness(uint4 shading) {
  return pg_make_float4(pg_float_of_half(shading.x), pg_float_of_half(shading.x >> 16),
                        pg_float_of_half(shading.y), pg_float_of_half(shading.y >> 16));
}
PG_FN float4 pg_unpack_gbuffer_metallic_specular(uint4 shading) {
  return pg_make_float4(pg_float_of_half(shading.z), pg_float_of_half(shading.z >> 16), 0.0f, 0.0f);
}
PG_FN uint pg_unpack_gbuffer_flags(uint4 shading) {
  return shading.w & 0xffu;
}
PG_FN uint pg_unpack_gbuffer_material(uint4 shading) {
  return shading.w >> 8;
}

/* What the device derives (include/rtpg/guiding_layout.h, "Cameras"), by the host's formulas:
 * the linear depth of a surface point (the renderer's G-buffer, host/render/renderer.cpp), the
 * unit vector from it towards the camera, and the offset in pixels from pixel (x, y) to where
 * the point was in the previous camera's image (CameraFrame::project; zero where the camera did
 * not move or the point was behind it). A sky pixel (position 0) has depth 0, no motion and a
 * view direction it never uses. */
PG_FN float3 pg_camera_position(pg_pinhole_camera c) {
  return pg_make_float3(c.position_x, c.position_y, c.position_z);
}
PG_FN float3 pg_camera_forward(pg_pinhole_camera c) {
  return pg_make_float3(c.forward_x, c.forward_y, c.forward_z);
}
PG_FN float pg_gbuffer_depth(pg_pinhole_camera c, float3 position) {
  return dot(position - pg_camera_position(c), pg_camera_forward(c));
}
PG_FN float4 pg_gbuffer_view_dir(pg_pinhole_camera c, float3 position) {
  float3 v = pg_camera_position(c) - position;
  float3 u = dot(v, v) > 0.0f ? normalize(v) : -pg_camera_forward(c);
  return pg_make_float4(u.x, u.y, u.z, 0.0f);
}
PG_FN float2 pg_gbuffer_motion(pg_gbuffer_cameras cameras, float3 position, uint x, uint y) {
  if (!cameras.moved) return pg_make_float2(0.0f, 0.0f);
  pg_pinhole_camera c = cameras.previous;
  float3 d = position - pg_camera_position(c);
  float z = dot(d, pg_camera_forward(c));
  if (!(z > 0.0f)) return pg_make_float2(0.0f, 0.0f);
  float px = dot(d, pg_make_float3(c.right_x, c.right_y, c.right_z)) / z;
  float py = dot(d, pg_make_float3(c.up_x, c.up_y, c.up_z)) / z;
  float sx = 0.5f * (px / (c.tan_half_fov_y * c.aspect) + 1.0f);
  float sy = 0.5f * (1.0f - py / c.tan_half_fov_y);
  return pg_make_float2(sx * (float)cameras.width - ((float)x + 0.5f),
                        sy * (float)cameras.height - ((float)y + 0.5f));
}

/* The G-buffer's layout of pixel (x, y) from its packed form and the frame's cameras. */
PG_FN float4 pg_unpack_gbuffer_position_depth(uint4 surface, uint4 shading,
                                              pg_gbuffer_cameras cameras) {
  float3 p = pg_unpack_gbuffer_position(surface);
  float depth = (pg_unpack_gbuffer_flags(shading) & PG_GBUF_SKY) != 0u
                    ? 0.0f
                    : pg_gbuffer_depth(cameras.current, p);
  return pg_make_float4(p.x, p.y, p.z, depth);
}

PG_NAMESPACE_END

#endif

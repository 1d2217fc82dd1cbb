/* The G-buffer as it crosses the bus to a device with memory of its own (include/rtpg/
 * guiding_layout.h, "Packed G-buffer"): the host packs each pixel into 24 bytes instead of the
 * layout's 96 and the device's unpack_gbuffer kernel (kernels/unpack_gbuffer.cl) writes the
 * layout's channels back, so the guiding and SVGF kernels read the one layout they always read.
 *
 * What rounds, and why that keeps the renderer unbiased (docs/design.md, "What crosses the
 * bus"): depths, flags and material ids travel exactly; the shading normal as an octahedral unit
 * vector (within PG_OCTAHEDRAL_MAX_ANGLE); base colour, roughness, metallic and specular as half
 * floats (relative error at most 2^-11). The position, the view direction and the motion vector
 * do not travel: the device follows the pixel's camera ray, the renderer's own, to the depth
 * (pg_gbuffer_camera_ray, pg_gbuffer_position_depth), which puts the point within a few
 * units in the last place of the host's (the host interpolates it from the triangle's corners),
 * and projects it into last frame's camera (pg_gbuffer_motion). The device samples the first
 * bounce with its rounded BSDF and frame and returns the density of what it did, which is all
 * the host's estimate f / pdf needs; the host's MIS weights, its BSDF and its VPLs use its own
 * exact G-buffer, and the device's position serves only training and reprojection. */
#ifndef RTPG_SHARED_GBUFFER_PACKING_H
#define RTPG_SHARED_GBUFFER_PACKING_H

#include "rtpg/guiding_layout.h"
#include "shared/bit_packing.h"
#include "shared/rng.h"

PG_NAMESPACE_BEGIN

/* Material ids above this do not fit beside the flags (pg_pack_gbuffer_shading). */
#define PG_PACKED_MATERIAL_MAX 0xffffffu

/* surface: depth (exact), the shading normal, base colour and roughness. */
PG_FN uint4 pg_pack_gbuffer_surface(float4 position_depth, float4 shading_normal,
                                    float4 base_color_roughness) {
  return pg_make_uint4(as_uint(position_depth.w),
                       pg_pack_unit_vector(pg_float4_xyz(shading_normal)),
                       pg_pack_half2(base_color_roughness.x, base_color_roughness.y),
                       pg_pack_half2(base_color_roughness.z, base_color_roughness.w));
}
/* shading: metallic and specular, then the flags (PG_GBUF_* fit in 8 bits) and the material id
 * (at most PG_PACKED_MATERIAL_MAX; the host packer refuses larger ids). */
PG_FN uint2 pg_pack_gbuffer_shading(float4 metallic_specular, uint flags, uint material) {
  return pg_make_uint2(pg_pack_half2(metallic_specular.x, metallic_specular.y),
                       (flags & 0xffu) | (material << 8));
}

PG_FN float pg_unpack_gbuffer_depth(uint4 surface) {
  return as_float(surface.x);
}
PG_FN float4 pg_unpack_gbuffer_shading_normal(uint4 surface) {
  float3 n = pg_unpack_unit_vector(surface.y);
  return pg_make_float4(n.x, n.y, n.z, 0.0f);
}
PG_FN float4 pg_unpack_gbuffer_base_color_roughness(uint4 surface) {
  return pg_make_float4(pg_float_of_half(surface.z), pg_float_of_half(surface.z >> 16),
                        pg_float_of_half(surface.w), pg_float_of_half(surface.w >> 16));
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

/* What the device derives (include/rtpg/guiding_layout.h, "Cameras"), by the host's formulas. */
PG_FN float3 pg_camera_position(pg_pinhole_camera c) {
  return pg_make_float3(c.position_x, c.position_y, c.position_z);
}
PG_FN float3 pg_camera_forward(pg_pinhole_camera c) {
  return pg_make_float3(c.forward_x, c.forward_y, c.forward_z);
}
/* Pixel (x, y)'s camera ray direction (host/render/camera_rays.cpp, CameraFrame::ray_direction:
 * the same draws and operations in the same order). */
PG_FN float3 pg_gbuffer_camera_ray(pg_gbuffer_cameras cameras, uint x, uint y) {
  float jx = 0.5f, jy = 0.5f;
  if (cameras.jitter) {
    pg_rng rng = pg_rng_make(cameras.jitter_seed, y * (uint)cameras.width + x, cameras.jitter_frame,
                             0u, PG_RNG_STREAM_CAMERA);
    jx = pg_rng_next(&rng);
    jy = pg_rng_next(&rng);
  }
  pg_pinhole_camera c = cameras.current;
  float sx = ((float)x + jx) / (float)cameras.width;
  float sy = ((float)y + jy) / (float)cameras.height;
  float fx = (2.0f * sx - 1.0f) * c.tan_half_fov_y * c.aspect;
  float fy = (1.0f - 2.0f * sy) * c.tan_half_fov_y;
  return normalize(pg_camera_forward(c) + fx * pg_make_float3(c.right_x, c.right_y, c.right_z) +
                   fy * pg_make_float3(c.up_x, c.up_y, c.up_z));
}
/* The point at linear depth `depth` (the G-buffer's: along forward) on the camera ray `ray`;
 * the sky's (depth 0) at the origin, as the renderer writes it. */
PG_FN float4 pg_gbuffer_position_depth(pg_pinhole_camera c, float3 ray, float depth) {
  if (!(depth > 0.0f)) return pg_make_float4(0.0f, 0.0f, 0.0f, depth);
  float3 p = pg_camera_position(c) + ray * (depth / dot(ray, pg_camera_forward(c)));
  return pg_make_float4(p.x, p.y, p.z, depth);
}
/* The renderer's view direction: its camera ray reversed (host/render/renderer.cpp). */
PG_FN float4 pg_gbuffer_view_dir(float3 ray) {
  float3 v = -normalize(ray);
  return pg_make_float4(v.x, v.y, v.z, 0.0f);
}
/* A motion vector's component clamped to PG_MAX_MOTION pixels either way (a NaN to -PG_MAX_MOTION):
 * a point just in front of last frame's camera projects through a division by nearly 0, up to
 * infinity, and a position formed from such a vector would leave float's exact integers and make
 * its conversion to int undefined (OpenCL C 1.2, 6.2.3.3), where a clamped one lies off the image
 * whatever the pixel (rtpg/image_size.h: sides of at most 65536 pixels), so no history is found
 * there, as for any point off screen. The host's G-buffer clamps its motion the same way. */
#define PG_MAX_MOTION 65536.0f
PG_FN float pg_bounded_motion(float m) {
  return fmin(fmax(m, -PG_MAX_MOTION), PG_MAX_MOTION);
}

/* The offset in pixels from pixel (x, y) to where `position` was in the previous camera's image
 * (CameraFrame::project), each component pg_bounded_motion; zero where the camera did not move or
 * the point was behind it. */
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
  return pg_make_float2(pg_bounded_motion(sx * (float)cameras.width - ((float)x + 0.5f)),
                        pg_bounded_motion(sy * (float)cameras.height - ((float)y + 0.5f)));
}

PG_NAMESPACE_END

#endif

/* The G-buffer's layout from its packed form (include/rtpg/guiding_layout.h, "Packed G-buffer";
 * kernels/shared/gbuffer_packing.h): where the device has memory of its own the host sends 24
 * bytes a pixel and this kernel writes the 96 that reproject, sample, train and SVGF read,
 * following the pixel's camera ray to its depth for the position (the view direction is that
 * ray reversed) and projecting the position into last frame's camera for the motion vector.
 * Per pixel: 24 bytes read, 96 written, about 130 float and integer operations (the jitter's
 * hash, an octahedral decode and two normalisations with their square roots, three divisions,
 * six half floats): memory-bound on a GPU. One work-item per pixel. */
#include "shared/gbuffer_packing.h"
#include "shared/kernel_args.h"

__kernel void unpack_gbuffer(PG_ARGS_PACKED_GBUFFER PG_ARGS_OUT_GBUFFER uint pixels,
                             pg_gbuffer_cameras cameras) {
  uint i = get_global_id(0);
  if (i >= pixels) return;
  uint width = (uint)cameras.width;
  uint x = i % width, y = i / width;
  uint4 surface = packed_surface[i];
  uint2 shading = packed_shading[i];
  float3 ray = pg_gbuffer_camera_ray(cameras, x, y);
  float4 pd = pg_gbuffer_position_depth(cameras.current, ray, pg_unpack_gbuffer_depth(surface));
  uint pixel_flags = pg_unpack_gbuffer_flags(shading);
  position_depth[i] = pd;
  shading_normal[i] = pg_unpack_gbuffer_shading_normal(surface);
  view_dir[i] = pg_gbuffer_view_dir(ray);
  base_color_roughness[i] = pg_unpack_gbuffer_base_color_roughness(surface);
  metallic_specular[i] = pg_unpack_gbuffer_metallic_specular(shading);
  flags[i] = pixel_flags;
  material[i] = pg_unpack_gbuffer_material(shading);
  motion[i] = (pixel_flags & PG_GBUF_SKY) != 0u ? (float2)(0.0f, 0.0f)
                                                : pg_gbuffer_motion(cameras, pd.xyz, x, y);
}

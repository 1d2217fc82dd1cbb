/* The G-buffer's layout from its packed form (include/rtpg/guiding_layout.h, "Packed G-buffer";
 * kernels/shared/gbuffer_packing.h): where the device has memory of its own the host sends 32
 * bytes a pixel and this kernel writes the 96 that reproject, sample, train and SVGF read,
 * deriving the depth, the view direction and the motion vector from the position and the
 * frame's cameras. Per pixel: 32 bytes read, 96 written, about 80 float and integer operations
 * (an octahedral decode and a normalisation with their square roots, two divisions for the
 * motion, six half floats): memory-bound. One work-item per pixel. */
#include "shared/gbuffer_packing.h"
#include "shared/kernel_args.h"

__kernel void unpack_gbuffer(PG_ARGS_PACKED_GBUFFER PG_ARGS_OUT_GBUFFER uint pixels,
                             pg_gbuffer_cameras cameras) {
  uint i = get_global_id(0);
  if (i >= pixels) return;
  uint4 surface = packed_surface[i];
  uint4 shading = packed_shading[i];
  float4 pd = pg_unpack_gbuffer_position_depth(surface, shading, cameras);
  float3 p = pd.xyz;
  uint pixel_flags = pg_unpack_gbuffer_flags(shading);
  int sky = (pixel_flags & PG_GBUF_SKY) != 0u;
  uint width = (uint)cameras.width;
  position_depth[i] = pd;
  shading_normal[i] = pg_unpack_gbuffer_shading_normal(surface);
  view_dir[i] = pg_gbuffer_view_dir(cameras.current, p);
  base_color_roughness[i] = pg_unpack_gbuffer_base_color_roughness(shading);
  metallic_specular[i] = pg_unpack_gbuffer_metallic_specular(shading);
  flags[i] = pixel_flags;
  material[i] = pg_unpack_gbuffer_material(shading);
  motion[i] = sky ? (float2)(0.0f, 0.0f) : pg_gbuffer_motion(cameras, p, i % width, i / width);
}

/* The G-buffer's layout from its packed form (include/rtpg/guiding_layout.h, "Packed G-buffer";
 * kernels/shared/gbuffer_packing.h): where the device has memory of its own the host sends 48
 * bytes a pixel and this kernel writes the 96 that reproject, sample, train and SVGF read.
 * Per pixel: 48 bytes read, 96 written, about 60 integer and float operations (two octahedral
 * decodes with their square roots, six half floats): memory-bound. One work-item per pixel. */
#include "shared/gbuffer_packing.h"
#include "shared/kernel_args.h"

__kernel void unpack_gbuffer(PG_ARGS_PACKED_GBUFFER PG_ARGS_OUT_GBUFFER uint pixels) {
  uint i = get_global_id(0);
  if (i >= pixels) return;
  uint4 surface = packed_surface[i];
  uint4 view_material = packed_view_material[i];
  uint2 shading = packed_shading[i];
  position_depth[i] = pg_unpack_gbuffer_position_depth(surface, view_material);
  shading_normal[i] = pg_unpack_gbuffer_shading_normal(surface);
  view_dir[i] = pg_unpack_gbuffer_view_dir(view_material);
  base_color_roughness[i] = pg_unpack_gbuffer_base_color_roughness(view_material);
  metallic_specular[i] = pg_unpack_gbuffer_metallic_specular(shading);
  flags[i] = pg_unpack_gbuffer_flags(shading);
  material[i] = pg_unpack_gbuffer_material(shading);
  motion[i] = packed_motion[i];
}

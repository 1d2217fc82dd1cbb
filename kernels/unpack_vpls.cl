/* The VPLs' layout from their packed form (include/rtpg/guiding_layout.h, "Packed VPLs";
 * kernels/shared/vpl_packing.h): where the device has memory of its own the host sends 10 bytes
 * a pixel and this kernel writes the 32 that train reads, putting each hit at its distance
 * along the direction the pixel's first sample took and taking that sample's densities (the
 * BSDF's evaluated here for a BSDF sample). Per pixel: 10 bytes of VPL, 20 of sample and 16-80
 * of G-buffer read (the BSDF's inputs only for a BSDF sample), 32 written, about 120 operations
 * (310 with the BSDF's density; counted again on 2026-11-28, when the normal's 8-bit code became
 * its 16-bit one in integers instead of through a unit vector, which had taken 50 more):
 * memory-bound on a GPU. One work-item per pixel. */
#include "shared/guiding_pixel.h"
#include "shared/kernel_args.h"
#include "shared/vpl_packing.h"

__kernel void unpack_vpls(
    PG_ARGS_GBUFFER PG_ARGS_PACKED_VPLS PG_ARGS_IN_SAMPLES PG_ARGS_OUT_VPLS uint pixels) {
  uint i = get_global_id(0);
  if (i >= pixels) return;
  float4 d = sample_direction_pdf[i];
  uint strategy = sample_strategy[i];
  float bsdf_pdf = 0.0f;
  if (strategy == PG_STRATEGY_BSDF) {
    pg_frame frame = pg_frame_from_normal(shading_normal[i].xyz);
    float3 wo = pg_to_local(frame, view_dir[i].xyz);
    pg_lobes lobes =
        pg_make_lobes(pg_material_from_gbuffer(base_color_roughness[i], metallic_specular[i]), wo);
    bsdf_pdf = pg_bsdf_pdf(lobes, wo, pg_to_local(frame, d.xyz));
  }
  pg_vpl v = pg_unpack_vpl(packed_distance[i], packed_radiance[i], packed_normal[i],
                           position_depth[i].xyz, d, strategy, bsdf_pdf);
  vpl_position[i] = v.position;
  vpl_normal_radiance[i] = v.normal_radiance;
}

/* The samples packed for their way back to the host (include/rtpg/guiding_layout.h, "Packed
 * samples"; kernels/shared/sample_packing.h): 20 bytes a pixel read (direction_pdf, strategy),
 * 12 written, about 15 operations (one division). Only where the device has memory of its own:
 * the host then copies 12 bytes a pixel instead of 20. One work-item per pixel. */
#include "shared/kernel_args.h"
#include "shared/sample_packing.h"

__kernel void pack_samples(PG_ARGS_IN_SAMPLES PG_ARGS_PACKED_SAMPLES uint pixels) {
  uint i = get_global_id(0);
  if (i >= pixels) return;
  float4 d = sample_direction_pdf[i];
  packed_direction[i] = pg_pack_direction(d.xyz);
  packed_pdf_strategy[i] = pg_pack_sample_density(d.w, sample_strategy[i]);
}

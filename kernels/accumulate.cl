/* One frame into the running mean: sum = mix(sum, frame, weight_new) per pixel. */
/* Each operation rounded on its own, as on the host: device and host sums agree bit for bit. */
#pragma OPENCL FP_CONTRACT OFF

#include "shared/tonemap.h"

__kernel void accumulate(__global const float4* frame, __global float4* sum, uint width,
                         uint height, float weight_new) {
  size_t i = get_global_id(0);
  if (i >= (size_t)width * height) return;
  float4 f = frame[i];
  /* The first frame after a reset (weight 1) does not read sum: see pg_accumulate. */
  sum[i] = weight_new >= 1.0f ? f : pg_accumulate(sum[i], f, weight_new);
}

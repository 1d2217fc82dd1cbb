/* A plain float4 copy, one element per work-item: the bandwidth yardstick that the guiding
 * kernels' GB/s are compared with (bench/bench_guiding_kernels.cpp; docs/design.md, "Metrics"). */
__kernel void copy_float4(__global const float4* src, __global float4* dst, uint n) {
  size_t i = get_global_id(0);
  if (i < (size_t)n) dst[i] = src[i];
}

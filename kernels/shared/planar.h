/* Planar float4 images (the layout: kernels/shared/svgf.h): channel c (0..3) of pixel i of an
 * image of n pixels at [c * n + i]. OpenCL C only. */
#ifndef RTPG_SHARED_PLANAR_H
#define RTPG_SHARED_PLANAR_H

#ifdef __OPENCL_C_VERSION__

static inline float4 pg_planar_get(__global const float* image, uint n, uint i) {
  return (float4)(image[i], image[n + i], image[2u * n + i], image[3u * n + i]);
}

static inline void pg_planar_set(__global float* image, uint n, uint i, float4 v) {
  image[i] = v.x;
  image[n + i] = v.y;
  image[2u * n + i] = v.z;
  image[3u * n + i] = v.w;
}

#endif

#endif

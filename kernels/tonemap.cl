/* Radiance to displayable sRGB 8-bit; the transform is documented in shared/tonemap.h. */
/* Each operation rounded on its own, as on the host: device and host pixels then agree. */
#pragma OPENCL FP_CONTRACT OFF

#include "shared/tonemap.h"

__kernel void tonemap(__global const float4* radiance, __global uchar4* srgb8, uint width,
                      uint height, float exposure) {
  size_t i = get_global_id(0);
  if (i >= (size_t)width * height) return;
  uint p = pg_tonemap_to_srgb8(radiance[i], exposure);
#ifdef __ENDIAN_LITTLE__
  /* The packing is R in the low byte, so on a little-endian device the uint's bytes are
   * already R, G, B, A. One whole-word store: building the uchar4 from lanes compiles (LLVM
   * 15) into a store of a partly-poison vector followed by byte stores, which Oclgrind
   * --uninitialized reports as an uninitialised write. */
  srgb8[i] = as_uchar4(p);
#else
  srgb8[i] = (uchar4)((uchar)(p & 0xffu), (uchar)((p >> 8) & 0xffu), (uchar)((p >> 16) & 0xffu),
                      (uchar)(p >> 24));
#endif
}

/* pg_guiding_applies (kernels/shared/guiding_pixel.h) for PG_LANES pixels at once (kernels/
 * wide/lanes.h). OpenCL C only. */
#ifndef RTPG_WIDE_GUIDING_PIXEL_WIDE_H
#define RTPG_WIDE_GUIDING_PIXEL_WIDE_H

#include "rtpg/guiding_layout.h"
#include "wide/lanes.h"

static inline pg_intw pg_guiding_applies_w(pg_uintw flags, pg_floatw roughness,
                                           pg_kernel_settings p) {
  uint skip = PG_GBUF_SKY | PG_GBUF_EMITTER | PG_GBUF_DELTA | PG_GBUF_TRANSMISSIVE;
  return ((flags & skip) == 0u) & (roughness > p.roughness_skip);
}

#endif

/* kernels/shared/sincos.h for PG_LANES angles at once (kernels/wide/lanes.h), operation for
 * operation as the scalar functions. OpenCL C only. */
#ifndef RTPG_WIDE_SINCOS_WIDE_H
#define RTPG_WIDE_SINCOS_WIDE_H

#include "shared/compat.h"
#include "wide/lanes.h"

/* pg_cos_sin_octant per lane: cos a and sin a for |a| <= pi/4. */
static inline void pg_cos_sin_octant_w(pg_floatw a, __private pg_floatw* c,
                                       __private pg_floatw* s) {
  pg_floatw z = a * a;
  *s = ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * a + a;
  *c = ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z -
       0.5f * z + 1.0f;
}

/* pg_cos_sin_turn per lane: cos 2 pi u and sin 2 pi u for u in [0, 1]. */
static inline void pg_cos_sin_turn_w(pg_floatw u, __private pg_floatw* c, __private pg_floatw* s) {
  pg_floatw four_u = 4.0f * u;
  pg_floatw q = floor(four_u + 0.5f);
  pg_floatw oc, os;
  pg_cos_sin_octant_w((PG_PI / 2.0f) * (four_u - q), &oc, &os);
  /* Quarter turns 0..3: (c, s), (-s, c), (-c, -s), (s, -c). */
  pg_intw quarter = pg_convert_intw(q) & 3;
  pg_intw odd = (quarter & 1) != 0;
  pg_floatw x = select(oc, os, odd), y = select(os, oc, odd);
  *c = select(x, -x, (quarter == 1) | (quarter == 2));
  *s = select(y, -y, quarter >= 2);
}

#endif

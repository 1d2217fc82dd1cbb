/* The per-pixel random numbers of kernels/shared/rng.h for PG_LANES pixels at once (kernels/
 * wide/lanes.h): the same 32-bit operations lane by lane, so every lane draws its pixel's
 * stream bit for bit. OpenCL C only. */
#ifndef RTPG_WIDE_RNG_WIDE_H
#define RTPG_WIDE_RNG_WIDE_H

#include "wide/lanes.h"

/* pg_pcg_hash per lane. */
static inline pg_uintw pg_pcg_hash_w(pg_uintw v) {
  pg_uintw state = v * 747796405u + 2891336453u;
  pg_uintw word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

/* pg_rng_make's state for each lane's pixel index. */
static inline pg_uintw pg_rng_make_w(uint seed, pg_uintw pixel, uint frame, uint sample,
                                     uint stream_tag) {
  uint h = pg_pcg_hash(seed ^ 0x9e3779b9u);
  pg_uintw hw = pg_pcg_hash_w(h ^ pixel);
  hw = pg_pcg_hash_w(hw ^ (frame * 0x85ebca6bu));
  hw = pg_pcg_hash_w(hw ^ (sample * 0xc2b2ae35u));
  return pg_pcg_hash_w(hw ^ (stream_tag * 0x27d4eb2fu));
}

/* pg_rng_next per lane. */
static inline pg_floatw pg_rng_next_w(__private pg_uintw* state) {
  pg_uintw old = *state;
  *state = old * 747796405u + 2891336453u;
  pg_uintw word = ((old >> ((old >> 28u) + 4u)) ^ old) * 277803737u;
  return pg_convert_floatw(((word >> 22u) ^ word) >> 8) * (1.0f / 16777216.0f);
}

#endif

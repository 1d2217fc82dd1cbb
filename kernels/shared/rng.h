/* Per-pixel random numbers, deterministic in (seed, pixel, frame, sample, dimension).
 *
 * The state is a 32-bit PCG-style LCG seeded by hashing the four coordinates (Jarzynski and
 * Olano 2020, "Hash Functions for GPU Rendering": pcg_hash). 32-bit arithmetic only, so the
 * host and any OpenCL device produce the same streams bit for bit. */
#ifndef RTPG_SHARED_RNG_H
#define RTPG_SHARED_RNG_H

#include "shared/compat.h"

PG_NAMESPACE_BEGIN

typedef struct {
  uint state;
} pg_rng;

PG_FN uint pg_pcg_hash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

/* A stream per (seed, pixel, frame, sample). stream_tag separates independent consumers
 * (for example the device sampler and the host integrator) that share those coordinates. */
PG_FN pg_rng pg_rng_make(uint seed, uint pixel, uint frame, uint sample, uint stream_tag) {
  pg_rng r;
  uint h = pg_pcg_hash(seed ^ 0x9e3779b9u);
  h = pg_pcg_hash(h ^ pixel);
  h = pg_pcg_hash(h ^ (frame * 0x85ebca6bu));
  h = pg_pcg_hash(h ^ (sample * 0xc2b2ae35u));
  r.state = pg_pcg_hash(h ^ (stream_tag * 0x27d4eb2fu));
  return r;
}

PG_FN uint pg_rng_next_uint(PG_PRIVATE pg_rng* r) {
  uint old = r->state;
  r->state = old * 747796405u + 2891336453u;
  uint word = ((old >> ((old >> 28u) + 4u)) ^ old) * 277803737u;
  return (word >> 22u) ^ word;
}

/* Uniform in [0, 1): the top 24 bits, so the result is exactly representable. */
PG_FN float pg_rng_next(PG_PRIVATE pg_rng* r) {
  return (float)(pg_rng_next_uint(r) >> 8) * (1.0f / 16777216.0f);
}

PG_NAMESPACE_END

#endif

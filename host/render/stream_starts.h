// The start states of one random stream per pixel, pg_rng_make(seed, i, frame, sample, tag)
// for i in [first, first + count) (kernels/shared/rng.h): five PCG hashes a pixel, which the
// path tracer needs for every pixel of every sample. Computed in vector lanes by the variant
// `code` names (render/cpu_code.h), every variant to the bit (docs/host-path-tracer.md,
// "Random streams started in vector lanes").
#pragma once

#include <cstddef>
#include <cstdint>

#include "render/cpu_code.h"

namespace rtpg {

struct StreamCoordinates {
  std::uint32_t seed = 0, frame = 0, sample = 0, tag = 0;
};

// states[k] = pg_rng_make(c.seed, first + k, c.frame, c.sample, c.tag).state, k < count (one
// thread; callers split their ranges).
void make_stream_starts(const StreamCoordinates& c, std::size_t first, std::size_t count,
                        std::uint32_t* states, CpuCode code = CpuCode::automatic);

}  // namespace rtpg

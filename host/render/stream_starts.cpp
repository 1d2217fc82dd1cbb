#include "render/stream_starts.h"

#include <algorithm>

#include "shared/rng.h"

namespace rtpg {
namespace {

// Pixels per step: the lane loop's fixed trip count lets the compiler vectorise the hashes (the
// per-lane shifts of pg_pcg_hash need AVX2; baseline code stays scalar).
constexpr std::size_t kLanes = 16;

[[gnu::always_inline]] inline void stream_starts(const StreamCoordinates& c, std::size_t first,
                                                 std::size_t count, std::uint32_t* states) {
  std::size_t k = 0;
  for (; k + kLanes <= count; k += kLanes) {
    std::uint32_t lanes[kLanes];
    for (std::size_t l = 0; l < kLanes; ++l)
      lanes[l] = shared::pg_rng_make(c.seed, static_cast<std::uint32_t>(first + k + l), c.frame,
                                     c.sample, c.tag)
                     .state;
    std::copy(lanes, lanes + kLanes, states + k);
  }
  for (; k < count; ++k)
    states[k] =
        shared::pg_rng_make(c.seed, static_cast<std::uint32_t>(first + k), c.frame, c.sample, c.tag)
            .state;
}

void stream_starts_baseline(const StreamCoordinates& c, std::size_t first, std::size_t count,
                            std::uint32_t* states) {
  stream_starts(c, first, count, states);
}

#if RTPG_HAS_AVX2_VARIANT
RTPG_AVX2_VARIANT void stream_starts_avx2(const StreamCoordinates& c, std::size_t first,
                                          std::size_t count, std::uint32_t* states) {
  stream_starts(c, first, count, states);
}
#endif

}  // namespace

void make_stream_starts(const StreamCoordinates& c, std::size_t first, std::size_t count,
                        std::uint32_t* states, CpuCode code) {
#if RTPG_HAS_AVX2_VARIANT
  if (resolve_cpu_code(code) == CpuCode::avx2) {
    stream_starts_avx2(c, first, count, states);
    return;
  }
#else
  resolve_cpu_code(code);
#endif
  stream_starts_baseline(c, first, count, states);
}

}  // namespace rtpg

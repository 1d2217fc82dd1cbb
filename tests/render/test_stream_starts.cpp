// Random streams started in vector lanes (host/render/stream_starts.h): every variant gives
// each pixel exactly pg_rng_make's state (kernels/shared/rng.h), for ranges that start anywhere
// and end inside a step of lanes, and writes nothing past the range.
#include <gtest/gtest.h>

#include <vector>

#include "render/stream_starts.h"
#include "rtpg/guiding_layout.h"
#include "shared/rng.h"

namespace rtpg {
namespace {

TEST(StreamStarts, EveryVariantGivesPgRngMakesStates) {
  std::vector<CpuCode> codes = {CpuCode::automatic, CpuCode::baseline};
  if (cpu_runs_avx2()) codes.push_back(CpuCode::avx2);
  const StreamCoordinates coordinates[] = {{7u, 0u, 0u, PG_RNG_STREAM_PATH},
                                           {1u, 31u, 3u, PG_RNG_STREAM_FIRST_BOUNCE},
                                           {0xffffffffu, 9999u, 1u, PG_RNG_STREAM_PATH}};
  const std::size_t ranges[][2] = {
      {0, 0},   {0, 1},       {5, 15},          {16, 16},
      {33, 17}, {1001, 2048}, {0xfffffff0u, 40}};  // the last one wraps the 32-bit index
  for (const CpuCode code : codes)
    for (const StreamCoordinates& c : coordinates)
      for (const auto& range : ranges) {
        const std::size_t first = range[0], count = range[1];
        std::vector<std::uint32_t> states(count + 1, 0xdeadbeefu);
        make_stream_starts(c, first, count, states.data(), code);
        int differing = 0;
        for (std::size_t k = 0; k < count; ++k)
          differing +=
              states[k] != shared::pg_rng_make(c.seed, static_cast<std::uint32_t>(first + k),
                                               c.frame, c.sample, c.tag)
                               .state;
        EXPECT_EQ(differing, 0) << "variant " << static_cast<int>(code) << ", first " << first
                                << ", count " << count;
        EXPECT_EQ(states[count], 0xdeadbeefu) << "wrote past the range";
      }
}

}  // namespace
}  // namespace rtpg
